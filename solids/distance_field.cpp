#include "solids/distance_field.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <stdexcept>

#include "core/parallel.h"
#include "solids/detail/mesh_distance_backend.h"

namespace sprig::solids {

namespace {

/// Analytic fields: one function of the point.
template <class F>
class AnalyticField final : public DistanceField {
 public:
  AnalyticField(F f, std::optional<DBox3> box) : f_(std::move(f)), box_(box) {}
  std::vector<float> sample(const std::vector<Vec3>& points, double, double) const override {
    std::vector<float> out(points.size());
    parallelFor(0, points.size(), [&](size_t i) { out[i] = float(f_(DVec3(points[i]))); }, 4096);
    return out;
  }
  std::optional<DBox3> bounds() const override { return box_; }

 private:
  F f_;
  std::optional<DBox3> box_;
};

template <class F>
FieldPtr analytic(F f, std::optional<DBox3> box) {
  return std::make_shared<AnalyticField<F>>(std::move(f), box);
}

/// A closed triangle mesh: OpenVDB's narrow-band signed distance, sampled trilinearly.
class MeshField final : public DistanceField {
 public:
  explicit MeshField(const PolyMesh& mesh) : points_(mesh.positions) {
    size_t c = 0;
    for (uint32_t n : mesh.faceSizes) {  // fan triangulation
      for (uint32_t k = 1; k + 1 < n; ++k)
        // The inside is found by OpenVDB's flood fill (closed meshes only: checked by the reader).
        tris_.emplace_back(mesh.faceVertices[c], mesh.faceVertices[c + k], mesh.faceVertices[c + k + 1]);
      c += n;
    }
    if (tris_.empty()) throw std::invalid_argument("the mesh has no faces");
    box_ = DBox3{};
    for (const Vec3& p : mesh.positions) box_.extend(DVec3(p));
  }

  std::vector<float> sample(const std::vector<Vec3>& points, double cell, double band) const override {
    std::vector<float> out(points.size());
    if (points.empty()) return out;
    // The grid's voxel centres fall on the lattice of points[0] (exact values at lattice nodes).
    const float bandVoxels = float(band / cell) + 1.0f;
    const std::unique_ptr<detail::DistanceGrid> grid =
        detail::meshDistanceBackend().build(points_, tris_, cell, points[0], bandVoxels);
    parallelForRange(0, points.size(), [&](size_t b, size_t e) { grid->sample(&points[b], e - b, &out[b]); }, 4096);
    return out;
  }
  std::optional<DBox3> bounds() const override { return box_; }

 private:
  std::vector<Vec3> points_;
  std::vector<glm::uvec3> tris_;
  DBox3 box_;
};

/// Union or intersection of children.
class MinMaxField final : public DistanceField {
 public:
  MinMaxField(std::vector<FieldPtr> children, bool isMax) : children_(std::move(children)), max_(isMax) {
    if (children_.empty()) throw std::invalid_argument("a combination needs at least one distance field");
  }
  std::vector<float> sample(const std::vector<Vec3>& points, double cell, double band) const override {
    std::vector<float> out = children_[0]->sample(points, cell, band);
    for (size_t c = 1; c < children_.size(); ++c) {
      const std::vector<float> v = children_[c]->sample(points, cell, band);
      for (size_t i = 0; i < out.size(); ++i) out[i] = max_ ? std::max(out[i], v[i]) : std::min(out[i], v[i]);
    }
    return out;
  }
  std::optional<DBox3> bounds() const override {
    std::optional<DBox3> box;
    for (const FieldPtr& c : children_) {
      std::optional<DBox3> b = c->bounds();
      if (max_) {  // intersection: inside every child's box
        if (b) box = box ? box->intersected(*b) : *b;
      } else {  // union: unbounded when any child is
        if (!b) return std::nullopt;
        if (!box) box = *b; else box->extend(*b);
      }
    }
    return box;
  }
  double reach() const override {
    double r = 0;
    for (const FieldPtr& c : children_) r = std::max(r, c->reach());
    return r;
  }

 private:
  std::vector<FieldPtr> children_;
  bool max_;
};

class SubtractionField final : public DistanceField {
 public:
  SubtractionField(FieldPtr a, FieldPtr b) : a_(std::move(a)), b_(std::move(b)) {}
  std::vector<float> sample(const std::vector<Vec3>& points, double cell, double band) const override {
    std::vector<float> out = a_->sample(points, cell, band);
    const std::vector<float> v = b_->sample(points, cell, band);
    for (size_t i = 0; i < out.size(); ++i) out[i] = std::max(out[i], -v[i]);
    return out;
  }
  std::optional<DBox3> bounds() const override { return a_->bounds(); }
  double reach() const override { return std::max(a_->reach(), b_->reach()); }

