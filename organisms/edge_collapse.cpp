#include "organisms/edge_collapse.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace sprig::organisms {

namespace {

// A symmetric 4x4 quadric: the area-weighted sum of squared distances to a set of
// planes, and the total weight.
struct Quadric {
  double xx = 0, xy = 0, xz = 0, xw = 0, yy = 0, yz = 0, yw = 0, zz = 0, zw = 0, ww = 0, weight = 0;

  // Adds the plane n·p + d = 0 (n unit length) with weight w.
  void addPlane(const glm::dvec3& n, double d, double w) {
    xx += w * n.x * n.x, xy += w * n.x * n.y, xz += w * n.x * n.z, xw += w * n.x * d;
    yy += w * n.y * n.y, yz += w * n.y * n.z, yw += w * n.y * d;
    zz += w * n.z * n.z, zw += w * n.z * d, ww += w * d * d, weight += w;
  }
  void add(const Quadric& q) {
    xx += q.xx, xy += q.xy, xz += q.xz, xw += q.xw, yy += q.yy, yz += q.yz, yw += q.yw, zz += q.zz, zw += q.zw,
        ww += q.ww, weight += q.weight;
  }
  // The weighted mean squared distance of p to the planes (as meshoptimizer normalizes
  // its quadrics), so that its square root is a distance.
  double eval(const glm::dvec3& p) const {
    double v = xx * p.x * p.x + yy * p.y * p.y + zz * p.z * p.z + ww +
               2 * (xy * p.x * p.y + xz * p.x * p.z + yz * p.y * p.z + xw * p.x + yw * p.y + zw * p.z);
    return weight > 0 ? std::max(v, 0.0) / weight : 0.0;
  }
};

// A collapse of vertex `from` onto vertex `to`.
struct Candidate {
  double cost;
  uint32_t from, to;
  // Cheapest first; ties by vertex ids, so the order is the same on every machine.
  bool operator<(const Candidate& o) const {
    if (cost != o.cost) return cost < o.cost;
    if (from != o.from) return from < o.from;
    return to < o.to;
  }
};

class Collapser {
 public:
  Collapser(const std::vector<Vec3>& positions, const std::vector<uint32_t>& indices)
      : p_(positions.begin(), positions.end()),
        faces_(indices.size() / 3),
        alive_(faces_.size(), 1),
        vertexFaces_(positions.size()),
        quadrics_(positions.size()),
        locked_(positions.size(), 0),
        dead_(positions.size(), 0),
        touched_(positions.size(), 0) {
    // Faces, the faces of each vertex, and each vertex's quadric of its faces' planes.
    for (size_t f = 0; f < faces_.size(); ++f) {
      faces_[f] = {indices[3 * f], indices[3 * f + 1], indices[3 * f + 2]};
      glm::dvec3 n = glm::cross(p_[faces_[f][1]] - p_[faces_[f][0]], p_[faces_[f][2]] - p_[faces_[f][0]]);
      double len = glm::length(n);
      for (uint32_t v : faces_[f]) vertexFaces_[v].push_back(uint32_t(f));
      if (len == 0) continue;
      for (uint32_t v : faces_[f]) quadrics_[v].addPlane(n / len, -glm::dot(n / len, p_[faces_[f][0]]), 0.5 * len);
    }
    // Vertices of edges with one face (boundary) or more than two stay where they are.
    std::vector<std::pair<uint64_t, uint32_t>> edges;
    edges.reserve(indices.size());
    for (const auto& t : faces_)
      for (int k = 0; k < 3; ++k) {
        uint32_t a = t[k], b = t[(k + 1) % 3];
        edges.push_back({(uint64_t(std::min(a, b)) << 32) | std::max(a, b), 0});
      }
    std::sort(edges.begin(), edges.end());
    for (size_t i = 0; i < edges.size();) {
      size_t j = i;
      while (j < edges.size() && edges[j].first == edges[i].first) ++j;
      if (j - i != 2) locked_[edges[i].first >> 32] = locked_[uint32_t(edges[i].first)] = 1;
      i = j;
    }
    faceCount_ = faces_.size();
  }

  // Collapses until target faces, no legal move, or a cost above maxCost. Works in passes,
  // as meshoptimizer does: every edge's cheaper direction, sorted, collapsed in order
  // unless its moving vertex has absorbed another in this pass (its quadric changed, so
  // the cost is stale; every other cost is still exact, and legality is tested on the
  // mesh as it is), then again over what is left. Sorting a flat array keeps memory
  // access cheap, where a heap of candidates spends its time in cache misses.
  double run(size_t target, double maxCost) {
    double worst = 0;
    std::vector<Candidate> candidates;
    for (uint32_t pass = 1; faceCount_ > target; ++pass) {
      candidates.clear();
      for (size_t f = 0; f < faces_.size(); ++f) {
        if (!alive_[f]) continue;
        for (int k = 0; k < 3; ++k) {
          uint32_t a = faces_[f][k], b = faces_[f][(k + 1) % 3];
          if (a > b) continue;  // each interior edge once (its other face has it as b -> a)
          double ca = locked_[a] ? HUGE_VAL : quadrics_[a].eval(p_[b]);
          double cb = locked_[b] ? HUGE_VAL : quadrics_[b].eval(p_[a]);
          if (ca == HUGE_VAL && cb == HUGE_VAL) continue;
          candidates.push_back(ca <= cb ? Candidate{ca, a, b} : Candidate{cb, b, a});
        }
      }
      std::sort(candidates.begin(), candidates.end());
      size_t made = 0;
      for (const Candidate& c : candidates) {
        if (faceCount_ <= target || c.cost > maxCost) break;
        if (dead_[c.from] || dead_[c.to] || touched_[c.from] == pass) continue;
        if (!legal(c.from, c.to)) continue;
        collapse(c.from, c.to, pass);
        worst = std::max(worst, c.cost);
        ++made;
      }
      if (made == 0 || (!candidates.empty() && candidates.front().cost > maxCost)) break;
    }
    return worst;
  }

