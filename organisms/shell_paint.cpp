#include "organisms/shell_paint.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sprig::organisms {

ShellPainter::ShellPainter(const ShellParams& params, const ShellModel& model, ShellTextureOptions options)
    : options_(std::move(options)),
      spiral_(params.spiral),
      startDeg_(params.startDeg),
      endDeg_(model.endDeg),
      fullEndDeg_(params.whorls * params.whorlDeg),
      varixSpacingDeg_(params.varices.spacingDeg),
      varices_(params.varices.enabled),
      opening_(params.opening.enabled),
      openingFromDeg_(model.endDeg - params.opening.depthDeg),
      spineLength_(params.varices.spineLength),
      axialLength_(params.axialSpines.length),
      shellFromWorld_(glm::inverse(model.worldFromShell)) {
  if (options_.pigment)
    pigment_ = std::make_shared<const textures::PigmentPattern>(textures::simulatePigment(options_.pigmentOptions));
}

HelicoCoords ShellPainter::helicoCoords(Vec3 q) const {
  const DVec3 p(q);
  const double phi = std::atan2(-p.z, p.x) * 180.0 / kPi;  // θ modulo 360
  HelicoCoords best;
  best.radial = best.grownRadial = std::numeric_limits<double>::max();
  auto radialAt = [&](double th, double& x, double& y) {
    const DVec3 c = spiral_.point(th);
    const double d = spiral_.curveSize(th);
    const DVec3 e = glm::normalize(DVec3(c.x, 0.0, c.z));
    x = glm::dot(p - c, e) / d;
    y = (p.y - c.y) / d;
    return std::hypot(x, y);
  };
  const double kLo = std::floor((startDeg_ - 360.0 - phi) / 360.0);
  const double kHi = std::ceil((std::max(endDeg_, fullEndDeg_) + 360.0 - phi) / 360.0);
  double lipR = -1.0;  // against the lip's curve, the grown one of every turn past it: once
  for (double k = kLo; k <= kHi; k += 1.0) {
    const double th = phi + 360.0 * k;
    double x = 0.0, y = 0.0, gx = 0.0, gy = 0.0;
    const double r = radialAt(th, x, y);
    const double grownTh = std::min(th, endDeg_);
    if (grownTh != th && lipR < 0.0) lipR = radialAt(grownTh, gx, gy);
    const double grownR = grownTh == th ? r : lipR;
    if (grownR < best.grownRadial) {
      best.grownRadial = grownR;
      best.grownThetaDeg = grownTh;
    }
    if (r < best.radial) {
      best.radial = r;
      best.thetaDeg = th;
      best.aroundDeg = std::atan2(-y, x) * 180.0 / kPi;  // positive towards the apex (−y)
    }
  }
  return best;
}

HelicoCoords ShellPainter::helicoCoordsOfWorld(Vec3 worldPoint) const {
  return helicoCoords(Vec3(shellFromWorld_ * glm::dvec4(DVec3(worldPoint), 1.0)));
}

Vec3 ShellPainter::whorlColor(Vec3 shellPoint) const { return whorlColorAt(helicoCoords(shellPoint)); }

Vec3 ShellPainter::whorlColorAt(const HelicoCoords& h) const {
  const double w = insideWeight(h);
  const Vec3 c = wallColor(h);
  if (w > 0.0) return glm::mix(c, options_.insideColor, static_cast<float>(w));
  return h.radial < kShellCanalRadial ? withVarixBand(c, h.thetaDeg) : c;
}

Vec3 ShellPainter::whorlSurfaceColor(double thetaDeg, double aroundDeg, bool canal) const {
  HelicoCoords h;
  h.thetaDeg = thetaDeg;
  h.aroundDeg = aroundDeg;
  const Vec3 c = wallColor(h);
  return canal ? c : withVarixBand(c, thetaDeg);
}

double ShellPainter::insideWeight(const HelicoCoords& h) const {
  // The inside of the aperture: the cut surface of the opening, inside the whorl's wall.
  const ShellTextureOptions& o = options_;
  if (!opening_ || o.insideRadial <= 0.0f || h.grownThetaDeg <= openingFromDeg_) return 0.0;
  return std::clamp((o.insideRadial + 0.04 - h.grownRadial) / 0.08, 0.0, 1.0);
}

