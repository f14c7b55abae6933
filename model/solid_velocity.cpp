#include "model/solid_velocity.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <regex>
#include <tuple>

#include "core/image.h"
#include "core/parallel.h"
#include "lsystem/expression.h"
#include "solids/extrude_field.h"
#include "solids/front_field.h"
#include "textures/noise.h"

namespace sprig {

namespace {

using solids::FieldPtr;

/// Lattice side on which a procedure's largest speed is measured.
constexpr int kProbeSide = 32;

/// A speed written as an expression of x, y, z, noise and turbulence.
struct ExpressionSpeed {
  lsystem::Expression expr;
  std::shared_ptr<const textures::PerlinNoise> noise;
  textures::FractalOptions octaves;
  double scale = 1;
  bool usesNoise = false, usesTurbulence = false;

  double at(const DVec3& p) const {
    const DVec3 q = p / scale;
    const double n = usesNoise ? (*noise)(q) : 0.0;
    const double t = usesTurbulence ? noise->turbulence(q, octaves) : 0.0;
    return expr({p.x, p.y, p.z, n, t});
  }
};

bool mentions(const std::string& text, const char* name) {
  return std::regex_search(text, std::regex(std::string("\\b") + name + "\\b"));
}

/// The painted value at a point from an image map laid over the plane perpendicular to an
/// axis (extrude_2d's placement): linear Rec. 709 luminance, bilinear, clamped at the edges.
class ProjectedImage {
 public:
  ProjectedImage(const Image& image, const DVec3& axis, glm::dvec2 size, glm::dvec2 center, double low, double high)
      : w_(image.width), h_(image.height), low_(low), high_(high), size_(size) {
    std::tie(u_, v_) = solids::imagePlaneAxes(axis);
    corner_ = center - size / 2.0;
    for (int y = 0; y < h_; ++y)
      for (int x = 0; x < w_; ++x) {
        const Vec4 c = image.at(x, y);
        lum_.push_back(0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b);
      }
  }

  float operator()(const Vec3& p) const {
    const DVec3 q(p);
    const double fx = std::clamp((glm::dot(q, u_) - corner_.x) / size_.x * w_ - 0.5, 0.0, double(w_ - 1));
    const double fy = std::clamp((glm::dot(q, v_) - corner_.y) / size_.y * h_ - 0.5, 0.0, double(h_ - 1));
    const int x0 = int(fx), y0 = int(fy), x1 = std::min(x0 + 1, w_ - 1), y1 = std::min(y0 + 1, h_ - 1);
    const double tx = fx - x0, ty = fy - y0;
    auto at = [&](int x, int y) { return double(lum_[size_t(y) * size_t(w_) + size_t(x)]); };
    const double value = (1 - ty) * ((1 - tx) * at(x0, y0) + tx * at(x1, y0)) + ty * ((1 - tx) * at(x0, y1) + tx * at(x1, y1));
    return float(low_ + (high_ - low_) * value);
  }

 private:
  int w_, h_;
  double low_, high_;
  glm::dvec2 size_, corner_;
  DVec3 u_, v_;
  std::vector<float> lum_;
};

/// The painted value near each point: vertex colour luminance smoothed over nearby vertices (a bucket grid).
class NearestVertex {
 public:
  NearestVertex(const PolyMesh& mesh, double low, double high) : low_(low), high_(high) {
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
      box_.extend(DVec3(mesh.positions[i]));
      const Vec3 c = mesh.colors[i];
      values_.push_back(0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b);  // Rec. 709, linear
    }
    positions_ = mesh.positions;
    const DVec3 size = box_.size();
    const double side = std::max({size.x, size.y, size.z, 1e-9});
    cell_ = side / 48;
    for (int a = 0; a < 3; ++a) dims_[a] = std::max(1, int(std::ceil(size[a] / cell_)) + 1);
    buckets_.assign(size_t(dims_[0]) * dims_[1] * dims_[2], {});
    for (uint32_t i = 0; i < positions_.size(); ++i) buckets_[bucketOf(DVec3(positions_[i]))].push_back(i);
  }

