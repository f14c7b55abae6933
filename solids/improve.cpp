#include "solids/improve.h"

#include "core/parallel.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <vector>

namespace sprig::solids {

namespace {

using Tet = std::array<uint32_t, 4>;
/// The material across a face of the visible interface.
constexpr uint16_t kOutside = 0xFFFF;
/// An interface's material pair, the smaller id in the high half.
using Pair = uint32_t;

Pair pairOf(uint16_t a, uint16_t b) { return a < b ? (uint32_t(a) << 16) | b : (uint32_t(b) << 16) | a; }

double signedVolume(const DVec3& a, const DVec3& b, const DVec3& c, const DVec3& d) {
  return glm::dot(glm::cross(b - a, c - a), d - a) / 6.0;
}

bool contains(const Tet& t, uint32_t v) { return t[0] == v || t[1] == v || t[2] == v || t[3] == v; }

template <class T>
void sortUnique(std::vector<T>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

/// The mesh while it is improved: tetrahedra die in place and new ones are appended; each
/// vertex knows its live tetrahedra. Every action is local and checked before it is taken.
class Improver {
 public:
  Improver(TetMesh& mesh, const ImproveOptions& options) : m_(mesh), o_(options) {
    double total = 0;
    for (size_t t = 0; t < m_.tets.size(); ++t) total += m_.volume(t);
    ideal_ = total / double(o_.targetCount > 0 ? o_.targetCount : std::max<size_t>(1, m_.tets.size()));
    double edge = 0;
    for (const Tet& t : m_.tets) edge += glm::length(m_.positions[t[1]] - m_.positions[t[0]]);
    // Flat means flat to this: rounding of the positions, not a modelling choice.
    tolerance_ = std::max(o_.interfaceTolerance, 1e-9 * (m_.tets.empty() ? 1.0 : edge / double(m_.tets.size())));
    alive_.assign(m_.tets.size(), 1);
    settled_.assign(m_.tets.size(), 0);
    q_.resize(m_.tets.size());
    parallelFor(0, m_.tets.size(), [&](size_t t) { q_[t] = quality(m_.tets[t]); }, 4096);
    star_.resize(m_.positions.size());
    for (uint32_t t = 0; t < m_.tets.size(); ++t)
      for (uint32_t v : m_.tets[t]) star_[v].push_back(t);
    // No action adds a vertex to an interface or takes one off (a collapse merges v into a
    // u on all of v's interfaces), so this stays true.
    onInterface_.assign(m_.positions.size(), 0);
    for (const auto& t : visibleInterface(m_))
      for (uint32_t v : t.v) onInterface_[v] = 1;
    for (const auto& t : materialInterfaces(m_))
      for (uint32_t v : t.v) onInterface_[v] = 1;
  }

  double ideal() const { return ideal_; }

  /// The paper's loop (§4.4): thresholds q = 1, 2, …; each tetrahedron at most q is offered
  /// the actions until one is taken.
  void run(ImproveStats& st) {
    stats_ = &st;
    for (int q = 1; q <= int(std::floor(o_.qualityBelow)); ++q) {
      std::vector<uint32_t> low;
      for (uint32_t t = 0; t < m_.tets.size(); ++t)
        if (alive_[t] && !settled_[t] && quality(t) <= q) low.push_back(t);
      for (uint32_t t : low)
        if (alive_[t] && !settled_[t] && quality(t) <= q && !improve(t)) settled_[t] = 1;
    }
  }

  /// Live tetrahedra in order and the vertices they use, in their old order.
  void compact() {
    std::vector<uint32_t> id(m_.positions.size(), UINT32_MAX);
    for (uint32_t t = 0; t < m_.tets.size(); ++t)
      if (alive_[t])
        for (uint32_t v : m_.tets[t]) id[v] = 0;
    std::vector<DVec3> positions;
    for (uint32_t v = 0; v < id.size(); ++v)
      if (id[v] == 0) id[v] = uint32_t(positions.size()), positions.push_back(m_.positions[v]);
    std::vector<Tet> tets;
    std::vector<uint16_t> materials;
    for (uint32_t t = 0; t < m_.tets.size(); ++t) {
      if (!alive_[t]) continue;
      tets.push_back({id[m_.tets[t][0]], id[m_.tets[t][1]], id[m_.tets[t][2]], id[m_.tets[t][3]]});
      materials.push_back(m_.materials[t]);
    }
    m_.positions = std::move(positions);
    m_.tets = std::move(tets);
    m_.materials = std::move(materials);
  }

 private:
  double quality(const Tet& t) const {
    return tetQuality(m_.positions[t[0]], m_.positions[t[1]], m_.positions[t[2]], m_.positions[t[3]], ideal_);
  }
  double quality(uint32_t t) const { return q_[t]; }
  double volume(const Tet& t) const {
    return signedVolume(m_.positions[t[0]], m_.positions[t[1]], m_.positions[t[2]], m_.positions[t[3]]);
  }

  void kill(uint32_t t) {
    alive_[t] = 0;
    for (uint32_t v : m_.tets[t]) {
      auto& s = star_[v];
      s.erase(std::find(s.begin(), s.end(), t));
    }
  }

  void add(const Tet& t, uint16_t material) {
    const auto id = uint32_t(m_.tets.size());
    m_.tets.push_back(t);
    m_.materials.push_back(material);
    alive_.push_back(1);
    settled_.push_back(0);
    q_.push_back(quality(t));
    for (uint32_t v : t) star_[v].push_back(id);
    unsettleAround(t);
  }

  /// Marks the tetrahedra around t's corners for another try.
  void unsettleAround(const Tet& t) {
    for (uint32_t v : t)
      for (uint32_t s : star_[v]) settled_[s] = 0;
  }

  /// The live tetrahedron other than t holding face (a, b, c), or -1.
  int64_t across(uint32_t t, uint32_t a, uint32_t b, uint32_t c) const {
    for (uint32_t s : star_[a])
      if (s != t && contains(m_.tets[s], b) && contains(m_.tets[s], c)) return s;
    return -1;
  }

  /// The material behind face (a, b, c) of t (kOutside on the visible interface).
  uint16_t behind(uint32_t t, uint32_t a, uint32_t b, uint32_t c) const {
    const int64_t s = across(t, a, b, c);
    return s < 0 ? kOutside : m_.materials[size_t(s)];
  }

  /// The interface faces (sorted vertex ids and their pair) of t that hold every vertex of `must`.
  template <class F>
  void interfaceFaces(uint32_t t, std::initializer_list<uint32_t> must, F&& f) const {
    const Tet& q = m_.tets[t];
    for (int skip = 0; skip < 4; ++skip) {
      std::array<uint32_t, 3> face;
      for (int i = 0, k = 0; i < 4; ++i)
        if (i != skip) face[size_t(k++)] = q[size_t(i)];
      bool ok = true;
      for (uint32_t v : must) ok = ok && (face[0] == v || face[1] == v || face[2] == v);
      if (!ok) continue;
      const uint16_t other = behind(t, face[0], face[1], face[2]);
      if (other == m_.materials[t]) continue;
      std::sort(face.begin(), face.end());
      f(face, pairOf(m_.materials[t], other));
    }
  }

  /// The interfaces vertex v lies on (sorted).
  std::vector<Pair> pairsAt(uint32_t v) const {
    std::vector<Pair> out;
    for (uint32_t t : star_[v]) interfaceFaces(t, {v}, [&](const auto&, Pair p) { out.push_back(p); });
    sortUnique(out);
    return out;
  }

  /// The interfaces edge (u, v) lies on (sorted), and the number of distinct faces of each.
  std::vector<std::pair<Pair, int>> pairsAt(uint32_t u, uint32_t v) const {
    std::vector<std::pair<std::array<uint32_t, 3>, Pair>> faces;
    for (uint32_t t : star_[v])
      if (contains(m_.tets[t], u)) interfaceFaces(t, {u, v}, [&](const auto& f, Pair p) { faces.push_back({f, p}); });
    sortUnique(faces);
    std::vector<std::pair<Pair, int>> out;
    for (const auto& face : faces) {
      const Pair p = face.second;
      auto it = std::find_if(out.begin(), out.end(), [p](const auto& e) { return e.first == p; });
      if (it == out.end()) out.push_back({p, 1});
      else ++it->second;
    }
    std::sort(out.begin(), out.end());
    return out;
  }

  static std::vector<Pair> pairsOnly(const std::vector<std::pair<Pair, int>>& e) {
    std::vector<Pair> out;
    for (const auto& [p, n] : e) out.push_back(p);
    return out;
  }

  std::vector<uint32_t> neighbours(uint32_t v) const {
    std::vector<uint32_t> out;
    for (uint32_t t : star_[v])
      for (uint32_t w : m_.tets[t])
        if (w != v) out.push_back(w);
    sortUnique(out);
    return out;
  }

  /// Offers t the actions in turn; true when one was taken.
  bool improve(uint32_t t) {
    const Tet q = m_.tets[t];
    if (o_.flips) {
      for (int i = 0; i < 4; ++i)
        if (flip23(t, i)) return true;
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j)
          if (flip32(q[size_t(i)], q[size_t(j)]) || flip22(q[size_t(i)], q[size_t(j)])) return true;
    }
    if (o_.smoothing)
      for (uint32_t v : q)
        if (smooth(v)) return true;
    if (o_.collapses)
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
          if (i != j && collapse(q[size_t(i)], q[size_t(j)])) return true;
    return false;
  }

  /// The qualities of a set of tetrahedra: the smallest, their sum and count.
  struct Tally {
    double min = 1e300, sum = 0;
    size_t n = 0;
    void add(double q) { min = std::min(min, q), sum += q, ++n; }
    /// The paper's rule (§4.4): the worst of the tetrahedra an action touches must rise;
    /// and their mean must not fall (an action that mends one sliver by spoiling its
    /// neighbours is refused).
    bool improvesOn(const Tally& before) const {
      return n > 0 && min > 0 && min > before.min && sum * double(before.n) >= before.sum * double(n);
    }
  };

  /// A flip: replaces `dead` (tetrahedra of one material) by `made` (oriented) when every
  /// made tetrahedron is positive, they fill the volume of dead, they improve on it
  /// (Tally::improvesOn) and fresh() holds (the new edge or face is not in the mesh yet;
  /// asked last, the dearest test). Counts the flip in counter.
  bool replace(std::initializer_list<uint32_t> dead, std::initializer_list<Tet> made, const std::function<bool()>& fresh,
               size_t& counter) {
    Tally before, after;
    double old = 0, sum = 0;
    for (uint32_t t : dead) before.add(quality(t)), old += volume(m_.tets[t]);
    for (const Tet& x : made) {
      const double v = volume(x);
      if (!(v > 0)) return false;
      sum += v;
      after.add(quality(x));
    }
    if (std::abs(sum - old) > 1e-9 * old || !after.improvesOn(before) || !fresh()) return false;
    const uint16_t material = m_.materials[*dead.begin()];
    for (uint32_t t : dead) kill(t);
    for (const Tet& x : made) add(x, material);
    ++counter;
    return true;
  }

  /// 2→3: t and its neighbour across the face opposite corner i become three tetrahedra
  /// around the edge joining the two apexes.
  bool flip23(uint32_t t, int i) {
    const Tet q = m_.tets[t];
    const uint32_t d = q[size_t(i)];
    std::array<uint32_t, 3> f;
    for (int k = 0, n = 0; k < 4; ++k)
      if (k != i) f[size_t(n++)] = q[size_t(k)];
    const int64_t s = across(t, f[0], f[1], f[2]);
    if (s < 0 || m_.materials[size_t(s)] != m_.materials[t]) return false;
    const Tet& r = m_.tets[size_t(s)];
    uint32_t e = 0;
    for (uint32_t w : r)
      if (w != f[0] && w != f[1] && w != f[2]) e = w;
    // t with each corner of the shared face replaced by e keeps t's orientation.
    Tet made[3];
    for (int k = 0, n = 0; k < 4; ++k)
      if (k != i) made[n] = q, made[n++][size_t(k)] = e;
    return replace({t, uint32_t(s)}, {made[0], made[1], made[2]}, [&] {
      for (uint32_t w : star_[d])
        if (contains(m_.tets[w], e)) return false;  // the edge d-e exists already
      return true;
    }, stats_->flips23);
  }

  /// The live tetrahedra around edge (a, b), at most n of them, into ring: their count, or
  /// n + 1 when there are more.
  size_t edgeRing(uint32_t a, uint32_t b, uint32_t* ring, size_t n) const {
    size_t k = 0;
    for (uint32_t t : star_[a])
      if (contains(m_.tets[t], b)) {
        if (k == n) return n + 1;
        ring[k++] = t;
      }
    return k;
  }

  /// 3→2: the three tetrahedra around an inner edge (a, b) of one material become two
  /// sharing the triangle of their other corners.
  bool flip32(uint32_t a, uint32_t b) {
    uint32_t ring[3];
    if (edgeRing(a, b, ring, 3) != 3) return false;
    const uint16_t material = m_.materials[ring[0]];
    std::array<uint32_t, 6> others;
    size_t k = 0;
    for (uint32_t t : ring) {
      if (m_.materials[t] != material) return false;
      for (uint32_t w : m_.tets[t])
        if (w != a && w != b) others[k++] = w;
    }
    // A closed ring: each other corner in exactly two of the three tetrahedra.
    std::sort(others.begin(), others.end());
    if (others[0] != others[1] || others[2] != others[3] || others[4] != others[5] || others[1] == others[2] ||
        others[3] == others[4])
      return false;
    const uint32_t c = others[0], d = others[2], e = others[4];
    Tet x = {c, d, e, a}, y = {c, d, e, b};
    if (volume(x) < 0) std::swap(x[1], x[2]);
    if (volume(y) < 0) std::swap(y[1], y[2]);
    // The triangle c-d-e must not exist already.
    return replace({ring[0], ring[1], ring[2]}, {x, y}, [&] { return across(UINT32_MAX, c, d, e) < 0; }, stats_->flips32);
  }

  /// 2→2: the two tetrahedra around an edge (a, b) of the visible interface whose two
  /// faces there are flat (within the tolerance) swap that edge for the other diagonal
  /// (c, d) of the quadrilateral a-c-b-d; the visible interface keeps its shape.
  bool flip22(uint32_t a, uint32_t b) {
    uint32_t ring[2];
    if (edgeRing(a, b, ring, 2) != 2 || m_.materials[ring[0]] != m_.materials[ring[1]]) return false;
    // ring[0] = (a, b, c, x) and ring[1] = (a, b, d, x): they share the face (a, b, x).
    uint32_t other[2][2];
    for (int k = 0; k < 2; ++k) {
      int m = 0;
      for (uint32_t w : m_.tets[ring[k]])
        if (w != a && w != b) other[k][m++] = w;
    }
    uint32_t x = 0, c = 0, d = 0;
    bool shared = false;
    for (int i = 0; i < 2 && !shared; ++i)
      for (int j = 0; j < 2 && !shared; ++j)
        if (other[0][i] == other[1][j]) x = other[0][i], c = other[0][1 - i], d = other[1][1 - j], shared = true;
    if (!shared || c == d) return false;
    // Both faces at the edge are visible and lie in one plane.
    if (across(ring[0], a, b, c) >= 0 || across(ring[1], a, b, d) >= 0) return false;
    const DVec3 &pa = m_.positions[a], &pb = m_.positions[b], &pc = m_.positions[c], &pd = m_.positions[d];
    const DVec3 normal = glm::cross(pb - pa, pc - pa);
    const double len = glm::length(normal);
    if (!(len > 0) || std::abs(glm::dot(pd - pa, normal)) / len > tolerance_) return false;
    Tet y = {c, d, x, a}, z = {c, d, x, b};
    if (volume(y) < 0) std::swap(y[0], y[1]);
    if (volume(z) < 0) std::swap(z[0], z[1]);
    return replace({ring[0], ring[1]}, {y, z}, [&] {
      for (uint32_t t : star_[c])
        if (contains(m_.tets[t], d)) return false;  // the edge c-d exists already
      return true;
    }, stats_->flips22);
  }

  /// Whether removing v into u keeps the interfaces v lies on (see the header).
  bool keepsInterfaces(uint32_t v, uint32_t u) const {
    if (!onInterface_[v]) return true;
    const std::vector<Pair> pv = pairsAt(v);
    const auto edge = pairsAt(u, v);
    if (pairsOnly(edge) != pv) return false;
    // Each interface face around v that does not hold u moves to u (also those of the edge's
    // tetrahedra, whose neighbours' faces take their place): v must lie within the tolerance
    // of its new plane.
    const DVec3 p = m_.positions[v];
    for (uint32_t t : star_[v]) {
      bool ok = true;
      interfaceFaces(t, {v}, [&](const std::array<uint32_t, 3>& f, Pair) {
        if (f[0] == u || f[1] == u || f[2] == u) return;
        DVec3 c[3];
        for (int k = 0; k < 3; ++k) c[k] = m_.positions[f[size_t(k)] == v ? u : f[size_t(k)]];
        const DVec3 n = glm::cross(c[1] - c[0], c[2] - c[0]);
        const double len = glm::length(n);
        if (!(len > 0) || std::abs(glm::dot(p - c[0], n)) / len > tolerance_) ok = false;
      });
      if (!ok) return false;
    }
    // Every interface edge at v: on one sheet, two faces of it; on a curve, v has two.
    int curveEdges = 0;
    uint32_t w = u;
    for (uint32_t n : neighbours(v)) {
      const auto e = pairsAt(n, v);
      if (e.empty()) continue;
      if (pv.size() == 1) {
        if (e.size() != 1 || e[0].second != 2) return false;
      } else if (pairsOnly(e) == pv) {
        ++curveEdges;
        if (n != u) w = n;
      }
    }
    if (pv.size() > 1) {
      if (curveEdges != 2) return false;
      // The curve through w, v, u becomes the segment w-u.
      const DVec3 &a = m_.positions[u], &b = m_.positions[w];
      const DVec3 ab = b - a;
      const double len2 = glm::dot(ab, ab);
      if (!(len2 > 0)) return false;
      const double s = std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0);
      if (glm::length(p - (a + s * ab)) > tolerance_) return false;
    }
    return true;
  }