bool ShellPainter::hasVarixBands() const { return varices_ && varixSpacingDeg_ > 0.0; }

Vec3 ShellPainter::wallColor(const HelicoCoords& h) const {
  const ShellTextureOptions& o = options_;
  Vec3 c = o.whorlColor;
  // Spiral cords: bands that follow the spiral (constant angle around the curve).
  if (o.cords > 0 && o.cordStrength > 0.0f) {
    const double s = 0.5 + 0.5 * std::cos(radians(h.aroundDeg) * o.cords);
    c = glm::mix(c, o.cordColor, static_cast<float>(o.cordStrength * std::pow(s, 3.0)));
  }
  // Growth lines across the whorl.
  if (o.growthLineDeg > 0.0f && o.growthLineStrength > 0.0f) {
    const double f = std::abs(std::remainder(h.thetaDeg, static_cast<double>(o.growthLineDeg))) / o.growthLineDeg;
    c *= 1.0f - o.growthLineStrength * static_cast<float>(std::max(0.0, 1.0 - 6.0 * f));
  }
  // Reaction-diffusion pigment, one row per growth stage of the fully grown shell.
  if (pigment_) {
    const double v = (h.thetaDeg - startDeg_) / std::max(1.0, fullEndDeg_ - startDeg_);
    const double u = h.aroundDeg / 360.0;
    const float a = pigment_->sample(u, v);
    c = glm::mix(c, o.pigmentColor, o.pigmentStrength * a);
  }
  return c;
}

Vec3 ShellPainter::withVarixBand(Vec3 c, double thetaDeg) const {
  // Pale bands where varices were laid down (only on the whorl proper: the canal's points
  // lie far from every generating centre, and a band there, constant θ along the axis,
  // would draw a pale line down the canal; whorlColorAt leaves them out there).
  if (!hasVarixBands()) return c;
  const double dv = std::abs(std::remainder(thetaDeg - startDeg_, varixSpacingDeg_));
  if (thetaDeg > startDeg_ + 0.5 * varixSpacingDeg_ && dv < 4.0)
    c = glm::mix(c, options_.varixColor, static_cast<float>(0.6 * (1.0 - dv / 4.0)));
  return c;
}

Vec3 ShellPainter::partColor(ShellPart part, Vec3 worldPoint, Vec2 uv) const {
  const ShellTextureOptions& o = options_;
  switch (part) {
    case ShellPart::Whorl: return whorlColor(Vec3(shellFromWorld_ * glm::dvec4(DVec3(worldPoint), 1.0)));
    case ShellPart::VarixSpine: {
      // Cone natural v runs from the spine base; tips darken.
      const float t = std::clamp(uv.y / std::max(1e-6f, spineLength_), 0.0f, 1.0f);
      return glm::mix(o.varixColor, o.spineTipColor, t * t * t);
    }
    case ShellPart::AxialSpine: {
      const float t = std::clamp(uv.y / std::max(1e-6f, axialLength_), 0.0f, 1.0f);
      return glm::mix(o.axialColor, o.spineTipColor, t * t);
    }
    case ShellPart::Bump: return o.bumpColor;
    case ShellPart::Inside: return o.insideColor;
  }
  return o.whorlColor;
}

Vec3 ShellPainter::color(Vec3 worldPoint, const blobtree::Attributes& a) const {
  if (a.textureCount == 0) return options_.whorlColor;
  Vec3 c(0.0f);
  float w = 0.0f;
  for (int i = 0; i < a.textureCount; ++i) {
    const uint16_t id = a.textureIds[size_t(i)];
    const ShellPart part = id <= static_cast<uint16_t>(ShellPart::Inside) ? static_cast<ShellPart>(id) : ShellPart::Whorl;
    c += a.textureWeights[size_t(i)] * partColor(part, worldPoint, a.uv);
    w += a.textureWeights[size_t(i)];
  }
  return w > 0.0f ? c / w : options_.whorlColor;
}

}  // namespace sprig::organisms
