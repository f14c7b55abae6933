#include "organisms/tree_builder.h"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>
#include <cmath>
#include <optional>

#include "core/diagnostics.h"
#include "core/rng.h"

namespace sprig::organisms {

namespace bt = blobtree;

namespace {

Vec3 f(const DVec3& v) { return Vec3(v); }

/// The part's axis end, nudged off its start when the two coincide.
DVec3 partEnd(const ConePart& p) {
  return glm::length(p.end - p.start) < 1e-9 ? p.start + DVec3(0, 1e-6, 0) : p.end;
}

/// The bend of part p (§3.6), or nothing when it is straight. The tangent angle is capped so
/// the cone's support stays inside the bend radius (ρ = L / (2 sin θ) for tangent angle θ).
std::optional<bt::Bend> partBend(const ConePart& p, bt::Kernel kernel) {
  if (!(p.bendAngle > 0)) return std::nullopt;
  const float r0 = static_cast<float>(std::max(p.startRadius, 1e-6));
  const float r1 = static_cast<float>(std::max(p.endRadius, 1e-6));
  const DVec3 b = partEnd(p);
  const double len = glm::length(b - p.start);
  const double support = bt::supportRadius(kernel, std::max(r0, r1));
  double theta = std::min(p.bendAngle, 0.45 * kPi);
  const double maxSin = len / (2.0 * support * 1.25);
  if (std::sin(theta) > maxSin) theta = maxSin < 1 ? std::asin(maxSin) : theta;
  if (!(theta > 1e-4)) return std::nullopt;
  return bt::Bend::fromAngle(f(p.start), f(b), f(p.bendToward), static_cast<float>(2.0 * theta));
}

/// The index of class c in classes, appended when new.
size_t classIndex(std::vector<BarkClass>& classes, const BarkClass& c) {
  for (size_t i = 0; i < classes.size(); ++i)
    if (classes[i] == c) return i;
  classes.push_back(c);
  return classes.size() - 1;
}

/// The direction of u = 0 around each internode's axis: the root's turtle up vector,
/// carried from parent to child by parallel transport (projected perpendicular to the
/// child's axis), so the bark's furrows run on along a branch where the turtle rolls
/// between internodes (`/` on the 137.5° spiral). Falls back to the internode's own up
/// vector where the projection vanishes.
std::vector<DVec3> barkReferences(const lsystem::Skeleton& sk) {
  std::vector<DVec3> ref(sk.internodes.size());
  auto perpendicular = [](DVec3 v, DVec3 axis) {
    const double len = glm::length(axis);
    if (len < 1e-12) return DVec3(0);
    axis /= len;
    v -= glm::dot(v, axis) * axis;
    const double l = glm::length(v);
    return l < 1e-6 ? DVec3(0) : v / l;
  };
  for (size_t i = 0; i < sk.internodes.size(); ++i) {
    const lsystem::Internode& in = sk.internodes[i];
    const DVec3 axis = in.end - in.start;
    DVec3 r(0);
    if (in.parent >= 0 && static_cast<size_t>(in.parent) < i) r = perpendicular(ref[size_t(in.parent)], axis);
    if (glm::length(r) == 0) r = perpendicular(in.up, axis);
    ref[i] = glm::length(r) == 0 ? in.up : r;
  }
  return ref;
}

// The cone of one part, bent when the plan says so.
bt::NodeId partNode(bt::BlobTree& tree, const ConePart& p, const std::vector<DVec3>& barkRef, const TreeOptions& opt,
                    std::vector<BarkClass>& barkClasses) {
  bt::TextureAttr tex;
  if (opt.bark.enabled) {
    const size_t cls = classIndex(barkClasses, barkClassFor(opt.bark, 0.5 * (p.startRadius + p.endRadius)));
    // At most 4094 furrow counts x 9 ages = 36,846 classes after texture <= 16383 (the
    // species reader's range): the ids stay below kNoTexture.
    if (opt.bark.texture < 0 || opt.bark.texture + cls > 65534)
      throw std::logic_error("buildTreeBlob: bark texture id " + std::to_string(opt.bark.texture + cls) +
                             " out of range");
    tex.textureId = static_cast<uint16_t>(opt.bark.texture + cls);
    tex.uvScale = Vec2(static_cast<float>(opt.bark.uScale), static_cast<float>(opt.bark.vScale));
    tex.vOffset = static_cast<float>(p.vStart);
    tex.refDir = f(barkRef[size_t(p.internode)]);
  }
  const float r0 = static_cast<float>(std::max(p.startRadius, 1e-6));
  const float r1 = static_cast<float>(std::max(p.endRadius, 1e-6));
  const DVec3 b = partEnd(p);
  bt::NodeId id = tree.cone(f(p.start), f(b), r0, r1, tex);

  if (auto bend = partBend(p, tree.kernel())) id = tree.bend(id, *bend);
  if (p.kind == ConePart::Kind::Pruned) {
    const bt::NodeId saw = tree.halfspace(f(p.cutPoint), f(p.cutNormal));
    const bt::NodeId both[2] = {id, saw};
    id = tree.intersect(both);
  }
  return id;
}

/// The ridge arcs of junction j (see ridgeArcs).
std::vector<textures::RidgeArc> junctionArcs(const TreePlan& plan, const Junction& j) {
  std::vector<textures::RidgeArc> out;
  const std::vector<ConePart>& parts = plan.parts;
  auto direction = [](const ConePart& p) {
    const DVec3 chord = p.end - p.start;
    const double len = glm::length(chord);
    if (!(len > 0)) return DVec3(0.0);
    // A bent cone leaves its start along the chord turned by the bend angle toward the bow.
    return std::cos(p.bendAngle) * (chord / len) + std::sin(p.bendAngle) * p.bendToward;
  };
  if (j.branches.size() < 2 || j.basal < 0) return out;
  const ConePart& basal = parts[static_cast<size_t>(j.basal)];
  const DVec3 up = direction(basal);
  int32_t leader = -1;
  double best = -2;
  for (int32_t b : j.branches) {
    const double c = glm::dot(direction(parts[static_cast<size_t>(b)]), up);
    if (c > best) best = c, leader = b;
  }
  const ConePart& lead = parts[static_cast<size_t>(leader)];
  const DVec3 axis = direction(lead);
  for (int32_t b : j.branches) {
    if (b == leader) continue;
    const ConePart& branch = parts[static_cast<size_t>(b)];
    textures::RidgeArc arc;
    arc.point = Vec3(j.point);
    arc.parentAxis = Vec3(axis);
    arc.branchAxis = Vec3(direction(branch));
    arc.parentRadius = static_cast<float>(std::max(basal.endRadius, lead.startRadius));
    arc.branchRadius = static_cast<float>(branch.startRadius);
    out.push_back(arc);
  }
  return out;
}

/// Where F(p + t·n) crosses 0.5 going outward in [lo, hi] (F(lo) > 0.5 >= F(hi)), by
/// bisection; nullopt when the span does not bracket a crossing.
template <class F>
std::optional<double> crossing(const F& field, double lo, double hi) {
  if (!(field(lo) > 0.5) || field(hi) > 0.5) return std::nullopt;
  for (int k = 0; k < 40; ++k) {
    const double mid = 0.5 * (lo + hi);
    (field(mid) > 0.5 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

BarkClass barkClassFor(const BarkOptions& bark, double r) {
  BarkClass c{bark.pattern.furrows, bark.pattern.maturity};
  if (bark.ridgeWidth > 0) {
    const double n = std::round(2 * kPi * std::max(0.0, r) / bark.ridgeWidth);
    c.furrows = static_cast<int>(std::clamp(n, 3.0, 4096.0));
  }
  if (bark.matureRadius > 0) c.maturity = std::min(1.0, std::round(8 * std::max(0.0, r) / bark.matureRadius) / 8);
  return c;
}

TreeBlob buildTreeBlob(const lsystem::Skeleton& skeleton, const TreeOptions& opt) {
  if (skeleton.internodes.empty()) throw InputError(SourceLoc{}, "tree skeleton has no internode");
  TreeBlob out{bt::BlobTree(opt.softKernel ? bt::Kernel::SoftObject : bt::Kernel::Wyvill), 0,
               planTree(skeleton, opt), {}};
  bt::BlobTree& tree = out.tree;
  const TreePlan& plan = out.plan;

  out.partNodes.reserve(plan.parts.size());
  const std::vector<DVec3> barkRef = barkReferences(skeleton);
  for (const ConePart& p : plan.parts) out.partNodes.push_back(partNode(tree, p, barkRef, opt, out.barkClasses));

  std::vector<bt::NodeId> negatives;
  for (const ConePart& p : plan.parts)
    if (p.kind == ConePart::Kind::Stub && p.negativeRadius > 0 && p.negativeWeight > 0)
      negatives.push_back(tree.negative(tree.point(f(p.negativeCenter), static_cast<float>(p.negativeRadius)),
                                        static_cast<float>(p.negativeWeight)));

  bt::NodeId body;
  if (!opt.controlledBlend) {
    // Everything blends with everything (the comparison case of controlled blending).
    body = tree.blend(out.partNodes);
  } else {
    bt::PcmParams pcm;
    pcm.width = static_cast<float>(opt.pcmWidth);
    pcm.bulgeScale = static_cast<float>(opt.pcmBulge);
    std::vector<bt::NodeId> groups;
    groups.reserve(plan.junctions.size() + 1);
    for (const Junction& j : plan.junctions) {
      std::vector<bt::NodeId> sum{out.partNodes[j.basal]}, contact;
      for (int32_t b : j.branches) {
        if (j.pcm && plan.parts[b].kind != ConePart::Kind::Stub)
          contact.push_back(out.partNodes[b]);
        else
          sum.push_back(out.partNodes[b]);
      }
      if (contact.size() == 1) sum.push_back(contact[0]);
      if (contact.size() > 1) sum.push_back(tree.pcm(contact, pcm));  // Eq. 5
      bt::NodeId group = tree.blend(sum);                             // Eq. 6
      if (opt.bark.ridgeArc.height > 0) {
        // The raised branch bark ridges over the junction's branches, summed into it.
        std::vector<bt::NodeId> raised{group};
        for (const textures::RidgeArc& arc : junctionArcs(plan, j))
          if (auto ridge = raisedRidgeArc(tree, group, arc, opt.bark.ridgeArc)) raised.push_back(*ridge);
        if (raised.size() > 1) group = tree.blend(raised);
      }
      groups.push_back(group);
    }
    // Parts in no junction (a lone internode) are their own group.
    for (size_t i = 0; i < plan.parts.size(); ++i)
      if (plan.parts[i].junctionAtStart < 0 && plan.parts[i].junctionAtEnd < 0) groups.push_back(out.partNodes[i]);
    body = groups.size() == 1 ? groups[0] : tree.unite(groups);
  }
  if (negatives.empty()) {
    out.root = body;
  } else {
    negatives.insert(negatives.begin(), body);
    out.root = tree.blend(negatives);
  }
  return out;
}

std::vector<textures::RidgeArc> ridgeArcs(const TreeBlob& blob) {
  std::vector<textures::RidgeArc> out;
  for (const Junction& j : blob.plan.junctions) {
    const std::vector<textures::RidgeArc> arcs = junctionArcs(blob.plan, j);
    out.insert(out.end(), arcs.begin(), arcs.end());
  }
  return out;
}

std::optional<bt::NodeId> raisedRidgeArc(bt::BlobTree& tree, bt::NodeId field, const textures::RidgeArc& arc,
                                         const textures::RidgeArcOptions& options) {
  if (!(options.height > 0)) return std::nullopt;
  // Crest points about a quarter branch radius apart along the crest.
  const double length = 2 * options.spread * std::sqrt(1 + options.droop * options.droop);
  const int count = std::clamp(static_cast<int>(std::ceil(length / 0.25)) + 1, 9, 257);
  const std::vector<textures::RidgeCrestPoint> crest = textures::RidgeArcs::crest(arc, options, count);
  if (crest.empty()) return std::nullopt;
  const double rB = arc.branchRadius;
  const bt::Kernel kernel = tree.kernel();

  // Step 1: per crest point, the axis of the ridge's skeleton. Along the normal n through
  // the crest point c, the surface of `field` lies at t0 (F(c + t0·n) = 0.5). A cone of
  // iso radius r (support R) whose axis crosses that line at depth e below t0 adds
  // g(((t − t0 + e)/R)²); summed with F, the surface moves out to t1. The raise t1 − t0
  // falls from its largest at e = 0 to 0 at e = R (the support just reaches the surface):
  // bisect e so the raise is height·r_B·weight (e = 0 when even that falls short).
  struct Vertex {
    Vec3 axisPoint{0.0f};
    float radius = 0.0f;
    bool raised = false;
  };
  std::vector<Vertex> vertices(crest.size());
  for (size_t i = 0; i < crest.size(); ++i) {
    const textures::RidgeCrestPoint& c = crest[i];
    const DVec3 p(c.position), n(c.normal);
    const double r = c.halfWidth, R = bt::supportRadius(kernel, static_cast<float>(r));
    auto F = [&](double t) { return static_cast<double>(tree.value(field, Vec3(p + t * n))); };
    const std::optional<double> t0 = crossing(F, -0.5 * arc.parentRadius, 0.5 * arc.parentRadius + R);
    Vertex& v = vertices[i];
    v.radius = static_cast<float>(r);
    if (!t0) {  // no bark surface found here: the skeleton stays clear of it
      v.axisPoint = Vec3(p - (0.5 * arc.parentRadius + R) * n);
      continue;
    }
    const double target = options.height * rB * c.weight;
    if (!(target > 0)) {  // the support just reaches the bark: no raise
      v.axisPoint = Vec3(p + (*t0 - R) * n);
      continue;
    }
    // F over [t0, t0 + R], where the raised surface lies, sampled once and interpolated.
    constexpr int kSamples = 48;
    std::array<double, kSamples + 1> Fs;
    for (int k = 0; k <= kSamples; ++k) Fs[size_t(k)] = F(*t0 + R * k / kSamples);
    auto Fat = [&](double t) {
      const double x = std::clamp((t - *t0) / R * kSamples, 0.0, double(kSamples));
      const int k = std::min(static_cast<int>(x), kSamples - 1);
      return Fs[size_t(k)] + (x - k) * (Fs[size_t(k) + 1] - Fs[size_t(k)]);
    };
    auto raise = [&](double e) {
      const double axis = *t0 - e;
      auto G = [&](double t) {
        const double s = (t - axis) * (t - axis) / (R * R);
        return Fat(t) + (s < 1 ? static_cast<double>(bt::kernelValue(kernel, static_cast<float>(s))) : 0.0);
      };
      const std::optional<double> t1 = crossing(G, *t0, axis + R);
      return t1 ? *t1 - *t0 : 0.0;
    };
    double e = 0;
    if (raise(0) > target) {
      double lo = 0, hi = R;
      for (int k = 0; k < 30; ++k) {
        const double mid = 0.5 * (lo + hi);
        (raise(mid) > target ? lo : hi) = mid;
      }
      e = 0.5 * (lo + hi);
    }
    v.raised = true;
    v.axisPoint = Vec3(p + (*t0 - e) * n);
  }

  // Step 2: cones between neighbouring points with a raise at either end, united (the
  // field of the nearest one: a tube along the crest without bulges at the joints).
  bt::TextureAttr relief;
  relief.relief = true;
  std::vector<bt::NodeId> cones;
  for (size_t i = 0; i + 1 < vertices.size(); ++i) {
    if (!vertices[i].raised && !vertices[i + 1].raised) continue;
    cones.push_back(tree.cone(vertices[i].axisPoint, vertices[i + 1].axisPoint, vertices[i].radius,
                              vertices[i + 1].radius, relief));
  }
  if (cones.empty()) return std::nullopt;
  return cones.size() == 1 ? cones[0] : tree.unite(cones);
}

CurveSet treeAxes(const TreeBlob& blob) {
  CurveSet out;
  constexpr int kArcSegments = 4;
  for (const ConePart& p : blob.plan.parts) {
    if (p.kind != ConePart::Kind::Internode) continue;
    const DVec3 b = partEnd(p);
    const auto bend = partBend(p, blob.tree.kernel());
    const int n = bend ? kArcSegments : 1;
    const uint32_t first = static_cast<uint32_t>(out.vertices.size());
    for (int k = 0; k <= n; ++k) {
      const double s = static_cast<double>(k) / n;
      Vec3 x = f(p.start + s * (b - p.start));
      if (bend) x = bend->worldFromLocal(x);
      out.vertices.emplace_back(x, static_cast<float>((1.0 - s) * p.startRadius + s * p.endRadius));
    }
    for (int k = 0; k < n; ++k) {
      out.segments.push_back(first + static_cast<uint32_t>(k));
      out.flags.push_back(static_cast<uint8_t>((k > 0 ? CurveSet::kJoinedBefore : 0) |
                                               (k + 1 < n ? CurveSet::kJoinedAfter : 0)));
    }
  }
  return out;
}

namespace {

struct LeafWriter {
  Mesh& mesh;
  uint32_t material;

  uint32_t vertex(const DVec3& p, const DVec3& n, Vec2 uv, Vec3 color) {
    mesh.positions.push_back(f(p));
    mesh.normals.push_back(glm::normalize(f(n)));
    mesh.uvs.push_back(uv);
    mesh.colors.push_back(color);
    return static_cast<uint32_t>(mesh.positions.size() - 1);
  }
  void tri(uint32_t a, uint32_t b, uint32_t c) {
    mesh.triangles.emplace_back(a, b, c);
    mesh.materials.push_back(material);
  }
};

Vec3 leafColor(int colorIndex, Rng& rng) {
  static const Vec3 kPalette[] = {{0.16f, 0.40f, 0.09f}, {0.35f, 0.52f, 0.12f}, {0.70f, 0.12f, 0.10f},
                                  {0.92f, 0.90f, 0.85f}, {0.90f, 0.55f, 0.70f}, {0.85f, 0.70f, 0.10f}};
  const Vec3 base = kPalette[static_cast<size_t>(std::clamp(colorIndex, 0, 5))];
  const float k = static_cast<float>(rng.uniform(0.85, 1.15));
  return glm::clamp(base * k, Vec3(0.0f), Vec3(1.0f));
}

// Ovate blade: half-width at fraction y of the length.
double bladeHalfWidth(double y) { return 0.38 * std::pow(std::sin(kPi * std::pow(y, 0.75)), 0.9); }

void addBlade(LeafWriter& w, const lsystem::Organ& o, double scale, Vec3 color) {
  constexpr int kRows = 8;
  const DVec3 h = glm::normalize(o.heading), right = -glm::normalize(o.left), up = glm::normalize(o.up);
  const double s = (o.radius > 0 ? o.radius : 1.0) * scale;
  auto at = [&](double x, double y) { return o.position + s * (y * h + x * right); };
  auto uv = [](double x, double y) { return Vec2(static_cast<float>(0.5 + x), static_cast<float>(y)); };
  const uint32_t base = w.vertex(at(0, 0), up, uv(0, 0), color);
  std::vector<uint32_t> L, M, R;
  for (int k = 1; k < kRows; ++k) {
    const double y = static_cast<double>(k) / kRows, hw = bladeHalfWidth(y);
    L.push_back(w.vertex(at(-hw, y), up, uv(-hw, y), color));
    M.push_back(w.vertex(at(0, y), up, uv(0, y), color));
    R.push_back(w.vertex(at(hw, y), up, uv(hw, y), color));
  }
  const uint32_t tip = w.vertex(at(0, 1), up, uv(0, 1), color);
  w.tri(base, R[0], M[0]);
  w.tri(base, M[0], L[0]);
  for (size_t k = 0; k + 1 < M.size(); ++k) {
    w.tri(M[k], R[k], R[k + 1]);
    w.tri(M[k], R[k + 1], M[k + 1]);
    w.tri(M[k], M[k + 1], L[k + 1]);
    w.tri(M[k], L[k + 1], L[k]);
  }
  w.tri(M.back(), R.back(), tip);
  w.tri(M.back(), tip, L.back());
}

/// A cpfg surface file's mesh, placed by the turtle (world units; the leaf scale does not
/// apply: the view file's size is the surface's size). uv: the vertex's x and y relative to
/// the organ's frame, scaled into [0, 1] per organ.
void addSurfaceMesh(LeafWriter& w, const lsystem::Organ& o, Vec3 color) {
  const uint32_t base = static_cast<uint32_t>(w.mesh.positions.size());
  for (size_t k = 0; k < o.points.size(); ++k) {
    const DVec3 n = k < o.normals.size() && glm::length(o.normals[k]) > 0 ? o.normals[k] : o.up;
    w.vertex(o.points[k], n, Vec2(0.5f, static_cast<float>(k) / static_cast<float>(std::max<size_t>(1, o.points.size() - 1))), color);
  }
  for (size_t k = 0; k + 2 < o.triangles.size(); k += 3)
    w.tri(base + o.triangles[k], base + o.triangles[k + 1], base + o.triangles[k + 2]);
}

void addPolygon(LeafWriter& w, const lsystem::Organ& o, Vec3 color) {
  if (o.points.size() < 3) return;
  DVec3 n(0);  // Newell normal
  for (size_t i = 0; i < o.points.size(); ++i) {
    const DVec3& a = o.points[i];
    const DVec3& b = o.points[(i + 1) % o.points.size()];
    n += DVec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
  }
  if (glm::length(n) < 1e-20) return;
  n = glm::normalize(n);
  const DVec3 e0 = glm::length(o.points[1] - o.points[0]) > 0 ? glm::normalize(o.points[1] - o.points[0])
                                                                : DVec3(1, 0, 0);
  const DVec3 e1 = glm::cross(n, e0);
  DBox3 box;
  std::vector<DVec3> plane;
  for (const DVec3& p : o.points) {
    const DVec3 q(glm::dot(p - o.points[0], e0), glm::dot(p - o.points[0], e1), 0);
    plane.push_back(q);
    box.extend(q);
  }
  const DVec3 size = glm::max(box.size(), DVec3(1e-12));
  const uint32_t first = static_cast<uint32_t>(w.mesh.positions.size());
  for (size_t i = 0; i < o.points.size(); ++i) {
    const DVec3 t = (plane[i] - box.lo) / size;
    w.vertex(o.points[i], n, Vec2(static_cast<float>(t.x), static_cast<float>(t.y)), color);
  }
  for (uint32_t i = 1; i + 1 < o.points.size(); ++i) w.tri(first, first + i, first + i + 1);
}

void addSphere(LeafWriter& w, const lsystem::Organ& o, Vec3 color) {
  constexpr int kLat = 6, kLon = 10;
  const uint32_t first = static_cast<uint32_t>(w.mesh.positions.size());
  for (int i = 0; i <= kLat; ++i) {
    const double th = kPi * i / kLat;
    for (int j = 0; j <= kLon; ++j) {
      const double ph = 2.0 * kPi * j / kLon;
      const DVec3 n(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
      w.vertex(o.position + o.radius * n, n,
               Vec2(static_cast<float>(j) / kLon, static_cast<float>(i) / kLat), color);
    }
  }
  for (int i = 0; i < kLat; ++i)
    for (int j = 0; j < kLon; ++j) {
      const uint32_t a = first + static_cast<uint32_t>(i * (kLon + 1) + j), b = a + kLon + 1;
      if (i > 0) w.tri(a, a + 1, b);
      if (i + 1 < kLat) w.tri(a + 1, b + 1, b);
    }
}

}  // namespace

namespace {

Mesh organMesh(const lsystem::Skeleton& skeleton, const TreeOptions& opt, std::optional<OrganSet> set) {
  Mesh mesh;
  if (!opt.leaves.enabled) return mesh;
  LeafWriter w{mesh, opt.leaves.material};
  constexpr uint64_t kSeedLeaf = 0x4c454146ull;
  for (size_t i = 0; i < skeleton.organs.size(); ++i) {
    const auto& o = skeleton.organs[i];
    if (set && (*set == OrganSet::Fruit) != (o.kind == lsystem::Organ::Kind::Sphere)) continue;
    if (o.texture >= 0 && !o.triangles.empty()) continue;  // a textured cpfg surface: model/tree_kind.cpp draws it
    Rng rng(deriveSeed(opt.seed, {kSeedLeaf, static_cast<uint64_t>(i)}));
    const Vec3 color = leafColor(o.color, rng);
    switch (o.kind) {
      case lsystem::Organ::Kind::Polygon: addPolygon(w, o, color); break;
      case lsystem::Organ::Kind::Sphere: addSphere(w, o, color); break;
      case lsystem::Organ::Kind::Surface:
        if (o.triangles.empty()) addBlade(w, o, opt.leaves.scale, color);
        else addSurfaceMesh(w, o, color);
        break;
    }
  }
  return mesh;
}

}  // namespace

Mesh buildLeafMesh(const lsystem::Skeleton& skeleton, const TreeOptions& opt) { return organMesh(skeleton, opt, std::nullopt); }

Mesh buildOrganMesh(const lsystem::Skeleton& skeleton, const TreeOptions& opt, OrganSet set) {
  return organMesh(skeleton, opt, set);
}

}  // namespace sprig::organisms
