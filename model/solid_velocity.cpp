#include "model/solid_velocity.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <regex>

#include "core/parallel.h"
#include "lsystem/expression.h"
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
    if (auto nz = m->section("noise")) {
      MapReader nm(*nz, diags, "noise");
      speed->scale = nm.number("scale", 1.0, 1e-6, 1e6);
      speed->octaves.octaves = int(nm.integer("octaves", 4, 1, 12));
      seed = uint64_t(nm.integer("seed", 0, 0, int64_t(1) << 53));
      nm.finish();
    }
    if (auto mx = m->get("max")) max = mx->asNumber(diags, "'max'", double(solids::kMinSpeed), 1e6);
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

}  // namespace

FieldPtr redistanced(FieldPtr child) { return solids::frontField(std::move(child), solids::uniformSpeed(1.0f), 1.0, false); }

std::optional<VelocityWrap> readVelocity(const YNode& node, DiagnosticList& diags, const PolyMesh* mesh, bool redistance) {
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
  if (auto e = m.get("expression")) {
    if (auto text = e->asString(diags, "'expression'")) out = readExpression(*e, *text, &m, diags);
  } else if (auto p = m.section("painted")) {
    MapReader pm(*p, diags, "painted");
    const double low = pm.number("low", 1.0, double(solids::kMinSpeed), 1e6);
    const double high = pm.number("high", 2.0, double(solids::kMinSpeed), 1e6);
    pm.finish();
    if (!mesh) {
      p->error(diags, "a painted velocity belongs on a surface_mesh (its vertex colours are the paint)");
    } else if (mesh->colors.size() != mesh->positions.size()) {
      p->error(diags, "a painted velocity needs a mesh with vertex colours (OBJ 'v x y z r g b', PLY red/green/blue)");
    } else {
      auto paint = std::make_shared<NearestVertex>(*mesh, low, high);
      const double top = std::max(low, high);
      out = VelocityWrap([paint, top](FieldPtr child) -> FieldPtr {
        if (!child) return nullptr;
        auto fn = [paint](const std::vector<Vec3>& pts, std::vector<float>& v) {
          parallelFor(0, pts.size(), [&](size_t i) { v[i] = (*paint)(pts[i]); }, 256);
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