  float operator()(const Vec3& p) const {
    const DVec3 q(p);
    const std::array<int, 3> c = cellOf(q);
    // The paint is smoothed over a radius of two buckets (weights (1 - (d/R)²)², Wendland-like),
    // so the layer does not show the mesh's Voronoi cells; far from every vertex, the nearest.
    const double radius = 2 * cell_;
    double wsum = 0, vsum = 0;
    for (int k = c[2] - 2; k <= c[2] + 2; ++k)
      for (int j = c[1] - 2; j <= c[1] + 2; ++j)
        for (int i = c[0] - 2; i <= c[0] + 2; ++i) {
          if (i < 0 || j < 0 || k < 0 || i >= dims_[0] || j >= dims_[1] || k >= dims_[2]) continue;
          for (uint32_t v : buckets_[i + size_t(dims_[0]) * (j + size_t(dims_[1]) * k)]) {
            const double e = glm::length(DVec3(positions_[v]) - q) / radius;
            if (e >= 1) continue;
            const double w = (1 - e * e) * (1 - e * e);
            wsum += w;
            vsum += w * values_[v];
          }
        }
    if (wsum > 1e-6) return float(low_ + (high_ - low_) * (vsum / wsum));
    double best = 1e300;
    uint32_t who = 0;
    // Rings of buckets outward until the ring is farther than the nearest vertex found.
    for (int r = 0;; ++r) {
      for (int k = c[2] - r; k <= c[2] + r; ++k)
        for (int j = c[1] - r; j <= c[1] + r; ++j)
          for (int i = c[0] - r; i <= c[0] + r; ++i) {
            if (std::max({std::abs(i - c[0]), std::abs(j - c[1]), std::abs(k - c[2])}) != r) continue;
            if (i < 0 || j < 0 || k < 0 || i >= dims_[0] || j >= dims_[1] || k >= dims_[2]) continue;
            for (uint32_t v : buckets_[i + size_t(dims_[0]) * (j + size_t(dims_[1]) * k)]) {
              const DVec3 e = DVec3(positions_[v]) - q;
              const double d2 = glm::dot(e, e);
              if (d2 < best || (d2 == best && v < who)) best = d2, who = v;
            }
          }
      const bool covered = r >= std::max({dims_[0], dims_[1], dims_[2]});
      if (covered || (best < 1e300 && std::sqrt(best) <= r * cell_)) break;
    }
    return float(low_ + (high_ - low_) * values_[who]);
  }

 private:
  std::array<int, 3> cellOf(const DVec3& p) const {
    std::array<int, 3> c{};
    for (int a = 0; a < 3; ++a) c[size_t(a)] = std::clamp(int(std::floor((p[a] - box_.lo[a]) / cell_)), 0, dims_[a] - 1);
    return c;
  }
  size_t bucketOf(const DVec3& p) const {
    const std::array<int, 3> c = cellOf(p);
    return c[0] + size_t(dims_[0]) * (c[1] + size_t(dims_[1]) * c[2]);
  }

