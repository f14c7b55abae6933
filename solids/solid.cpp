#include "solids/solid.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <unordered_map>

#include "core/parallel.h"
#include "solids/chunked.h"
#include "solids/octree.h"
#include "core/timer.h"

namespace sprig::solids {

namespace {

using Tet = std::array<uint32_t, 4>;
constexpr int kTetEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
uint64_t edgeKey(uint32_t a, uint32_t b) { return a < b ? (uint64_t(a) << 32) | b : (uint64_t(b) << 32) | a; }

double det(const DVec3& a, const DVec3& b, const DVec3& c, const DVec3& d) {
  return glm::dot(b - a, glm::cross(c - a, d - a));
}

/// Face f (kTetFaces) of tetrahedron q as its three vertex ids, sorted: the key two
/// tetrahedra sharing the face agree on.
std::array<uint32_t, 3> faceKey(const std::array<uint32_t, 4>& q, int f) {
  std::array<uint32_t, 3> k = {q[size_t(kTetFaces[size_t(f)][0])], q[size_t(kTetFaces[size_t(f)][1])], q[size_t(kTetFaces[size_t(f)][2])]};
  std::sort(k.begin(), k.end());
  return k;
}

/// Union-find over 0..n-1 with path halving.
struct DisjointSets {
  std::vector<uint32_t> parent;
  explicit DisjointSets(size_t n) : parent(n) {
    for (size_t i = 0; i < n; ++i) parent[i] = uint32_t(i);
  }
  uint32_t find(uint32_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  }
  void join(uint32_t a, uint32_t b) { parent[find(a)] = find(b); }
};

/// The mesh while it is cut: vertices with every volume's distance, tetrahedra with a flag
/// "no earlier volume claims it".
struct Work {
  std::vector<DVec3> positions;
  std::vector<std::vector<float>> fields;  ///< [volume][vertex]
  std::vector<Tet> tets;
  std::vector<uint8_t> active;
  std::vector<int> tag;  ///< carried to the pieces of a split (a material when clipping)

  /// Per volume, sorted (tetrahedron, field at its centroid) of the tetrahedra whose four
  /// vertices all lie on one of the volume's boundaries (resolveFlatTets).
  std::vector<std::vector<std::pair<uint32_t, float>>> flat;