 private:
  FieldPtr a_, b_;
};

/// Rodrigues' rotation of q by angle (radians) about unit u.
DVec3 rotate(const DVec3& q, const DVec3& u, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return q * c + glm::cross(u, q) * s + u * glm::dot(u, q) * (1 - c);
}

class TransformField final : public DistanceField {
 public:
  TransformField(FieldPtr child, double scale, DVec3 axis, double angleDeg, DVec3 t)
      : child_(std::move(child)), s_(scale), u_(glm::normalize(axis)), angle_(angleDeg * M_PI / 180.0), t_(t) {
    if (!(scale > 0)) throw std::invalid_argument("the scale must be positive");
  }
  std::vector<float> sample(const std::vector<Vec3>& points, double cell, double band) const override {
    std::vector<Vec3> local(points.size());
    parallelFor(0, points.size(), [&](size_t i) { local[i] = Vec3(toChild(DVec3(points[i]))); }, 4096);
    std::vector<float> out = child_->sample(local, cell / s_, band / s_);
    for (float& v : out) v = float(v * s_);
    return out;
  }
  std::optional<DBox3> bounds() const override {
    std::optional<DBox3> b = child_->bounds();
    if (!b) return std::nullopt;
    DBox3 out;
    for (int k = 0; k < 8; ++k) {
      const DVec3 corner((k & 1) ? b->hi.x : b->lo.x, (k & 2) ? b->hi.y : b->lo.y, (k & 4) ? b->hi.z : b->lo.z);
      out.extend(rotate(corner * s_, u_, angle_) + t_);
    }
    return out;
  }
  double reach() const override { return child_->reach(); }

 private:
  DVec3 toChild(const DVec3& p) const { return rotate(p - t_, u_, -angle_) / s_; }
  FieldPtr child_;
  double s_;
  DVec3 u_;
  double angle_;
  DVec3 t_;
};

/// The child grown by d: its value less d, so the zero set moves d outward. Asks the child
/// for a band d wider, so values near the new zero set and its layers are not clamped.
class OffsetField final : public DistanceField {
 public:
  OffsetField(FieldPtr child, double d) : child_(std::move(child)), d_(d) {
    if (!(d >= 0)) throw std::invalid_argument("the offset must not be negative");
  }
  std::vector<float> sample(const std::vector<Vec3>& points, double cell, double band) const override {
    std::vector<float> out = child_->sample(points, cell, band + d_);
    for (float& v : out) v = float(double(v) - d_);
    return out;
  }
  std::optional<DBox3> bounds() const override {
    std::optional<DBox3> b = child_->bounds();
    if (!b) return std::nullopt;
    return DBox3{b->lo - d_, b->hi + d_};
  }
  double reach() const override { return child_->reach(); }

 private:
  FieldPtr child_;
  double d_;
};

}  // namespace

FieldPtr meshField(const PolyMesh& mesh) { return std::make_shared<MeshField>(mesh); }

FieldPtr sphereField(const DVec3& c, double r) {
  return analytic([c, r](const DVec3& p) { return glm::length(p - c) - r; }, DBox3{c - r, c + r});
}

FieldPtr boxField(const DVec3& c, const DVec3& size) {
  const DVec3 h = size * 0.5;
  return analytic(
      [c, h](const DVec3& p) {
        const DVec3 q = glm::abs(p - c) - h;
        return glm::length(glm::max(q, DVec3(0.0))) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
      },
      DBox3{c - h, c + h});
}

FieldPtr cylinderField(const DVec3& c, double radius, double height, const DVec3& axis) {
  const DVec3 a = glm::normalize(axis);
  const double r = std::max(radius, height * 0.5);
  return analytic(
      [c, radius, height, a](const DVec3& p) {
        const DVec3 q = p - c;
        const double h = glm::dot(q, a);
        const double dr = glm::length(q - h * a) - radius, dh = std::abs(h) - height * 0.5;
        return std::hypot(std::max(dr, 0.0), std::max(dh, 0.0)) + std::min(std::max(dr, dh), 0.0);
      },
      DBox3{c - r * 1.0000001, c + r * 1.0000001});
}

FieldPtr groundPlaneField(const DVec3& normal, double height) {
  const DVec3 n = glm::normalize(normal);
  return analytic([n, height](const DVec3& p) { return glm::dot(n, p) - height; }, std::nullopt);
}

FieldPtr unionField(std::vector<FieldPtr> fields) { return std::make_shared<MinMaxField>(std::move(fields), false); }
FieldPtr intersectionField(std::vector<FieldPtr> fields) { return std::make_shared<MinMaxField>(std::move(fields), true); }
FieldPtr subtractionField(FieldPtr a, FieldPtr b) { return std::make_shared<SubtractionField>(std::move(a), std::move(b)); }
FieldPtr transformField(FieldPtr child, double scale, const DVec3& axis, double angleDeg, const DVec3& t) {
  return std::make_shared<TransformField>(std::move(child), scale, axis, angleDeg, t);
}
FieldPtr offsetField(FieldPtr child, double by) { return std::make_shared<OffsetField>(std::move(child), by); }

std::optional<OpenEdge> firstOpenEdge(const PolyMesh& mesh) {
  std::map<std::pair<uint32_t, uint32_t>, int> uses;
  auto edges = [&](auto&& visit) {
    size_t c = 0;
    for (size_t f = 0; f < mesh.faceSizes.size(); ++f) {
      const uint32_t n = mesh.faceSizes[f];
      for (uint32_t k = 0; k < n; ++k) visit(f, mesh.faceVertices[c + k], mesh.faceVertices[c + (k + 1) % n]);
      c += n;
    }
  };
  edges([&](size_t, uint32_t a, uint32_t b) { ++uses[{std::min(a, b), std::max(a, b)}]; });
  std::optional<OpenEdge> open;
  edges([&](size_t f, uint32_t a, uint32_t b) {
    if (!open && uses[{std::min(a, b), std::max(a, b)}] == 1) open = OpenEdge{a, b, f};
  });
  return open;
}

}  // namespace sprig::solids