  double low_, high_;
  DBox3 box_;
  std::vector<Vec3> positions_;
  std::vector<double> values_;
  double cell_ = 1;
  int dims_[3] = {1, 1, 1};
  std::vector<std::vector<uint32_t>> buckets_;
};

/// An expression speed: always a front (the speed varies), whatever the child is.
std::optional<VelocityWrap> readExpression(const YNode& exprNode, const std::string& text, MapReader* m, DiagnosticList& diags) {
  auto speed = std::make_shared<ExpressionSpeed>();
  try {
    const SourceLoc at = exprNode.loc();
    speed->expr = lsystem::Expression::compile(text, {"x", "y", "z", "noise", "turbulence"}, at,
                                               exprNode.file().sourceLine(at.line));
  } catch (const InputError& e) {
    std::vector<Diagnostic> ds = e.diagnostics();
    for (Diagnostic& d : ds)
      if (d.message == "unknown function 'noise'" || d.message == "unknown function 'turbulence'")
        d.message += ": here 'noise' and 'turbulence' are variables, the values at the point (their frequency is "
                     "'noise: {scale}')";
    diags.append(ds);
    return std::nullopt;
  }
  speed->usesNoise = mentions(text, "noise");
  speed->usesTurbulence = mentions(text, "turbulence");
  uint64_t seed = 0;
  std::optional<double> max;
  if (m) {
    if (auto nz = m->section({"noise", "The noise the expression's `noise` and `turbulence` read: `scale`, `octaves`, `seed`."})) {
      MapReader nm(*nz, diags, "noise");
      speed->scale = nm.number({"scale", "World units per noise lattice cell."}, 1.0, 1e-6, 1e6);
      speed->octaves.octaves = int(nm.integer({"octaves", "Octaves of the turbulence."}, 4, 1, 12));
      seed = uint64_t(nm.integer({"seed", "Seed of the noise."}, 0, 0, int64_t(1) << 53));
      nm.finish();
    }
    if (auto mx = m->get({"max", "The largest speed (default: probed over the field's box; required when the field is unbounded)."})) max = mx->asNumber(diags, "'max'", double(solids::kMinSpeed), 1e6);
  }
  speed->noise = std::make_shared<textures::PerlinNoise>(seed);
  const YNode where = exprNode;
  return VelocityWrap([speed, max, where, &diags](FieldPtr child) -> FieldPtr {
    if (!child) return nullptr;
    double top = max.value_or(0.0);
    if (!max) {
      std::optional<DBox3> box = child->bounds();
      if (!box) {
        where.error(diags, "this velocity needs 'max' (the largest speed): its field is unbounded");
        return nullptr;
      }
      const DBox3 probe = box->expanded(0.25 * std::max({box->size().x, box->size().y, box->size().z}));
      std::vector<double> v(size_t(kProbeSide) * kProbeSide * kProbeSide);
      parallelFor(0, size_t(kProbeSide), [&](size_t k) {
        for (int j = 0; j < kProbeSide; ++j)
          for (int i = 0; i < kProbeSide; ++i) {
            const DVec3 f = DVec3(i, j, int(k)) / double(kProbeSide - 1);
            v[i + kProbeSide * (j + kProbeSide * k)] = speed->at(probe.lo + f * probe.size());
          }
      });
      for (size_t i = 0; i < v.size(); ++i) {
        if (!(std::isfinite(v[i]) && v[i] > 0)) {
          char buf[160];
          std::snprintf(buf, sizeof buf, "the velocity is %g at a point of its field's box (it must be positive and finite)", v[i]);
          where.error(diags, buf);
          return nullptr;
        }
        top = std::max(top, v[i]);
      }
      top *= 1.1;  // between the probe's nodes the speed may rise a little higher
    }
    auto fn = [speed](const std::vector<Vec3>& pts, std::vector<float>& out) {
      parallelFor(0, pts.size(), [&](size_t i) { out[i] = float(speed->at(DVec3(pts[i]))); }, 4096);
    };
    return solids::frontField(child, fn, top, false);
  });
}

/// `[u, v]` of two finite numbers at key, or def.
std::optional<glm::dvec2> pairAt(MapReader& m, Key key, glm::dvec2 def, DiagnosticList& diags) {
  auto n = m.get(key);
  if (!n) return def;
  const std::vector<YNode> items = n->isSequence() ? n->items() : std::vector<YNode>{};
  if (items.size() != 2) {
    n->error(diags, sprig::quoted(key.name) + " must be [u, v]");
    return std::nullopt;
  }
  auto a = items[0].asNumber(diags, sprig::quoted(key.name)), b = items[1].asNumber(diags, sprig::quoted(key.name));
  if (!a || !b) return std::nullopt;
  return glm::dvec2(*a, *b);
}

/// `image: {file, axis, size, center}` of a painted velocity: the paint from an image map.
std::function<float(const Vec3&)> readImagePaint(const YNode& node, DiagnosticList& diags, const PolyMesh& mesh, double low,
                                                 double high, const PathPolicy* policy) {
  MapReader m(node, diags, "image");
  std::optional<std::filesystem::path> file;
  const Key fileKey{"file", "The paint image (PNG, JPEG, EXR; at most 8192 × 8192), relative to the species file; its linear luminance is the paint; required."};
  if (policy) file = m.path(fileKey, *policy);
  else m.get(fileKey);
  m.markRequired("file");
  if (!m.has("file")) node.error(diags, "missing required key 'file' in image (a PNG or EXR map; its luminance is the paint)");
  Vec3 axisIn = m.vec3({"axis", "The image lies on the plane across this axis and is projected along it onto the surface (not zero)."}, Vec3(0, 1, 0));
  if (glm::length(axisIn) == 0) {
    m.get("axis")->error(diags, "'axis' must not be zero");
    axisIn = Vec3(0, 1, 0);
  }
  const DVec3 axis = glm::normalize(DVec3(axisIn));
  const auto [u, v] = solids::imagePlaneAxes(axis);
  glm::dvec2 lo(1e300), hi(-1e300);
  for (const Vec3& p : mesh.positions) {
    const glm::dvec2 q(glm::dot(DVec3(p), u), glm::dot(DVec3(p), v));
    lo = glm::min(lo, q), hi = glm::max(hi, q);
  }
  const std::optional<glm::dvec2> size =
      pairAt(m, {"size", "[u, v]: the image's size in world units (default: the mesh's extent on the plane)."}, glm::max(hi - lo, glm::dvec2(1e-6)), diags);
  const std::optional<glm::dvec2> center =
      pairAt(m, {"center", "[u, v]: plane coordinates of the image's centre (default: the middle of the mesh's extent)."}, (lo + hi) / 2.0, diags);
  m.finish();
  if (size && !(size->x > 0 && size->y > 0)) {
    m.get("size")->error(diags, "'size' must be positive, world units [along columns, along rows]");
    return {};
  }
  if (!policy && m.has("file")) {
    node.error(diags, "an image map is not available here");
    return {};
  }
  if (!file || !size || !center) return {};
  try {
    auto paint = std::make_shared<ProjectedImage>(readImage(*file), axis, *size, *center, low, high);
    return [paint](const Vec3& q) { return (*paint)(q); };
  } catch (const ImageReadError& e) {
    m.get("file")->error(diags, e.what());
  }
  return {};
}

}  // namespace