  double centroidValue(size_t volume, const Tet& t) const {
    const std::vector<float>& f = fields[volume];
    return (double(f[t[0]]) + f[t[1]] + f[t[2]] + f[t[3]]) * 0.25;
  }
  /// The field of volume at tetrahedron t's centroid: linear from its vertices, or the
  /// field itself where all four vertices lie on one boundary (resolveFlatTets).
  double valueAt(size_t volume, size_t t) const {
    const Tet& q = tets[t];
    const std::vector<float>& f = fields[volume];
    if (volume < flat.size() && f[q[0]] == f[q[1]] && f[q[0]] == f[q[2]] && f[q[0]] == f[q[3]]) {
      const auto& list = flat[volume];
      const auto it = std::lower_bound(list.begin(), list.end(), std::make_pair(uint32_t(t), -HUGE_VALF));
      if (it != list.end() && it->first == t) return it->second;
    }
    return centroidValue(volume, q);
  }
};

/// The edges (sorted, unique keys) of tetrahedra t with take(t) for which crosses(a, c).
template <class Take, class Crosses>
std::vector<uint64_t> edgesWhere(const Work& w, Take take, Crosses crosses) {
  std::vector<uint64_t> keys = chunked<uint64_t>(w.tets.size(), [&](size_t lo, size_t hi, std::vector<uint64_t>& out) {
    for (size_t t = lo; t < hi; ++t) {
      if (!take(t)) continue;
      const Tet& q = w.tets[t];
      for (const auto& e : kTetEdges)
        if (crosses(q[e[0]], q[e[1]])) out.push_back(edgeKey(q[e[0]], q[e[1]]));
    }
  });
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  return keys;
}

/// Splits, in every tetrahedron of w that has them, the edges keys (sorted, unique) at the
/// parameter s(a, c) in (0, 1) from a; every field is interpolated linearly there and then
/// fix(new vertex) may set values exactly.
template <class Param, class Fix>
void splitEdges(Work& w, const std::vector<uint64_t>& keys, Param param, Fix fix) {
  if (keys.empty()) return;
  // 1. One new vertex per edge, in key order.
  const uint32_t first = uint32_t(w.positions.size());
  if (size_t(first) + keys.size() >= std::numeric_limits<uint32_t>::max())
    throw std::length_error("the tetrahedral mesh has more than 4 billion vertices");
  w.positions.resize(first + keys.size());
  for (auto& g : w.fields) g.resize(first + keys.size());
  parallelFor(0, keys.size(), [&](size_t i) {
    const uint32_t a = uint32_t(keys[i] >> 32), c = uint32_t(keys[i]);
    const double s = param(a, c);
    w.positions[first + i] = w.positions[a] + (w.positions[c] - w.positions[a]) * s;
    for (auto& g : w.fields) g[first + i] = float(double(g[a]) + (double(g[c]) - double(g[a])) * s);
    fix(uint32_t(first + i));
  }, 1024);
  auto lookup = [&](uint32_t a, uint32_t c) -> int64_t {
    const uint64_t k = edgeKey(a, c);
    auto it = std::lower_bound(keys.begin(), keys.end(), k);
    return it != keys.end() && *it == k ? int64_t(first + (it - keys.begin())) : -1;
  };
  // 3. Split each tetrahedron on its listed edges, smallest key first (the consistent
  // order: two tetrahedra sharing a face split its edges in the same order).
  struct Piece {
    Tet t;
    uint8_t active;
    int tag;
  };
  std::vector<Piece> pieces = chunked<Piece>(w.tets.size(), [&](size_t lo, size_t hi, std::vector<Piece>& out) {
    std::vector<Tet> stack;
    for (size_t t = lo; t < hi; ++t) {
      stack.assign(1, w.tets[t]);
      while (!stack.empty()) {
        const Tet q = stack.back();
        stack.pop_back();
        uint64_t best = std::numeric_limits<uint64_t>::max();
        int be = -1;
        int64_t m = -1;
        for (int e = 0; e < 6; ++e) {
          const int64_t id = lookup(q[kTetEdges[e][0]], q[kTetEdges[e][1]]);
          const uint64_t k = edgeKey(q[kTetEdges[e][0]], q[kTetEdges[e][1]]);
          if (id >= 0 && k < best) best = k, be = e, m = id;
        }
        if (be < 0) {
          out.push_back({q, w.active[t], w.tag[t]});
          continue;
        }
        Tet c1 = q, c2 = q;  // same orientation: a vertex moves along its edge
        c1[kTetEdges[be][1]] = uint32_t(m);
        c2[kTetEdges[be][0]] = uint32_t(m);
        stack.push_back(c2);  // c1 is handled first
        stack.push_back(c1);
      }
    }
  });
  w.tets.resize(pieces.size());
  w.active.resize(pieces.size());
  w.tag.resize(pieces.size());
  for (size_t i = 0; i < pieces.size(); ++i) w.tets[i] = pieces[i].t, w.active[i] = pieces[i].active, w.tag[i] = pieces[i].tag;
}

/// Cuts every tetrahedron of w at the zero set of fields[v] - b (§4.3): the edges of active
/// tetrahedra whose ends lie strictly on both sides are split at the crossing, in order of
/// their vertex ids, in every tetrahedron that has them (earlier volumes' too, so faces
/// match). Returns the number of edges split.
size_t cutAt(Work& w, size_t v, double b) {
  const std::vector<float>& f = w.fields[v];
  // Fields are stored as floats: compare with the float boundary, so that values set (or
  // snapped) onto it read exactly zero.
  const double bf = double(float(b));
  auto phi = [&](uint32_t x) { return double(f[x]) - bf; };
  const std::vector<uint64_t> keys = edgesWhere(w, [&](size_t t) { return w.active[t] != 0; }, [&](uint32_t a, uint32_t c) {
    const double pa = phi(a), pc = phi(c);
    return (pa < 0 && pc > 0) || (pa > 0 && pc < 0);
  });
  // At the crossing of the (linear) field, set exactly onto the boundary.
  splitEdges(w, keys, [&](uint32_t a, uint32_t c) { return phi(a) / (phi(a) - phi(c)); },
             [&](uint32_t x) { w.fields[v][x] = float(b); });
  return keys.size();
}

/// The tetrahedra of w with a material >= 0, their vertices renumbered in id order.
/// tintField: index of the first of four fields holding the tints (none when < 0).
TetMesh compact(const Work& w, const std::vector<int>& material, int tintField = -1) {
  TetMesh mesh;
  std::vector<uint32_t> remap(w.positions.size(), 0);
  for (size_t t = 0; t < w.tets.size(); ++t)
    if (material[t] >= 0)
      for (uint32_t x : w.tets[t]) remap[x] = 1;
  uint32_t next = 0;
  for (size_t x = 0; x < remap.size(); ++x)
    if (remap[x]) {
      remap[x] = next++;
      mesh.positions.push_back(w.positions[x]);
      if (tintField >= 0) {
        const size_t f = size_t(tintField);
        mesh.tints.push_back(Vec4(w.fields[f][x], w.fields[f + 1][x], w.fields[f + 2][x], w.fields[f + 3][x]));
      }
    }
  for (size_t t = 0; t < w.tets.size(); ++t) {
    if (material[t] < 0) continue;
    const Tet& q = w.tets[t];
    mesh.tets.push_back({remap[q[0]], remap[q[1]], remap[q[2]], remap[q[3]]});
    mesh.materials.push_back(uint16_t(material[t]));
  }
  return mesh;
}

}  // namespace

int Volume::regionAt(double d) const {
  return regions[size_t(std::upper_bound(boundaries.begin(), boundaries.end(), d) - boundaries.begin())];
}

std::pair<double, double> Volume::claimed() const {
  constexpr double inf = std::numeric_limits<double>::infinity();
  const double lo = regions.front() != kUnclaimed ? -inf : boundaries.front();
  const double hi = regions.back() != kUnclaimed ? inf : boundaries.back();
  return {lo, hi};
}

Volume makeVolume(FieldPtr field, const std::vector<Layer>& layers) {
  std::vector<Layer> in, out;
  for (const Layer& l : layers) (l.interior ? in : out).push_back(l);
  for (size_t i = 0; i < in.size(); ++i)
    if (in[i].fill && i + 1 != in.size()) throw std::invalid_argument("only the innermost interior layer may fill");
  for (const Layer& l : out)
    if (l.fill) throw std::invalid_argument("an exterior layer cannot fill");
  Volume v;
  v.field = std::move(field);
  const bool fill = !in.empty() && in.back().fill;
  v.regions.push_back(fill ? in.back().material : kUnclaimed);
  // Interior layers from the innermost finite one outward: layer i spans [-(s_i + t_i), -s_i].
  std::vector<double> start(in.size(), 0.0);
  for (size_t i = 1; i < in.size(); ++i) start[i] = start[i - 1] + in[i - 1].thickness;
  for (size_t i = in.size(); i-- > 0;) {
    if (in[i].fill) continue;
    v.boundaries.push_back(-(start[i] + in[i].thickness));
    v.regions.push_back(in[i].material);
  }
  v.boundaries.push_back(0.0);
  double s = 0;
  for (const Layer& l : out) {
    v.regions.push_back(l.material);
    s += l.thickness;
    v.boundaries.push_back(s);
  }
  v.regions.push_back(kUnclaimed);
  // Merge neighbouring regions of one material (no boundary to cut there).
  for (size_t i = 0; i < v.boundaries.size();) {
    if (v.regions[i] == v.regions[i + 1]) {
      v.boundaries.erase(v.boundaries.begin() + long(i));
      v.regions.erase(v.regions.begin() + long(i) + 1);
    } else {
      ++i;
    }
  }
  return v;
}

void closeInward(Volume& v, double margin) {
  const auto zero = std::find(v.boundaries.begin(), v.boundaries.end(), 0.0);
  if (zero == v.boundaries.end() || !(margin > 0)) return;
  const size_t z = size_t(zero - v.boundaries.begin());
  const int below = v.regions[z], above = v.regions[z + 1];
  if (below != kUnclaimed || above == kUnclaimed || above == kNothing) return;
  const double floor = z > 0 ? v.boundaries[z - 1] : -std::numeric_limits<double>::infinity();
  v.boundaries[z] = std::max(-margin, floor / 2);
}

double TetMesh::volume(size_t t) const {
  const auto& q = tets[t];
  return det(positions[q[0]], positions[q[1]], positions[q[2]], positions[q[3]]) / 6.0;
}

namespace {

/// The smallest solid angle of (a, b, c, d) is 2·atan2(num, den) (Van Oosterom and
/// Strackee 1983): at a corner with edges x, y, z, the numerator |x·(y×z)| is the same at
/// every corner (six times the volume) and den = |x||y||z| + (x·y)|z| + (x·z)|y| + (y·z)|x|,
/// so the smallest angle is the one of the largest den.
std::pair<double, double> smallestAngleTangent(const DVec3& a, const DVec3& b, const DVec3& c, const DVec3& d) {
  const DVec3 p[4] = {a, b, c, d};
  const double num = std::abs(glm::dot(b - a, glm::cross(c - a, d - a)));
  double den = -1e300;
  for (int i = 0; i < 4; ++i) {
    const DVec3 x = p[(i + 1) % 4] - p[i], y = p[(i + 2) % 4] - p[i], z = p[(i + 3) % 4] - p[i];
    const double lx = glm::length(x), ly = glm::length(y), lz = glm::length(z);
    den = std::max(den, lx * ly * lz + glm::dot(x, y) * lz + glm::dot(x, z) * ly + glm::dot(y, z) * lx);
  }
  return {num, den};
}

}  // namespace

double minSolidAngle(const DVec3& a, const DVec3& b, const DVec3& c, const DVec3& d) {
  const auto [num, den] = smallestAngleTangent(a, b, c, d);
  return 2 * std::atan2(num, den);
}

double tetQuality(const DVec3& a, const DVec3& b, const DVec3& c, const DVec3& d, double idealVolume) {
  constexpr double kAlpha = 0.7;  // the paper's weight of the angle term (§4.4)
  const double v = det(a, b, c, d) / 6;
  if (!(v > 0)) return -1;
  // A(t) is 10 for every angle of 0.5 sr or more: no arctangent for those.
  const auto [num, den] = smallestAngleTangent(a, b, c, d);
  static const double kTanQuarter = std::tan(0.25);
  const double angle = den <= 0 || num >= kTanQuarter * den ? 10.0 : 10 * std::sqrt(4 * std::atan2(num, den));
  const double size = 10 * std::min(1.0, std::sqrt(v / idealVolume));
  return kAlpha * angle + (1 - kAlpha) * size;
}

QualityStats measureQuality(const TetMesh& mesh, size_t targetCount) {
  QualityStats q;
  if (mesh.tets.empty()) return q;
  double total = 0;
  for (size_t t = 0; t < mesh.tets.size(); ++t) total += mesh.volume(t);
  const double ideal = total / double(targetCount > 0 ? targetCount : mesh.tets.size());
  std::vector<double> quality(mesh.tets.size()), angle(mesh.tets.size());
  parallelFor(0, mesh.tets.size(), [&](size_t t) {
    const auto& v = mesh.tets[t];
    const DVec3 &a = mesh.positions[v[0]], &b = mesh.positions[v[1]], &c = mesh.positions[v[2]], &d = mesh.positions[v[3]];
    angle[t] = minSolidAngle(a, b, c, d);
    quality[t] = tetQuality(a, b, c, d, ideal);
  }, 4096);
  q.minQuality = *std::min_element(quality.begin(), quality.end());
  q.minSolidAngle = *std::min_element(angle.begin(), angle.end());
  double sum = 0;
  for (double x : quality) sum += x;  // in order: the same sum at any thread count
  q.meanQuality = sum / double(quality.size());
  return q;
}

namespace {

/// Ranges (a, b] of distance with region ids that pass keep, adjacent ones merged.
std::vector<std::pair<double, double>> rangesOf(const Volume& v, bool (*keep)(int)) {
  std::vector<std::pair<double, double>> out;
  const double inf = std::numeric_limits<double>::infinity();
  for (size_t r = 0; r < v.regions.size(); ++r) {
    if (!keep(v.regions[r])) continue;
    const double a = r == 0 ? -inf : v.boundaries[r - 1], b = r < v.boundaries.size() ? v.boundaries[r] : inf;
    if (!out.empty() && out.back().second == a) out.back().second = b;
    else out.emplace_back(a, b);
  }
  return out;
}

/// Negative inside the ranges: min over ranges of max(a - d, d - b).
float inRanges(const std::vector<std::pair<double, double>>& ranges, float d) {
  float f = std::numeric_limits<float>::infinity();
  for (const auto& [a, b] : ranges) f = std::min(f, float(std::max(a - d, d - b)));
  return f;
}

bool isMaterial(int id) { return id != kUnclaimed && id != kNothing; }
bool isNothing(int id) { return id == kNothing; }

class VolumeSurfaceField final : public DistanceField {
 public:
  explicit VolumeSurfaceField(std::vector<Volume> volumes) : volumes_(std::move(volumes)) {
    if (volumes_.empty()) throw std::invalid_argument("from_volume_surface needs a volume");
    for (const Volume& v : volumes_) {
      material_.push_back(rangesOf(v, isMaterial));
      nothing_.push_back(rangesOf(v, isNothing));
    }
  }
  std::vector<float> sample(const std::vector<Vec3>& points, double cell, double band) const override {
    std::vector<float> out(points.size(), std::numeric_limits<float>::infinity());
    std::vector<float> carved(points.size(), -std::numeric_limits<float>::infinity());  // max of -nothing so far
    for (size_t v = 0; v < volumes_.size(); ++v) {
      const double outer = volumes_[v].boundaries.empty() ? 0.0 : std::abs(volumes_[v].boundaries.back());
      const std::vector<float> d = volumes_[v].field->sample(points, cell, band + outer);
      for (size_t i = 0; i < points.size(); ++i) {
        if (!material_[v].empty()) out[i] = std::min(out[i], std::max(inRanges(material_[v], d[i]), carved[i]));
        if (!nothing_[v].empty()) carved[i] = std::max(carved[i], -inRanges(nothing_[v], d[i]));
      }
    }
    for (float& f : out) f = std::clamp(f, float(-band), float(band));
    return out;
  }
  std::optional<DBox3> bounds() const override {
    std::optional<DBox3> box;
    for (size_t v = 0; v < volumes_.size(); ++v) {
      if (material_[v].empty()) continue;
      std::optional<DBox3> b = volumes_[v].field->bounds();
      if (!b) return std::nullopt;
      const double outer = material_[v].back().second;
      if (!std::isfinite(outer)) return std::nullopt;
      const DBox3 e = b->expanded(std::max(0.0, outer) * volumes_[v].field->reach());
      if (box) box->extend(e); else box = e;
    }
    return box;
  }

