#include "organisms/skeleton_geometry.h"

#include <algorithm>
#include <cmath>

namespace sprig::organisms {

namespace {

Vec3 toVec3(const DVec3& v) { return Vec3(static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)); }

/// True when the round segment a-c with radii ra, rc is the union of the segments a-b and
/// b-c (radii ra, rb, rc): b lies on a-c (the directions agree to 1e-9) and rb is the linear
/// interpolation of ra and rc at b (to 1e-9 of the larger radius). Then the joint at b is
/// dropped without changing the shape: a straight run of equal internodes (`F F F ...`) is
/// few segments. Merged segments stay at most kMaxMergedAspect times as long as their
/// radius: Embree's float intersection of a round segment loses hits along one that is
/// hundreds of radii long (an 8-million-F axiom drawn as one segment showed gaps).
constexpr double kMaxMergedAspect = 16.0;

bool mergeable(const DVec3& a, double ra, const DVec3& b, double rb, const DVec3& c, double rc) {
  const DVec3 d1 = b - a, d2 = c - b;
  const double l1 = glm::length(d1), l2 = glm::length(d2);
  if (!(l1 > 0) || !(l2 > 0) || glm::dot(d1, d2) <= 0) return false;
  if (l1 + l2 > kMaxMergedAspect * std::max(ra, rc)) return false;
  if (glm::length(glm::cross(d1, d2)) > 1e-9 * l1 * l2) return false;
  const double t = l1 / (l1 + l2);
  return std::abs(rb - (ra + t * (rc - ra))) <= 1e-9 * std::max(ra, rc);
}

/// Internodes as curve chains: each internode is chained with the first child that starts
/// where it ends (a continuation of the same order first, then any child), so joints are
/// shared vertices of one curve rather than two overlapping caps. Collinear joints whose
/// radius is the interpolation of its neighbours' are merged (see mergeable).
CurveSet internodeCurves(const lsystem::Skeleton& skeleton, double radiusScale, double minRadius) {
  CurveSet out;
  const auto& nodes = skeleton.internodes;
  if (nodes.empty()) return out;
  auto radiusD = [&](double r) { return std::max(r * radiusScale, minRadius); };
  auto radius = [&](double r) { return static_cast<float>(radiusD(r)); };
  std::vector<int32_t> next(nodes.size(), -1);
  std::vector<char> continues(nodes.size(), 0);
  for (int pass = 0; pass < 2; ++pass) {
    for (size_t i = 0; i < nodes.size(); ++i) {
      int32_t p = nodes[i].parent;
      if (p < 0 || static_cast<size_t>(p) >= nodes.size() || next[p] >= 0 || continues[i]) continue;
      if (pass == 0 && nodes[i].order != nodes[p].order) continue;
      double tol = 1e-6 * std::max(1.0, nodes[p].length());
      if (glm::length(nodes[i].start - nodes[p].end) <= tol) {
        next[p] = static_cast<int32_t>(i);
        continues[i] = 1;
      }
    }
  }
  for (size_t i = 0; i < nodes.size(); ++i) {
    if (continues[i]) continue;
    out.vertices.emplace_back(toVec3(nodes[i].start), radius(nodes[i].baseRadius));
    // The current segment's start and end in double precision, for mergeable().
    DVec3 runStart = nodes[i].start, runEnd{0};
    double runStartRadius = radiusD(nodes[i].baseRadius), runEndRadius = 0;
    bool firstInChain = true;
    for (int32_t k = static_cast<int32_t>(i); k >= 0; k = next[k]) {
      const auto& n = nodes[k];
      double tip = next[k] >= 0 ? 0.5 * (n.tipRadius + nodes[next[k]].baseRadius) : n.tipRadius;
      if (!firstInChain && mergeable(runStart, runStartRadius, runEnd, runEndRadius, n.end, radiusD(tip))) {
        out.vertices.back() = Vec4(toVec3(n.end), radius(tip));
        runEnd = n.end;
        runEndRadius = radiusD(tip);
        if (next[k] < 0) out.flags.back() &= static_cast<uint8_t>(~CurveSet::kJoinedAfter);
        continue;
      }
      if (!firstInChain) {
        runStart = runEnd;
        runStartRadius = runEndRadius;
      }
      runEnd = n.end;
      runEndRadius = radiusD(tip);
      out.segments.push_back(static_cast<uint32_t>(out.vertices.size() - 1));
      out.vertices.emplace_back(toVec3(n.end), radius(tip));
      uint8_t f = 0;
      if (!firstInChain) f |= CurveSet::kJoinedBefore;
      if (next[k] >= 0) f |= CurveSet::kJoinedAfter;
      out.flags.push_back(f);
      firstInChain = false;
    }
  }
  return out;
}

/// Appends a flat polygon, fan-triangulated, with its Newell normal; skips degenerate ones.
void addFlatPolygon(SkeletonGeometry& g, const std::vector<Vec3>& pts, const Vec3& color) {
  if (pts.size() < 3) return;
  Vec3 normal(0);
  for (size_t k = 0; k < pts.size(); ++k) normal += glm::cross(pts[k], pts[(k + 1) % pts.size()]);  // Newell
  float len = glm::length(normal);
  if (!(len > 0)) return;
  normal /= len;
  uint32_t base = static_cast<uint32_t>(g.leaves.positions.size());
  for (const Vec3& p : pts) {
    g.leaves.positions.push_back(p);
    g.leaves.normals.push_back(normal);
  }
  for (uint32_t k = 1; k + 1 < pts.size(); ++k) {
    g.leaves.triangles.emplace_back(base, base + k, base + k + 1);
    g.leafColors.push_back(color);
  }
}

}  // namespace