  /// The link condition of Dey et al. (1999) for edge (u, v): the links of u and v meet
  /// exactly in the link of the edge (vertices, edges and triangles).
  bool linkCondition(uint32_t u, uint32_t v) const {
    std::vector<uint32_t> both;
    std::vector<std::array<uint32_t, 2>> edgeLink;
    for (uint32_t t : star_[v]) {
      if (!contains(m_.tets[t], u)) continue;
      std::array<uint32_t, 2> e{};
      int k = 0;
      for (uint32_t w : m_.tets[t])
        if (w != u && w != v) both.push_back(w), e[size_t(k++)] = w;
      if (e[0] > e[1]) std::swap(e[0], e[1]);
      edgeLink.push_back(e);
    }
    sortUnique(both);
    sortUnique(edgeLink);
    std::vector<uint32_t> nu = neighbours(u), nv = neighbours(v), common;
    std::set_intersection(nu.begin(), nu.end(), nv.begin(), nv.end(), std::back_inserter(common));
    if (common != both) return false;
    // Edges and triangles opposite u and v in their stars.
    auto linkOf = [&](uint32_t x, std::vector<std::array<uint32_t, 2>>& edges, std::vector<std::array<uint32_t, 3>>& tris) {
      for (uint32_t t : star_[x]) {
        std::array<uint32_t, 3> f{};
        int k = 0;
        for (uint32_t w : m_.tets[t])
          if (w != x) f[size_t(k++)] = w;
        std::sort(f.begin(), f.end());
        tris.push_back(f);
        edges.push_back({f[0], f[1]});
        edges.push_back({f[0], f[2]});
        edges.push_back({f[1], f[2]});
      }
      sortUnique(edges);
      sortUnique(tris);
    };
    std::vector<std::array<uint32_t, 2>> eu, ev, ecommon;
    std::vector<std::array<uint32_t, 3>> tu, tv, tcommon;
    linkOf(u, eu, tu);
    linkOf(v, ev, tv);
    std::set_intersection(eu.begin(), eu.end(), ev.begin(), ev.end(), std::back_inserter(ecommon));
    for (const auto& e : ecommon)
      if (e[0] != u && e[1] != u && e[0] != v && e[1] != v && !std::binary_search(edgeLink.begin(), edgeLink.end(), e))
        return false;
    std::set_intersection(tu.begin(), tu.end(), tv.begin(), tv.end(), std::back_inserter(tcommon));
    return tcommon.empty();
  }