 private:
  std::vector<Volume> volumes_;
  std::vector<std::vector<std::pair<double, double>>> material_, nothing_;
};

}  // namespace

FieldPtr volumeSurfaceField(std::vector<Volume> volumes) { return std::make_shared<VolumeSurfaceField>(std::move(volumes)); }

std::vector<Vec3> gridNodes(const Grid& g) {
  const size_t nx = size_t(g.cells[0]) + 1, ny = size_t(g.cells[1]) + 1;
  std::vector<Vec3> nodes(g.nodeCount());
  parallelFor(0, nodes.size(), [&](size_t n) {
    nodes[n] = Vec3(g.origin + g.cell * DVec3(double(n % nx), double((n / nx) % ny), double(n / (nx * ny))));
  }, 4096);
  return nodes;
}

namespace {

/// Step 1 of meshSolid: every volume's distance at the grid's nodes, within a band wider
/// than its boundaries; values very near a boundary snap onto it.
void sampleFields(const Solid& solid, const Grid& grid, const std::vector<Vec3>& nodes, double snapFraction, Work& w) {
  w.positions.resize(nodes.size());
  const size_t nx = size_t(grid.cells[0]) + 1, ny = size_t(grid.cells[1]) + 1;
  parallelFor(0, nodes.size(), [&](size_t n) {
    w.positions[n] = grid.origin + grid.cell * DVec3(double(n % nx), double((n / nx) % ny), double(n / (nx * ny)));
  }, 4096);
  for (const Volume& v : solid.volumes) {
    double band = 0;
    for (double b : v.boundaries) band = std::max(band, std::abs(b));
    w.fields.push_back(v.field->sample(nodes, grid.cell, band + 2 * grid.cell));
    std::vector<float>& f = w.fields.back();
    const double snap = snapFraction * grid.cell;
    parallelFor(0, f.size(), [&](size_t n) {
      for (double b : v.boundaries)
        if (std::abs(double(f[n]) - b) < snap) f[n] = float(b);
    }, 4096);
  }
}

/// The nodes' classes for the coarsened octree (§4.4): a node's class packs its region index
/// in every volume; nodes on a boundary or in a procedural layer are kMixedClass (never
/// merge) and marked in `procedural` when in a procedural layer.
struct NodeClasses {
  int levels = 0;  ///< octree levels of coarsening; 0 when the classes do not fit 63 bits
  std::vector<uint64_t> nodeClass;
  std::vector<uint8_t> procedural;
};

NodeClasses classifyNodes(const Solid& solid, const Work& w, int levels) {
  NodeClasses out;
  std::vector<int> bits;
  int totalBits = 0;
  for (const Volume& v : solid.volumes) {
    int b = 1;
    while ((size_t(1) << b) < v.regions.size()) ++b;
    bits.push_back(b);
    totalBits += b;
  }
  out.levels = totalBits > 63 ? 0 : levels;
  if (out.levels <= 0) return out;
  const size_t count = w.positions.size();
  out.nodeClass.resize(count);
  out.procedural.assign(count, 0);
  parallelFor(0, count, [&](size_t n) {
    uint64_t k = 0;
    int shift = 0;
    bool claimed = false;
    for (size_t v = 0; v < solid.volumes.size(); ++v) {
      const Volume& vol = solid.volumes[v];
      const double d = w.fields[v][n];
      const size_t r = size_t(std::upper_bound(vol.boundaries.begin(), vol.boundaries.end(), d) - vol.boundaries.begin());
      const bool onBoundary = std::any_of(vol.boundaries.begin(), vol.boundaries.end(), [&](double b) { return double(float(b)) == d; });
      if (!claimed && vol.regions[r] <= kProcedural0) out.procedural[n] = 1;
      if (onBoundary || out.procedural[n]) {
        out.nodeClass[n] = kMixedClass;
        return;
      }
      claimed = claimed || vol.regions[r] != kUnclaimed;
      k |= uint64_t(r) << shift;
      shift += bits[v];
    }
    out.nodeClass[n] = k;
  }, 4096);
  return out;
}

/// Blocks an interface crosses merge where every volume's field is affine on them to within
/// eps (§4.4: "accurately represented by interpolation"): the coarse tetrahedra's linear
/// interpolation then puts each interface within that distance of where the fine cells put
/// it. Volumes whose nodes in the block lie in one region (no boundary near) do not count;
/// blocks with a node of a procedural layer never merge.
MergeTest affineMergeTest(const Solid& solid, const Grid& grid, const Work& w, const std::vector<uint8_t>& procedural, double eps) {
  const size_t nx = size_t(grid.cells[0]) + 1, ny = size_t(grid.cells[1]) + 1;
  return [&solid, &w, &procedural, nx, ny, eps](const std::array<int, 3>& base, int s) {
    auto node = [&](int i, int j, int k) { return size_t(base[0] + i) + nx * (size_t(base[1] + j) + ny * size_t(base[2] + k)); };
    for (int k = 0; k <= s; ++k)
      for (int j = 0; j <= s; ++j)
        for (int i = 0; i <= s; ++i)
          if (procedural[node(i, j, k)]) return false;
    for (size_t v = 0; v < solid.volumes.size(); ++v) {
      const Volume& vol = solid.volumes[v];
      const std::vector<float>& f = w.fields[v];
      auto region = [&](float d) { return std::upper_bound(vol.boundaries.begin(), vol.boundaries.end(), double(d)) - vol.boundaries.begin(); };
      const auto r0 = region(f[node(0, 0, 0)]);
      bool crossed = false;
      for (int k = 0; k <= s && !crossed; ++k)
        for (int j = 0; j <= s && !crossed; ++j)
          for (int i = 0; i <= s && !crossed; ++i) crossed = region(f[node(i, j, k)]) != r0;
      if (!crossed) continue;
      // The affine function of the eight corners (least squares): mean and slopes per cell.
      double c[8], mean = 0;
      for (int q = 0; q < 8; ++q) mean += c[q] = f[node((q & 1) * s, ((q >> 1) & 1) * s, ((q >> 2) & 1) * s)];
      mean /= 8;
      double g[3] = {0, 0, 0};
      for (int q = 0; q < 8; ++q)
        for (int a = 0; a < 3; ++a) g[a] += ((q >> a) & 1 ? c[q] : -c[q]) / (4.0 * s);
      const double half = s / 2.0;
      for (int k = 0; k <= s; ++k)
        for (int j = 0; j <= s; ++j)
          for (int i = 0; i <= s; ++i) {
            const double fit = mean + g[0] * (i - half) + g[1] * (j - half) + g[2] * (k - half);
            if (std::abs(double(f[node(i, j, k)]) - fit) > eps) return false;
          }
    }
    return true;
  };
}

/// Step 2 of meshSolid: five tetrahedra per cube that some volume may claim, on the
/// coarsened octree (§4.4).
void cellsOfSolid(const Solid& solid, const Grid& grid, const MeshOptions& options, Work& w, MeshStats& st) {
  std::vector<std::pair<double, double>> claims;
  for (const Volume& v : solid.volumes) claims.push_back(v.claimed());
  const NodeClasses classes = classifyNodes(solid, w, options.coarsenLevels);
  MergeTest interpolated;
  if (classes.levels > 0 && options.coarsenTolerance > 0)
    interpolated = affineMergeTest(solid, grid, w, classes.procedural, options.coarsenTolerance * grid.cell);
  CellStats cells;
  w.tets = cellTetrahedra(grid, classes.levels, classes.nodeClass, [&](const uint32_t* corner) {
    for (size_t v = 0; v < solid.volumes.size(); ++v) {
      float mn = std::numeric_limits<float>::max(), mx = std::numeric_limits<float>::lowest();
      for (int q = 0; q < 8; ++q) mn = std::min(mn, w.fields[v][corner[q]]), mx = std::max(mx, w.fields[v][corner[q]]);
      if (mx >= claims[v].first && mn <= claims[v].second) return true;
    }
    return false;
  }, &cells, interpolated);
  st.cellTets = w.tets.size();
  st.cubes = cells.leaves;
  st.coarseCubes = cells.coarseLeaves;
  st.transitionCubes = cells.transition;
  w.active.assign(w.tets.size(), 1);
  w.tag.assign(w.tets.size(), 0);
}

/// A tetrahedron whose four vertices all lie on one boundary b of a volume (at the nodes,
/// or snapped there) is not flat, so the boundary is not planar in it: the linear field is
/// b at its centroid and cannot tell which side the tetrahedron lies on. That happens along
/// every edge and corner of a box whose faces lie on the grid's planes (as the automatic
/// grid puts the outermost ones), where the tetrahedra spanning a convex edge were
/// dropped and the edge meshed notched, every other cell. Those tetrahedra take the
/// volume's own field at their centroid instead (one batch per volume).
void resolveFlatTets(const Solid& solid, const Grid& grid, Work& w) {
  w.flat.assign(solid.volumes.size(), {});
  for (size_t v = 0; v < solid.volumes.size(); ++v) {
    const Volume& vol = solid.volumes[v];
    const std::vector<float>& f = w.fields[v];
    std::vector<uint32_t> ids = chunked<uint32_t>(w.tets.size(), [&](size_t lo, size_t hi, std::vector<uint32_t>& out) {
      for (size_t t = lo; t < hi; ++t) {
        const Tet& q = w.tets[t];
        const float a = f[q[0]];
        if (a != f[q[1]] || a != f[q[2]] || a != f[q[3]]) continue;
        for (double b : vol.boundaries)
          if (a == float(b)) out.push_back(uint32_t(t));
      }
    });
    if (ids.empty()) continue;
    std::vector<Vec3> centroids(ids.size());
    for (size_t i = 0; i < ids.size(); ++i) {
      const Tet& q = w.tets[ids[i]];
      centroids[i] = Vec3((w.positions[q[0]] + w.positions[q[1]] + w.positions[q[2]] + w.positions[q[3]]) * 0.25);
    }
    double band = 0;
    for (double b : vol.boundaries) band = std::max(band, std::abs(b));
    const std::vector<float> value = vol.field->sample(centroids, grid.cell, band + 2 * grid.cell);
    for (size_t i = 0; i < ids.size(); ++i) w.flat[v].push_back({ids[i], value[i]});
  }
}

/// The region material of tetrahedron t: the first volume claiming its centroid (the fields
/// are linear in it; resolveFlatTets settles the tetrahedra they cannot).
int regionOf(const Solid& solid, const Work& w, size_t t) {
  for (size_t v = 0; v < solid.volumes.size(); ++v) {
    const int m = solid.volumes[v].regionAt(w.valueAt(v, t));
    if (m != kUnclaimed) return m;
  }
  return kUnclaimed;
}

/// Step 5 of meshSolid: tetrahedra of procedural layers are subdivided to follow the
/// procedure (§4.3, last paragraph): an edge whose ends choose different materials is split
/// where the choice changes (bisection to 1/1024 of the edge), in every tetrahedron that
/// has it. Returns the edges split.
size_t splitProceduralLayers(const Solid& solid, const MeshOptions& options, Work& w) {
  size_t splits = 0;
  for (size_t p = 0; p < solid.materials.procedural.size(); ++p) {
    const ProceduralMaterial& proc = solid.materials.procedural[p];
    const int code = kProcedural0 - int(p);
    std::vector<uint8_t> in(w.tets.size());
    parallelFor(0, w.tets.size(), [&](size_t t) { in[t] = regionOf(solid, w, t) == code; }, 4096);
    auto crossing = [&](uint32_t a, uint32_t c) {
      const DVec3 pa = w.positions[a], pc = w.positions[c];
      const int ma = proc.at(pa);
      double lo = 0, hi = 1;
      for (int k = 0; k < 10; ++k) {
        const double mid = 0.5 * (lo + hi);
        (proc.at(pa + (pc - pa) * mid) == ma ? lo : hi) = mid;
      }
      return 0.5 * (lo + hi);
    };
    for (int round = 0; round < options.proceduralRounds; ++round) {
      // Crossings nearer an end than the snap fraction are left to the centroid choice (no slivers).
      const double near = options.snapFraction;
      const std::vector<uint64_t> keys = edgesWhere(w, [&](size_t t) { return in[t] != 0; }, [&](uint32_t a, uint32_t c) {
        if (proc.at(w.positions[a]) == proc.at(w.positions[c])) return false;
        const double x = crossing(std::min(a, c), std::max(a, c));
        return x > near && x < 1 - near;
      });
      if (keys.empty()) break;
      splits += keys.size();
      for (size_t t = 0; t < in.size(); ++t) w.tag[t] = in[t];
      splitEdges(w, keys, crossing, [](uint32_t) {});
      in.assign(w.tag.begin(), w.tag.end());  // pieces keep their parent's flag
    }
  }
  return splits;
}

/// Step 6 of meshSolid: each tetrahedron's material; procedural ones chosen at the centroid.
std::vector<int> tetMaterials(const Solid& solid, const Work& w) {
  std::vector<int> material(w.tets.size(), kUnclaimed);
  parallelFor(0, w.tets.size(), [&](size_t t) {
    int m = regionOf(solid, w, t);
    if (m <= kProcedural0) {
      const Tet& q = w.tets[t];
      const DVec3 c = (w.positions[q[0]] + w.positions[q[1]] + w.positions[q[2]] + w.positions[q[3]]) * 0.25;
      m = solid.materials.procedural[size_t(kProcedural0 - m)].at(c);
    }
    material[t] = m;
  }, 4096);
  return material;
}

using FaceKey = std::array<uint32_t, 3>;
struct FaceKeyHash {
  size_t operator()(const FaceKey& f) const { return (size_t(f[0]) * 0x9E3779B97F4A7C15ull) ^ (size_t(f[1]) * 0xC2B2AE3D27D4EB4Full) ^ f[2]; }
};

/// Step 6b of meshSolid: pockets of unclaimed space sealed on every side by tetrahedra with
/// a material, each smaller than one grid cell, take the material most of their faces touch
/// (ties: the lowest id). A pocket under the grid's resolution is no feature of the model:
/// the tetrahedra of a cell whose centroids fall just outside a thin, nearly closed crease
/// leave one (a sampled field cannot tell it from the wall around it). Pockets open to the
/// outside, to a `nothing` layer or larger than a cell stay. Returns the pockets filled.
size_t fillSealedSpecks(const Work& w, double cellVolume, std::vector<int>& material) {
  std::vector<uint32_t> air;
  for (size_t t = 0; t < material.size(); ++t)
    if (material[t] == kUnclaimed) air.push_back(uint32_t(t));
  // Pockets: the unclaimed tetrahedra joined across shared faces.
  std::vector<std::pair<FaceKey, uint32_t>> faces;
  faces.reserve(air.size() * 4);
  for (uint32_t a = 0; a < air.size(); ++a)
    for (int k = 0; k < 4; ++k) faces.emplace_back(faceKey(w.tets[air[a]], k), a);
  std::sort(faces.begin(), faces.end());
  DisjointSets pockets(air.size());
  auto root = [&](uint32_t a) { return pockets.find(a); };
  std::vector<std::pair<FaceKey, uint32_t>> open;  // faces of one unclaimed tetrahedron only
  for (size_t i = 0; i < faces.size();) {
    size_t j = i + 1;
    while (j < faces.size() && faces[j].first == faces[i].first) ++j;
    if (j - i == 1) open.push_back(faces[i]);
    for (size_t k = i + 1; k < j; ++k) pockets.join(faces[k].second, faces[i].second);
    i = j;
  }
  std::vector<double> volume(air.size(), 0.0);  // per pocket, at its root
  for (uint32_t a = 0; a < air.size(); ++a) {
    const Tet& q = w.tets[air[a]];
    volume[root(a)] += std::abs(det(w.positions[q[0]], w.positions[q[1]], w.positions[q[2]], w.positions[q[3]])) / 6.0;
  }
  // The small pockets' open faces, and what lies across each.
  std::unordered_map<FaceKey, std::pair<uint32_t, int>, FaceKeyHash> across;  // face -> (pocket, material seen or -1)
  for (const auto& [key, a] : open)
    if (volume[root(a)] < cellVolume) across.emplace(key, std::make_pair(root(a), -1));
  if (across.empty()) return 0;
  for (size_t t = 0; t < material.size(); ++t)
    if (material[t] >= 0)
      for (int k = 0; k < 4; ++k)
        if (auto it = across.find(faceKey(w.tets[t], k)); it != across.end()) it->second.second = material[t];
  std::map<uint32_t, std::map<int, size_t>> votes;  // pocket -> material -> faces
  std::set<uint32_t> leaky;
  for (const auto& [key, v] : across) {
    if (v.second < 0) leaky.insert(v.first);
    else ++votes[v.first][v.second];
  }
  std::map<uint32_t, int> fill;  // sealed pocket -> its material
  for (const auto& [pocket, count] : votes)
    if (!leaky.count(pocket))
      fill[pocket] = std::max_element(count.begin(), count.end(), [](const auto& x, const auto& y) { return x.second < y.second; })->first;
  if (!fill.empty())
    for (uint32_t a = 0; a < air.size(); ++a)
      if (auto it = fill.find(root(a)); it != fill.end()) material[air[a]] = it->second;
  return fill.size();
}

}  // namespace

TetMesh meshSolid(const Solid& solid, const Grid& grid, const MeshOptions& options, MeshStats* stats) {
  MeshStats st;
  auto t0 = std::chrono::steady_clock::now();
  Work w;
  sampleFields(solid, grid, gridNodes(grid), options.snapFraction, w);  // 1. the fields at the nodes
  st.fieldSeconds = secondsSince(t0);
  t0 = std::chrono::steady_clock::now();
  cellsOfSolid(solid, grid, options, w, st);  // 2. the cells some volume may claim
  // 3. Cut at every boundary of every volume, in precedence order; a volume cuts only where
  // no earlier volume claims the space (but splits claimed tetrahedra along shared edges).
  for (size_t v = 0; v < solid.volumes.size(); ++v) {
    if (v > 0)
      parallelFor(0, w.tets.size(), [&](size_t t) {
        if (w.active[t] && solid.volumes[v - 1].regionAt(w.centroidValue(v - 1, w.tets[t])) != kUnclaimed) w.active[t] = 0;
      }, 4096);
    for (double b : solid.volumes[v].boundaries) st.splits += cutAt(w, v, b);
  }
  st.splits += splitProceduralLayers(solid, options, w);  // 4-5. procedural layers
  resolveFlatTets(solid, grid, w);
  // 6-7. Keep tetrahedra with a material; renumber the vertices they use in id order.
  std::vector<int> material = tetMaterials(solid, w);
  st.sealedSpecks = fillSealedSpecks(w, grid.cell * grid.cell * grid.cell, material);
  TetMesh mesh = compact(w, material);
  st.tets = mesh.tets.size();
  st.meshSeconds = secondsSince(t0);
  if (stats) *stats = st;
  return mesh;
}

TetMesh clipByPlane(const TetMesh& mesh, const DVec3& normal, double offset) {
  const DVec3 n = glm::normalize(normal);
  Work w;
  w.positions = mesh.positions;
  w.tets = mesh.tets;
  w.active.assign(w.tets.size(), 1);
  w.fields.emplace_back(w.positions.size());
  parallelFor(0, w.positions.size(), [&](size_t v) { w.fields[0][v] = float(glm::dot(n, w.positions[v]) - offset); }, 4096);
  w.tag.assign(mesh.materials.begin(), mesh.materials.end());
  const bool tinted = mesh.tints.size() == mesh.positions.size() && !mesh.tints.empty();
  if (tinted)
    for (int c = 0; c < 4; ++c) {
      w.fields.emplace_back(mesh.positions.size());
      for (size_t v = 0; v < mesh.positions.size(); ++v) w.fields.back()[v] = mesh.tints[v][c];
    }
  cutAt(w, 0, 0.0);
  std::vector<int> material(w.tets.size(), kUnclaimed);
  for (size_t t = 0; t < w.tets.size(); ++t)
    if (w.centroidValue(0, w.tets[t]) <= 0) material[t] = w.tag[t];
  return compact(w, material, tinted ? 1 : -1);
}

size_t cutByField(TetMesh& mesh, const std::vector<uint8_t>& splittable, const std::function<double(const DVec3&)>& field,
                  std::vector<uint32_t>* parent, double snap) {
  if (splittable.size() != mesh.tets.size()) throw std::invalid_argument("cutByField: one flag per tetrahedron expected");
  const size_t nv = mesh.positions.size();
  std::vector<double> value(nv);
  parallelFor(0, nv, [&](size_t v) { value[v] = field(mesh.positions[v]); }, 1024);
  // Edges of tetrahedra that may not split.
  std::vector<uint64_t> frozen;
  for (size_t t = 0; t < mesh.tets.size(); ++t)
    if (!splittable[t])
      for (const auto& e : kTetEdges) frozen.push_back(edgeKey(mesh.tets[t][e[0]], mesh.tets[t][e[1]]));
  std::sort(frozen.begin(), frozen.end());
  frozen.erase(std::unique(frozen.begin(), frozen.end()), frozen.end());
  Work w;
  w.positions = mesh.positions;
  w.tets = mesh.tets;
  w.active.assign(w.tets.size(), 1);
  w.tag.resize(w.tets.size());
  for (size_t t = 0; t < w.tag.size(); ++t) w.tag[t] = int(t);
  const bool tinted = mesh.tints.size() == nv && nv > 0;
  if (tinted)
    for (int c = 0; c < 4; ++c) {
      w.fields.emplace_back(nv);
      for (size_t v = 0; v < nv; ++v) w.fields.back()[v] = mesh.tints[v][c];
    }
  const std::vector<uint64_t> candidates = edgesWhere(w, [&](size_t t) { return splittable[t] != 0; }, [&](uint32_t a, uint32_t c) {
    const double pa = value[a], pc = value[c];
    if (!((pa < 0 && pc > 0) || (pa > 0 && pc < 0))) return false;
    return !std::binary_search(frozen.begin(), frozen.end(), edgeKey(a, c));
  });
  // Bisection of the field along the edge, from the end with the smaller id.
  auto crossing = [&](uint32_t a, uint32_t c) {
    const DVec3 pa = mesh.positions[a], pc = mesh.positions[c];
    const bool negA = value[a] < 0;
    double lo = 0, hi = 1;
    for (int k = 0; k < 42; ++k) {
      const double mid = 0.5 * (lo + hi);
      ((field(pa + (pc - pa) * mid) < 0) == negA ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  };
  std::vector<uint64_t> kept;
  std::vector<double> at;
  for (uint64_t k : candidates) {
    const double x = crossing(uint32_t(k >> 32), uint32_t(k));
    if (x > snap && x < 1 - snap) kept.push_back(k), at.push_back(x);
  }
  const std::vector<uint64_t>& keys = kept;
  splitEdges(w, keys, [&](uint32_t a, uint32_t c) {
    return at[size_t(std::lower_bound(keys.begin(), keys.end(), edgeKey(a, c)) - keys.begin())];
  }, [](uint32_t) {});
  mesh.positions = std::move(w.positions);
  if (tinted) {
    mesh.tints.resize(mesh.positions.size());
    for (size_t v = nv; v < mesh.positions.size(); ++v)
      mesh.tints[v] = Vec4(w.fields[0][v], w.fields[1][v], w.fields[2][v], w.fields[3][v]);
  }
  std::vector<uint16_t> materials(w.tets.size());
  if (parent) parent->assign(w.tets.size(), 0);
  for (size_t t = 0; t < w.tets.size(); ++t) {
    materials[t] = mesh.materials[size_t(w.tag[t])];
    if (parent) (*parent)[t] = uint32_t(w.tag[t]);
  }
  mesh.tets = std::move(w.tets);
  mesh.materials = std::move(materials);
  return keys.size();
}

namespace {

struct FaceRef {
  std::array<uint32_t, 3> key;  ///< sorted vertex ids
  uint32_t tet;
  uint8_t face;
  bool operator<(const FaceRef& o) const { return key != o.key ? key < o.key : tet < o.tet; }
};

/// Every tetrahedron face, sorted so shared faces are neighbours.
std::vector<FaceRef> sortedFaces(const TetMesh& mesh) {
  std::vector<FaceRef> faces(mesh.tets.size() * 4);
  parallelFor(0, mesh.tets.size(), [&](size_t t) {
    for (uint8_t f = 0; f < 4; ++f) faces[t * 4 + f] = {faceKey(mesh.tets[t], f), uint32_t(t), f};
  }, 4096);
  std::sort(faces.begin(), faces.end());
  return faces;
}

InterfaceTriangle triangleOf(const TetMesh& mesh, const FaceRef& f) {
  const auto& q = mesh.tets[f.tet];
  return {{q[kTetFaces[f.face][0]], q[kTetFaces[f.face][1]], q[kTetFaces[f.face][2]]}, mesh.materials[f.tet]};
}

}  // namespace

std::vector<InterfaceTriangle> visibleInterface(const TetMesh& mesh, size_t* badFaces) {
  const std::vector<FaceRef> faces = sortedFaces(mesh);
  std::vector<InterfaceTriangle> out;
  size_t bad = 0;
  for (size_t i = 0; i < faces.size();) {
    size_t j = i + 1;
    while (j < faces.size() && faces[j].key == faces[i].key) ++j;
    if (j - i == 1) out.push_back(triangleOf(mesh, faces[i]));
    if (j - i > 2) ++bad;
    i = j;
  }
  if (badFaces) *badFaces = bad;
  return out;
}

std::vector<InterfaceTriangle> materialInterfaces(const TetMesh& mesh) {
  const std::vector<FaceRef> faces = sortedFaces(mesh);
  std::vector<InterfaceTriangle> out;
  for (size_t i = 0; i + 1 < faces.size(); ++i) {
    if (faces[i + 1].key != faces[i].key) continue;
    if (mesh.materials[faces[i].tet] != mesh.materials[faces[i + 1].tet]) {
      out.push_back(triangleOf(mesh, faces[i]));
      out.push_back(triangleOf(mesh, faces[i + 1]));
    }
    ++i;
  }
  return out;
}

namespace {

/// boundarySurface's work: the boundary triangles of the selected tetrahedra, their corners
/// joined across edges by union-find, and the wedges at pinched edges.
class BoundaryBuilder {
 public:
  BoundaryBuilder(const TetMesh& mesh, const std::vector<uint8_t>& selected) : mesh_(mesh), selected_(selected) {}

  BoundarySurface build(double pull) {
    collectTriangles();
    pairAtEdges();
    BoundarySurface out;
    std::vector<uint8_t> moved = numberVertices(out);
    splitPinchedEdges(out, moved);
    pullMoved(out, moved, pull);
    return out;
  }

 private:
  struct Wedge {
    uint64_t edge;  ///< mesh vertex ids
    uint32_t s, t;  ///< its two triangles
  };
  struct Group {
    uint32_t vertex, first, root;
  };

  bool in(uint32_t t) const { return selected_.empty() || selected_[t] != 0; }

  uint32_t find(uint32_t a) { return corners_.find(a); }

  uint32_t corner(uint32_t t, uint32_t v) const {
    const auto& q = tris_[t].v;
    return uint32_t(3 * t + size_t(std::find(q.begin(), q.end(), v) - q.begin()));
  }

  /// Joins the corners of triangles s and t at edge e's two vertices.
  void pair(uint32_t s, uint32_t t, uint64_t e) {
    for (uint32_t v : {uint32_t(e >> 32), uint32_t(e & 0xffffffffu)}) corners_.join(corner(s, v), corner(t, v));
  }

  /// 1. The boundary triangles: faces of a selected tetrahedron no other selected one shares.
  void collectTriangles() {
    const std::vector<FaceRef> faces = sortedFaces(mesh_);
    for (size_t i = 0; i < faces.size();) {
      size_t j = i + 1;
      while (j < faces.size() && faces[j].key == faces[i].key) ++j;
      size_t n = 0, last = i;
      for (size_t k = i; k < j; ++k)
        if (in(faces[k].tet)) ++n, last = k;
      if (n == 1) {
        tris_.push_back(triangleOf(mesh_, faces[last]));
        tetOf_.push_back(faces[last].tet);
      }
      i = j;
    }
    corners_ = DisjointSets(tris_.size() * 3);
  }

  /// 2. Pair the triangles at each edge: two at an edge are one wedge; at an edge of 2k > 2,
  /// see pairPinched.
  void pairAtEdges() {
    std::vector<std::pair<uint64_t, uint32_t>> halfEdges;  // (edge, triangle)
    halfEdges.reserve(tris_.size() * 3);
    for (size_t t = 0; t < tris_.size(); ++t)
      for (int e = 0; e < 3; ++e) halfEdges.push_back({edgeKey(tris_[t].v[size_t(e)], tris_[t].v[size_t((e + 1) % 3)]), uint32_t(t)});
    std::sort(halfEdges.begin(), halfEdges.end());
    for (size_t i = 0; i < halfEdges.size();) {
      size_t j = i + 1;
      while (j < halfEdges.size() && halfEdges[j].first == halfEdges[i].first) ++j;
      if (j - i == 2) pair(halfEdges[i].second, halfEdges[i + 1].second, halfEdges[i].first);
      if (j - i > 2) {
        std::vector<uint32_t> around;
        for (size_t k = i; k < j; ++k) around.push_back(halfEdges[k].second);
        pairPinched(halfEdges[i].first, around);
      }
      i = j;
    }
  }

  /// The selected tetrahedra by vertex (CSR), built at the first pinched edge.
  void indexTetsByVertex() {
    start_.assign(mesh_.positions.size() + 1, 0);
    for (size_t t = 0; t < mesh_.tets.size(); ++t)
      if (in(uint32_t(t)))
        for (uint32_t v : mesh_.tets[t]) ++start_[v + 1];
    for (size_t v = 0; v + 1 < start_.size(); ++v) start_[v + 1] += start_[v];
    items_.resize(start_.back());
    std::vector<uint32_t> at(start_.begin(), start_.end() - 1);
    for (size_t t = 0; t < mesh_.tets.size(); ++t)
      if (in(uint32_t(t)))
        for (uint32_t v : mesh_.tets[t]) items_[at[v]++] = uint32_t(t);
  }

  /// An edge e of more than two boundary triangles (around): the selected tetrahedra around
  /// it are joined through their faces at the edge into wedges, and each wedge's two
  /// boundary triangles are paired.
  void pairPinched(uint64_t e, const std::vector<uint32_t>& around) {
    if (start_.empty()) indexTetsByVertex();
    const uint32_t a = uint32_t(e >> 32), b = uint32_t(e & 0xffffffffu);
    std::vector<uint32_t> star;
    for (uint32_t k = start_[a]; k < start_[a + 1]; ++k) {
      const auto& q = mesh_.tets[items_[k]];
      if (std::find(q.begin(), q.end(), b) != q.end()) star.push_back(items_[k]);
    }
    DisjointSets wedges(star.size());
    auto root = [&](uint32_t x) { return wedges.find(x); };
    for (size_t x = 0; x < star.size(); ++x)
      for (size_t y = x + 1; y < star.size(); ++y) {
        int common = 0;
        for (uint32_t v : mesh_.tets[star[x]])
          common += std::find(mesh_.tets[star[y]].begin(), mesh_.tets[star[y]].end(), v) != mesh_.tets[star[y]].end() ? 1 : 0;
        if (common == 3) wedges.join(uint32_t(x), uint32_t(y));
      }
    // Each triangle's wedge; the two triangles of a wedge are paired.
    std::vector<std::pair<uint32_t, uint32_t>> byWedge;  // (wedge root, triangle)
    for (uint32_t t : around) {
      const size_t x = size_t(std::find(star.begin(), star.end(), tetOf_[t]) - star.begin());
      byWedge.push_back({root(uint32_t(x)), t});
    }
    std::sort(byWedge.begin(), byWedge.end());
    for (size_t k = 0; k + 1 < byWedge.size(); ++k)
      if (byWedge[k].first == byWedge[k + 1].first) {
        pair(byWedge[k].second, byWedge[k + 1].second, e);
        wedges_.push_back({e, byWedge[k].second, byWedge[k + 1].second});
        ++k;
      }
  }

  /// 3. One surface vertex per group of corners, numbered by (mesh vertex, first corner).
  /// Returns, per surface vertex, whether it is one of several for its mesh vertex.
  std::vector<uint8_t> numberVertices(BoundarySurface& out) {
    const size_t nt = tris_.size();
    std::vector<Group> groups;
    std::vector<uint32_t> seen(nt * 3, UINT32_MAX);
    for (uint32_t c = 0; c < nt * 3; ++c) {
      const uint32_t r = find(c);
      if (seen[r] != UINT32_MAX) continue;
      seen[r] = 0;
      groups.push_back({tris_[c / 3].v[c % 3], c, r});
    }
    std::sort(groups.begin(), groups.end(), [](const Group& x, const Group& y) {
      return x.vertex != y.vertex ? x.vertex < y.vertex : x.first < y.first;
    });
    for (size_t g = 0; g < groups.size(); ++g) {
      seen[groups[g].root] = uint32_t(g);
      out.sources.push_back({groups[g].vertex, groups[g].vertex});
      out.positions.push_back(mesh_.positions[groups[g].vertex]);
      if (g > 0 && groups[g].vertex == groups[g - 1].vertex && (g < 2 || groups[g - 2].vertex != groups[g].vertex)) ++out.splitVertices;
    }
    out.triangles = tris_;
    for (uint32_t c = 0; c < nt * 3; ++c) out.triangles[c / 3].v[c % 3] = seen[find(c)];
    std::vector<uint8_t> moved(out.positions.size(), 0);
    for (size_t g = 0; g < groups.size(); ++g)
      moved[g] = (g > 0 && groups[g - 1].vertex == groups[g].vertex) || (g + 1 < groups.size() && groups[g + 1].vertex == groups[g].vertex);
    return moved;
  }

  /// The surface vertex of triangle t (in out) at mesh vertex v of its original.
  uint32_t surfaceVertex(const BoundarySurface& out, uint32_t t, uint32_t v) const {
    const auto& orig = tris_[t].v;
    return out.triangles[t].v[size_t(std::find(orig.begin(), orig.end(), v) - orig.begin())];
  }

  /// 4. Edges still of more than two triangles: the first wedge keeps the edge, each other
  /// wedge's triangles are split at a midpoint vertex of their own.
  void splitPinchedEdges(BoundarySurface& out, std::vector<uint8_t>& moved) {
    std::map<uint64_t, std::vector<uint32_t>> onEdge;  // surface edge -> its wedges (indices into wedges_)
    for (size_t w = 0; w < wedges_.size(); ++w) {
      const uint32_t a = uint32_t(wedges_[w].edge >> 32), b = uint32_t(wedges_[w].edge & 0xffffffffu);
      onEdge[edgeKey(surfaceVertex(out, wedges_[w].s, a), surfaceVertex(out, wedges_[w].s, b))].push_back(uint32_t(w));
    }
    std::vector<std::pair<uint32_t, uint32_t>> halves;  // (triangle, a half split off it)
    for (const auto& entry : onEdge) {
      // Not a structured binding: the lambda below uses the key, and clang 14 (the sanitizer
      // build's compiler) does not let lambdas capture structured bindings.
      const auto key = entry.first;
      const auto& list = entry.second;
      // The edge's place in triangle t, or -1.
      auto edgeAt = [&](uint32_t t) {
        const auto& v = out.triangles[t].v;
        for (int e = 0; e < 3; ++e)
          if (edgeKey(v[size_t(e)], v[size_t((e + 1) % 3)]) == key) return e;
        return -1;
      };
      for (size_t k = 1; k < list.size(); ++k) {
        const Wedge& w = wedges_[list[k]];
        const uint32_t m = uint32_t(out.positions.size());
        const uint32_t a = uint32_t(w.edge >> 32), b = uint32_t(w.edge & 0xffffffffu);
        out.positions.push_back(0.5 * (mesh_.positions[a] + mesh_.positions[b]));
        out.sources.push_back({a, b});
        moved.push_back(1);
        ++out.splitEdges;
        for (uint32_t t0 : {w.s, w.t}) {
          // The triangle holding the edge: t0 or a half of it split at another edge.
          uint32_t t = t0;
          int e = edgeAt(t);
          for (size_t h = 0; e < 0 && h < halves.size(); ++h)
            if (halves[h].first == t0) e = edgeAt(t = halves[h].second);
          if (e < 0) continue;
          // (p, q, r) with p-q the edge, in the triangle's order -> (p, m, r) and (m, q, r).
          InterfaceTriangle second = out.triangles[t];
          out.triangles[t].v[size_t((e + 1) % 3)] = m;
          second.v[size_t(e)] = m;
          halves.push_back({t0, uint32_t(out.triangles.size())});
          out.triangles.push_back(second);
          tetOf_.push_back(tetOf_[t]);
        }
      }
    }
  }

  /// 5. Pull the moved surface vertices into their own sheets.
  void pullMoved(BoundarySurface& out, const std::vector<uint8_t>& moved, double pull) const {
    if (!(pull > 0) || std::find(moved.begin(), moved.end(), 1) == moved.end()) return;
    const size_t ns = out.positions.size();
    std::vector<DVec3> toward(ns, DVec3(0.0)), at(ns);
    for (size_t s = 0; s < ns; ++s) at[s] = 0.5 * (mesh_.positions[out.sources[s][0]] + mesh_.positions[out.sources[s][1]]);
    std::vector<double> shortest(ns, INFINITY);
    for (size_t t = 0; t < out.triangles.size(); ++t)
      for (size_t c = 0; c < 3; ++c) {
        const uint32_t s = out.triangles[t].v[c];
        if (!moved[s]) continue;
        const auto& q = mesh_.tets[tetOf_[t]];
        toward[s] += (mesh_.positions[q[0]] + mesh_.positions[q[1]] + mesh_.positions[q[2]] + mesh_.positions[q[3]]) * 0.25 - at[s];
        for (uint32_t o : out.triangles[t].v)
          if (o != s) shortest[s] = std::min(shortest[s], glm::length(at[o] - at[s]));
      }
    for (size_t s = 0; s < ns; ++s)
      if (moved[s] && glm::length(toward[s]) > 0) out.positions[s] = at[s] + pull * shortest[s] * glm::normalize(toward[s]);
  }

  const TetMesh& mesh_;
  const std::vector<uint8_t>& selected_;
  std::vector<InterfaceTriangle> tris_;
  std::vector<uint32_t> tetOf_;   ///< the tetrahedron of each triangle (and of each half split off)
  DisjointSets corners_{0};  ///< union-find over triangle corners (3 t + i)
  std::vector<uint32_t> start_, items_;
  std::vector<Wedge> wedges_;     ///< at the edges of more than two triangles, in edge order
};

}  // namespace

BoundarySurface boundarySurface(const TetMesh& mesh, const std::vector<uint8_t>& selected, double pull) {
  return BoundaryBuilder(mesh, selected).build(pull);
}

}  // namespace sprig::solids