SkeletonGeometry buildSkeletonGeometry(const lsystem::Skeleton& skeleton, const SkeletonGeometryOptions& o) {
  SkeletonGeometry g;
  const DBox3 box = skeleton.bounds();
  const double minRadius = box.empty() ? 0.0 : o.minRadiusFraction * glm::length(box.size());
  g.internodes = internodeCurves(skeleton, o.radiusScale, minRadius);
  if (!o.organs) return g;

  auto organColor = [&](const lsystem::Organ& organ, const Vec3& fallback) {
    return organ.color > 0 && static_cast<size_t>(organ.color) < o.palette.size() ? o.palette[organ.color] : fallback;
  };
  const double surfaceScale = box.empty() ? 1.0 : 0.02 * glm::length(box.size());
  for (const auto& organ : skeleton.organs) {
    if (organ.kind == lsystem::Organ::Kind::Polygon) {
      if (organ.texture >= 0) continue;  // textured (`@Tx`): left to the caller, as surfaces
      std::vector<Vec3> pts;
      for (const auto& p : organ.points) pts.push_back(toVec3(p));
      addFlatPolygon(g, pts, organColor(organ, o.leafColor));
    } else if (organ.kind == lsystem::Organ::Kind::Surface && !organ.triangles.empty()) {
      // A cpfg surface file's mesh, placed by the turtle; a textured one (`@Tx`) is left to
      // the caller, which holds the view file's images (model/tree_kind.cpp).
      if (organ.texture >= 0) continue;
      const Vec3 color = organColor(organ, o.leafColor);
      const uint32_t base = static_cast<uint32_t>(g.leaves.positions.size());
      for (size_t k = 0; k < organ.points.size(); ++k) {
        g.leaves.positions.push_back(toVec3(organ.points[k]));
        g.leaves.normals.push_back(k < organ.normals.size() ? toVec3(organ.normals[k]) : toVec3(organ.up));
      }
      for (size_t k = 0; k + 2 < organ.triangles.size(); k += 3) {
        g.leaves.triangles.emplace_back(base + organ.triangles[k], base + organ.triangles[k + 1], base + organ.triangles[k + 2]);
        g.leafColors.push_back(color);
      }
    } else if (organ.kind == lsystem::Organ::Kind::Surface) {
      // A named surface is drawn as a diamond leaf in the turtle's heading-left plane.
      double s = organ.radius > 0 ? organ.radius : surfaceScale;
      DVec3 h = organ.heading * s, l = organ.left * (0.35 * s);
      addFlatPolygon(g,
                     {toVec3(organ.position), toVec3(organ.position + 0.5 * h + l), toVec3(organ.position + h),
                      toVec3(organ.position + 0.5 * h - l)},
                     organColor(organ, o.leafColor));
    }
  }
  for (const auto& organ : skeleton.organs) {
    if (organ.kind != lsystem::Organ::Kind::Sphere || !(organ.radius > 0)) continue;
    g.fruit.spheres.emplace_back(toVec3(organ.position), static_cast<float>(organ.radius * o.radiusScale));
    g.fruit.colors.push_back(organColor(organ, o.fruitColor));
  }
  return g;
}

}  // namespace sprig::organisms