  /// Half-edge collapse: v merges into its neighbour u; the tetrahedra of the edge die and
  /// v's others take u in its place.
  bool collapse(uint32_t v, uint32_t u) {
    Tally before, after;
    for (uint32_t t : star_[v]) before.add(quality(t));
    for (uint32_t t : star_[v]) {
      if (contains(m_.tets[t], u)) continue;
      Tet x = m_.tets[t];
      *std::find(x.begin(), x.end(), v) = u;
      const double q = quality(x);
      if (!(q > before.min)) return false;
      after.add(q);
    }
    if (!after.improvesOn(before) || !keepsInterfaces(v, u) || !linkCondition(u, v)) return false;
    const std::vector<uint32_t> around = star_[v];
    for (uint32_t t : around) {
      if (contains(m_.tets[t], u)) {
        kill(t);
        continue;
      }
      *std::find(m_.tets[t].begin(), m_.tets[t].end(), v) = u;
      q_[t] = quality(m_.tets[t]);
      star_[u].push_back(t);
    }
    star_[v].clear();
    for (uint32_t t : star_[u]) unsettleAround(m_.tets[t]);
    ++stats_->collapses;
    return true;
  }

  /// Moves v (on no interface) toward its neighbours' centroid by the largest of the steps
  /// 1, 1/2, 1/4, 1/8 that raises the worst quality around it (and keeps their mean).
  bool smooth(uint32_t v) {
    if (star_[v].empty() || onInterface_[v]) return false;
    Tally before;
    for (uint32_t t : star_[v]) before.add(quality(t));
    DVec3 centroid(0.0);
    const std::vector<uint32_t> ns = neighbours(v);
    for (uint32_t n : ns) centroid += m_.positions[n];
    centroid /= double(ns.size());
    const DVec3 old = m_.positions[v];
    for (double step = 1.0; step > 0.1; step *= 0.5) {
      m_.positions[v] = old + step * (centroid - old);
      Tally after;
      for (uint32_t t : star_[v]) {
        const double q = quality(m_.tets[t]);
        if (!(q > before.min)) break;
        after.add(q);
      }
      if (after.n == star_[v].size() && after.improvesOn(before)) {
        for (uint32_t t : star_[v]) q_[t] = quality(m_.tets[t]);
        for (uint32_t t : star_[v]) unsettleAround(m_.tets[t]);
        ++stats_->moves;
        return true;
      }
    }
    m_.positions[v] = old;
    return false;
  }

  TetMesh& m_;
  const ImproveOptions& o_;
  double ideal_ = 1, tolerance_ = 0;
  std::vector<uint8_t> alive_;
  /// Per tetrahedron: every action failed and nothing around it has changed since (an
  /// action's outcome depends only on the tetrahedra around it, so it would fail again).
  std::vector<uint8_t> settled_;
  std::vector<uint8_t> onInterface_;  ///< per vertex
  std::vector<double> q_;  ///< quality per tetrahedron, kept current
  std::vector<std::vector<uint32_t>> star_;
  ImproveStats* stats_ = nullptr;
};

}  // namespace

ImproveStats improveQuality(TetMesh& mesh, const ImproveOptions& options) {
  ImproveStats st;
  st.tetsBefore = mesh.tets.size();
  if (mesh.tets.empty()) return st;
  const size_t target = options.targetCount > 0 ? options.targetCount : mesh.tets.size();
  st.before = measureQuality(mesh, target);
  Improver improver(mesh, options);
  improver.run(st);
  improver.compact();
  st.tetsAfter = mesh.tets.size();
  st.after = measureQuality(mesh, target);
  return st;
}

}  // namespace sprig::solids