  std::vector<uint32_t> indices() const {
    std::vector<uint32_t> out;
    out.reserve(faceCount_ * 3);
    for (size_t f = 0; f < faces_.size(); ++f)
      if (alive_[f]) out.insert(out.end(), faces_[f].begin(), faces_[f].end());
    return out;
  }

 private:
  // The live faces of v (dead ones are dropped from its list on the way).
  const std::vector<uint32_t>& facesOf(uint32_t v) {
    auto& fs = vertexFaces_[v];
    fs.erase(std::remove_if(fs.begin(), fs.end(), [&](uint32_t f) { return !alive_[f]; }), fs.end());
    return fs;
  }

  static bool has(const std::array<uint32_t, 3>& t, uint32_t v) { return t[0] == v || t[1] == v || t[2] == v; }

  // Whether moving u onto v keeps the mesh manifold and every face facing as before.
  bool legal(uint32_t u, uint32_t v) {
    const std::vector<uint32_t>& fu = facesOf(u);
    const std::vector<uint32_t>& fv = facesOf(v);
    // The edge has two faces; their third vertices are the only neighbours u and v may
    // share (the link condition).
    uint32_t shared = 0;
    common_.clear();
    for (uint32_t f : fu)
      if (has(faces_[f], v)) {
        ++shared;
        for (uint32_t w : faces_[f])
          if (w != u && w != v) common_.push_back(w);
      }
    if (shared != 2) return false;
    for (uint32_t f : fu)
      for (uint32_t w : faces_[f]) {
        if (w == u || w == v || w == common_[0] || w == common_[1]) continue;
        for (uint32_t g : fv)
          if (has(faces_[g], w)) return false;
      }
    // Valences after the move: the two opposite vertices lose a face, and v gets u's
    // faces less the two: an inner vertex keeps three faces at the least, a border
    // vertex one.
    for (uint32_t o : common_)
      if (facesOf(o).size() < (locked_[o] ? 2u : 4u)) return false;
    if (fu.size() + fv.size() < (locked_[v] ? 1u : 3u) + 4) return false;
    // No face of u may flip or collapse when u moves to v.
    for (uint32_t f : fu) {
      const auto& t = faces_[f];
      if (has(t, v)) continue;
      glm::dvec3 q[3], r[3];
      for (int k = 0; k < 3; ++k) q[k] = p_[t[k]], r[k] = t[k] == u ? p_[v] : p_[t[k]];
      glm::dvec3 before = glm::cross(q[1] - q[0], q[2] - q[0]), after = glm::cross(r[1] - r[0], r[2] - r[0]);
      if (glm::length(after) <= 1e-12 * glm::length(before) || glm::dot(before, after) <= 0) return false;
    }
    return true;
  }

  // Moves u onto v; v is touched for the rest of the pass (its quadric changed).
  void collapse(uint32_t u, uint32_t v, uint32_t pass) {
    std::vector<uint32_t> moved = facesOf(u);
    for (uint32_t f : moved) {
      auto& t = faces_[f];
      if (has(t, v)) {
        alive_[f] = 0;
        --faceCount_;
        continue;
      }
      for (auto& w : t)
        if (w == u) w = v;
      vertexFaces_[v].push_back(f);
    }
    vertexFaces_[u].clear();
    dead_[u] = 1;
    quadrics_[v].add(quadrics_[u]);
    touched_[v] = pass;
  }

  std::vector<glm::dvec3> p_;
  std::vector<std::array<uint32_t, 3>> faces_;
  std::vector<char> alive_;
  std::vector<std::vector<uint32_t>> vertexFaces_;
  std::vector<Quadric> quadrics_;
  std::vector<char> locked_, dead_;
  std::vector<uint32_t> touched_;  // the pass in which a vertex last absorbed another
  size_t faceCount_ = 0;
  std::vector<uint32_t> common_;  // scratch: the two vertices opposite the edge being tested
};

}  // namespace

EdgeCollapseResult collapseEdges(const std::vector<Vec3>& positions, const std::vector<uint32_t>& indices,
                                 size_t targetFaces, float maxError) {
  Collapser c(positions, indices);
  double worst = c.run(targetFaces, double(maxError) * double(maxError));
  return {c.indices(), float(std::sqrt(worst))};
}

}  // namespace sprig::organisms