FieldPtr redistanced(FieldPtr child) { return solids::frontField(std::move(child), solids::uniformSpeed(1.0f), 1.0, false); }

std::optional<VelocityWrap> readVelocity(const YNode& node, DiagnosticList& diags, const PolyMesh* mesh, bool redistance,
                                         const PathPolicy* policy) {
  if (node.isScalar() && node.isPlainScalar()) {
    // A number, or an unquoted expression.
    const std::string text = node.scalar();
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (end && *end == '\0' && !text.empty()) {
      if (!(std::isfinite(v) && v >= solids::kMinSpeed && v <= 1e6)) {
        node.error(diags, "'velocity' must be a positive number (at least 0.01), got " + text);
        return std::nullopt;
      }
      return VelocityWrap([v, redistance](FieldPtr child) -> FieldPtr {
        if (!child) return nullptr;
        if (!redistance) return solids::constantSpeedField(child, v);
        return solids::frontField(child, solids::uniformSpeed(float(v)), v, false);
      });
    }
  }
  if (node.isScalar()) return readExpression(node, node.scalar(), nullptr, diags);
  if (!node.isMap()) {
    node.error(diags, "'velocity' must be a number, an expression, {expression: ...} or {painted: {low, high}}");
    return std::nullopt;
  }
  MapReader m(node, diags, "velocity");
  std::optional<VelocityWrap> out;
  if (auto e = m.get({"expression", "The speed as an expression of x, y, z, noise and turbulence (the grammar's expression language, degrees)."})) {
    if (auto text = e->asString(diags, "'expression'")) out = readExpression(*e, *text, &m, diags);
  } else if (auto p = m.section({"painted", "`surface_mesh` only: speed low + (high − low)·luminance of the mesh's vertex colours, or of an `image` map."})) {
    MapReader pm(*p, diags, "painted");
    const double low = pm.number({"low", "Speed where the paint is black."}, 1.0, double(solids::kMinSpeed), 1e6);
    const double high = pm.number({"high", "Speed where the paint is white."}, 2.0, double(solids::kMinSpeed), 1e6);
    std::optional<YNode> imageNode = pm.section({"image", "The paint from an image map laid on a plane: `file`, `axis`, `size`, `center` (default: the mesh's vertex colours)."});
    pm.finish();
    std::function<float(const Vec3&)> paint;
    if (!mesh) {
      p->error(diags, "a painted velocity belongs on a surface_mesh (its vertex colours or an image map are the paint)");
    } else if (imageNode) {
      paint = readImagePaint(*imageNode, diags, *mesh, low, high, policy);
    } else if (mesh->colors.size() != mesh->positions.size()) {
      p->error(diags, "a painted velocity needs a mesh with vertex colours (OBJ 'v x y z r g b', PLY red/green/blue) or an 'image' map");
    } else {
      paint = [near = std::make_shared<NearestVertex>(*mesh, low, high)](const Vec3& q) { return (*near)(q); };
    }
    if (paint) {
      const double top = std::max(low, high);
      out = VelocityWrap([paint, top](FieldPtr child) -> FieldPtr {
        if (!child) return nullptr;
        auto fn = [paint](const std::vector<Vec3>& pts, std::vector<float>& v) {
          parallelFor(0, pts.size(), [&](size_t i) { v[i] = paint(pts[i]); }, 256);
        };
        return solids::frontField(child, fn, top, true);
      });
    }
  } else {
    node.error(diags, "'velocity' needs 'expression' or 'painted'");
  }
  m.finish();
  return out;
}

}  // namespace sprig
