#include "solids/operators.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/parallel.h"

namespace sprig::solids {

namespace {

bool finite(const DVec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

std::vector<uint8_t> usedVertices(const TetMesh& mesh) {
  std::vector<uint8_t> used(mesh.positions.size(), 0);
  for (const auto& q : mesh.tets)
    for (uint32_t v : q) used[v] = 1;
  return used;
}

/// The used vertices within kGroundBand of the mesh's extent along up of its lowest point
/// (where a model resting on the ground touches it: a plane base, or a cap of a round one).
constexpr double kGroundBand = 0.02;

std::vector<uint8_t> lowestVertices(const TetMesh& mesh, const DVec3& up) {
  const std::vector<uint8_t> used = usedVertices(mesh);
  double lo = INFINITY, hi = -INFINITY;
  for (size_t v = 0; v < used.size(); ++v)
    if (used[v]) {
      const double h = glm::dot(mesh.positions[v], up);
      lo = std::min(lo, h);
      hi = std::max(hi, h);
    }
  std::vector<uint8_t> out(used.size(), 0);
  const double tol = kGroundBand * (hi - lo);
  for (size_t v = 0; v < used.size(); ++v)
    if (used[v] && glm::dot(mesh.positions[v], up) <= lo + tol) out[v] = 1;
  return out;
}

DVec3 unitUp(const DVec3& up) {
  if (!finite(up) || glm::length(up) == 0) throw std::invalid_argument("'up' must be a finite, non-zero vector");
  return glm::normalize(up);
}

std::vector<uint8_t> asFixed(const std::vector<uint8_t>& flags) {
  std::vector<uint8_t> out(flags.size());
  for (size_t v = 0; v < flags.size(); ++v) out[v] = flags[v] ? 7 : 0;
  return out;
}

void checkIds(const std::vector<uint16_t>& ids, size_t count, const char* what) {
  for (uint16_t id : ids)
    if (id >= count)
      throw std::invalid_argument(std::string(what) + " names material id " + std::to_string(id) + ", but there are " +
                                  std::to_string(count) + " materials");
}

/// Keeps the tetrahedra with keep[t], in order; returns how many went.
size_t removeTets(TetMesh& mesh, const std::vector<uint8_t>& keep) {
  size_t out = 0;
  for (size_t t = 0; t < mesh.tets.size(); ++t)
    if (keep[t]) {
      mesh.tets[out] = mesh.tets[t];
      mesh.materials[out] = mesh.materials[t];
      ++out;
    }
  const size_t gone = mesh.tets.size() - out;
  mesh.tets.resize(out);
  mesh.materials.resize(out);
  return gone;
}

/// Removes every face-connected piece that `fixed` does not hold; returns how many tetrahedra went.
size_t dropLoose(TetMesh& mesh, const std::vector<uint8_t>& fixed) {
  const auto [component, count] = faceComponents(mesh);
  const std::vector<bool> held = componentsHeld(mesh, component, count, fixed);
  std::vector<uint8_t> keep(mesh.tets.size());
  for (size_t t = 0; t < keep.size(); ++t) keep[t] = held[component[t]] ? 1 : 0;
  return removeTets(mesh, keep);
}

/// Removes, round by round, the affected tetrahedra around edges of the visible interface
/// that more than two visible triangles share (two pieces touching along an edge only,
/// left by removals), until none is left or only unaffected tetrahedra meet there.
size_t mendEdges(TetMesh& mesh, const std::vector<uint8_t>& affected) {
  size_t gone = 0;
  for (int round = 0; round < 64; ++round) {
    std::vector<uint64_t> edges;
    for (const InterfaceTriangle& t : visibleInterface(mesh))
      for (int e = 0; e < 3; ++e) {
        const uint32_t a = t.v[size_t(e)], b = t.v[size_t((e + 1) % 3)];
        edges.push_back(a < b ? (uint64_t(a) << 32) | b : (uint64_t(b) << 32) | a);
      }
    std::sort(edges.begin(), edges.end());
    std::vector<uint64_t> bad;
    for (size_t i = 0; i < edges.size();) {
      size_t j = i + 1;
      while (j < edges.size() && edges[j] == edges[i]) ++j;
      if (j - i > 2) bad.push_back(edges[i]);
      i = j;
    }
    if (bad.empty()) break;
    std::vector<uint8_t> keep(mesh.tets.size(), 1);
    for (size_t t = 0; t < mesh.tets.size(); ++t) {
      if (!affected[mesh.materials[t]]) continue;
      const auto& q = mesh.tets[t];
      for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b) {
          const uint32_t x = q[size_t(a)], y = q[size_t(b)];
          if (std::binary_search(bad.begin(), bad.end(), x < y ? (uint64_t(x) << 32) | y : (uint64_t(y) << 32) | x)) keep[t] = 0;
        }
    }
    const size_t r = removeTets(mesh, keep);
    if (r == 0) break;
    gone += r;
  }
  return gone;
}

/// Removes, round by round, affected tetrahedra where the visible interface is not a
/// manifold (surfaceDefects), until it is or only unaffected tetrahedra meet there. At a bad
/// vertex (or edge) the tetrahedra around it are split into groups joined through faces at
/// it (the pieces that touch there); the affected tetrahedra of every group but the largest
/// go (the largest by count, then by lowest index), or, when they hold none or there is one
/// group only, the affected tetrahedra around it. Returns how many went.
size_t mendSurface(TetMesh& mesh, const std::vector<uint8_t>& affected) {
  size_t gone = 0;
  for (int round = 0; round < 64; ++round) {
    const SurfaceDefects bad = surfaceDefects(mesh);
    if (bad.edges.empty() && bad.vertices.empty()) break;
    // Tetrahedra by vertex (compressed rows).
    std::vector<uint32_t> start(mesh.positions.size() + 1, 0), items(mesh.tets.size() * 4);
    for (const auto& q : mesh.tets)
      for (uint32_t v : q) ++start[v + 1];
    for (size_t v = 0; v + 1 < start.size(); ++v) start[v + 1] += start[v];
    {
      std::vector<uint32_t> at(start.begin(), start.end() - 1);
      for (size_t t = 0; t < mesh.tets.size(); ++t)
        for (uint32_t v : mesh.tets[t]) items[at[v]++] = uint32_t(t);
    }
    std::vector<uint8_t> keep(mesh.tets.size(), 1);
    auto common = [&](uint32_t s, uint32_t t) {
      int n = 0;
      for (uint32_t x : mesh.tets[s]) n += std::find(mesh.tets[t].begin(), mesh.tets[t].end(), x) != mesh.tets[t].end() ? 1 : 0;
      return n;
    };
    // Separates the pieces meeting at the tetrahedra `star` (all around one vertex or edge).
    auto separate = [&](const std::vector<uint32_t>& star) {
      const size_t k = star.size();
      std::vector<uint32_t> parent(k);
      for (size_t a = 0; a < k; ++a) parent[a] = uint32_t(a);
      auto find = [&](uint32_t a) {
        while (parent[a] != a) a = parent[a] = parent[parent[a]];
        return a;
      };
      for (size_t a = 0; a < k; ++a)
        for (size_t b = a + 1; b < k; ++b)
          if (common(star[a], star[b]) == 3) parent[find(uint32_t(a))] = find(uint32_t(b));
      std::vector<size_t> size(k, 0);
      for (size_t a = 0; a < k; ++a) ++size[find(uint32_t(a))];
      uint32_t largest = find(0);
      for (size_t a = 0; a < k; ++a)
        if (size[find(uint32_t(a))] > size[largest]) largest = find(uint32_t(a));
      bool removed = false;
      for (size_t a = 0; a < k; ++a)
        if (find(uint32_t(a)) != largest && affected[mesh.materials[star[a]]]) keep[star[a]] = 0, removed = true;
      if (!removed)
        for (uint32_t t : star)
          if (affected[mesh.materials[t]]) keep[t] = 0;
    };
    std::vector<uint32_t> star;
    for (uint32_t v : bad.vertices) {
      star.assign(items.begin() + start[v], items.begin() + start[v + 1]);
      separate(star);
    }
    for (uint64_t e : bad.edges) {
      const uint32_t a = uint32_t(e >> 32), b = uint32_t(e & 0xffffffffu);
      star.clear();
      for (uint32_t i = start[a]; i < start[a + 1]; ++i) {
        const auto& q = mesh.tets[items[i]];
        if (std::find(q.begin(), q.end(), b) != q.end()) star.push_back(items[i]);
      }
      separate(star);
    }
    const size_t r = removeTets(mesh, keep);
    if (r == 0) break;
    gone += r;
  }
  return gone;
}

}  // namespace

SurfaceDefects surfaceDefects(const TetMesh& mesh) {
  SurfaceDefects out;
  const std::vector<InterfaceTriangle> tris = visibleInterface(mesh);
  std::vector<uint64_t> edges;
  std::vector<std::pair<uint32_t, uint32_t>> corners;  // (vertex, triangle)
  for (size_t t = 0; t < tris.size(); ++t)
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = tris[t].v[size_t(e)], b = tris[t].v[size_t((e + 1) % 3)];
      edges.push_back(a < b ? (uint64_t(a) << 32) | b : (uint64_t(b) << 32) | a);
      corners.push_back({a, uint32_t(t)});
    }
  std::sort(edges.begin(), edges.end());
  for (size_t i = 0; i < edges.size();) {
    size_t j = i + 1;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i > 2) out.edges.push_back(edges[i]);
    i = j;
  }
  // Fans: the triangles at a vertex, joined when they share a second vertex (an edge at it).
  std::sort(corners.begin(), corners.end());
  std::vector<uint32_t> parent;
  for (size_t i = 0; i < corners.size();) {
    size_t j = i + 1;
    while (j < corners.size() && corners[j].first == corners[i].first) ++j;
    const uint32_t v = corners[i].first;
    const size_t k = j - i;
    parent.resize(k);
    for (size_t a = 0; a < k; ++a) parent[a] = uint32_t(a);
    auto find = [&](uint32_t a) {
      while (parent[a] != a) a = parent[a] = parent[parent[a]];
      return a;
    };
    for (size_t a = 0; a < k; ++a)
      for (size_t b = a + 1; b < k; ++b) {
        const auto& ta = tris[corners[i + a].second].v;
        const auto& tb = tris[corners[i + b].second].v;
        bool share = false;
        for (uint32_t x : ta)
          if (x != v && std::find(tb.begin(), tb.end(), x) != tb.end()) share = true;
        if (share) parent[find(uint32_t(a))] = find(uint32_t(b));
      }
    size_t fans = 0;
    for (size_t a = 0; a < k; ++a) fans += find(uint32_t(a)) == a ? 1 : 0;
    if (fans > 1) out.vertices.push_back(v);
    i = j;
  }
  return out;
}

std::vector<uint8_t> hammerAnchors(const TetMesh& mesh, const HammerOptions& options) {
  const size_t nv = mesh.positions.size();
  if (!options.anchored.empty() && options.anchored.size() != nv)
    throw std::invalid_argument("hammer: 'anchored' has " + std::to_string(options.anchored.size()) +
                                " entries; the mesh has " + std::to_string(nv) + " vertices");
  std::vector<uint8_t> held(nv, 0);
  for (size_t v = 0; v < options.anchored.size(); ++v) held[v] = options.anchored[v] ? 1 : 0;
  if (!options.affects.empty())
    for (size_t t = 0; t < mesh.tets.size(); ++t)
      if (std::find(options.affects.begin(), options.affects.end(), mesh.materials[t]) == options.affects.end())
        for (uint32_t v : mesh.tets[t]) held[v] = 1;
  if (std::find(held.begin(), held.end(), 1) == held.end()) held = lowestVertices(mesh, unitUp(options.up));
  return held;
}

std::vector<DVec3> hammerForces(const TetMesh& mesh, const HammerOptions& options, const std::vector<uint8_t>& anchored) {
  if (!finite(options.position)) throw std::invalid_argument("hammer: 'position' is not finite");
  if (!finite(options.orientation) || glm::length(options.orientation) == 0)
    throw std::invalid_argument("hammer: 'orientation' must be a finite, non-zero vector");
  if (!std::isfinite(options.magnitude)) throw std::invalid_argument("hammer: 'magnitude' is not finite");
  if (!(options.size > 0) || !std::isfinite(options.size)) throw std::invalid_argument("hammer: 'size' must be positive");
  const std::vector<uint8_t> used = usedVertices(mesh);
  std::vector<double> w(mesh.positions.size(), 0.0);
  double sum = 0;
  for (size_t v = 0; v < w.size(); ++v) {
    if (!used[v] || (v < anchored.size() && anchored[v])) continue;
    const double d = glm::length(mesh.positions[v] - options.position) / options.size;
    if (d > 3) continue;
    w[v] = std::exp(-d * d);
    sum += w[v];
  }
  std::vector<DVec3> f(w.size(), DVec3(0.0));
  if (sum == 0) return f;
  const DVec3 total = options.magnitude * glm::normalize(options.orientation);
  for (size_t v = 0; v < w.size(); ++v) f[v] = (w[v] / sum) * total;
  return f;
}

HammerStats hammer(TetMesh& mesh, const std::vector<Material>& materials, const HammerOptions& options) {
  checkIds(options.affects, materials.size(), "hammer: 'affects'");
  if (options.rounds < 1) throw std::invalid_argument("hammer: 'rounds' must be at least 1");
  const std::vector<uint8_t> anchors = hammerAnchors(mesh, options);
  hammerForces(mesh, options, anchors);  // validates the blow before anything changes
  std::vector<uint8_t> affected(materials.size(), options.affects.empty() ? 1 : 0);
  for (uint16_t id : options.affects) affected[id] = 1;
  const std::vector<uint8_t> fixed = asFixed(anchors);

  HammerStats st;
  st.fallen += dropLoose(mesh, fixed);
  std::vector<DVec3> guess;
  for (int round = 0; round < options.rounds; ++round) {
    FemProblem pb;
    pb.forces = hammerForces(mesh, options, anchors);
    const size_t loaded = size_t(std::count_if(pb.forces.begin(), pb.forces.end(), [](const DVec3& f) { return f != DVec3(0.0); }));
    if (round == 0) st.loaded = loaded;
    if (loaded == 0 || mesh.tets.empty()) break;
    pb.fixed = fixed;
    pb.initialGuess = guess;
    FemResult r = solveElastic(mesh, materials, pb, options.fem);
    st.fem.push_back(r.stats);
    ++st.solves;
    std::vector<uint8_t> keep(mesh.tets.size(), 1);
    size_t breaking = 0;
    for (size_t t = 0; t < keep.size(); ++t) {
      const uint16_t id = mesh.materials[t];
      if (!affected[id]) continue;
      const double s = options.criterion == FractureCriterion::MaxPrincipal ? r.tets[t].maxPrincipal : r.tets[t].vonMises;
      if (s > materials[id].strength) {
        keep[t] = 0;
        ++breaking;
      }
    }
    if (breaking == 0) break;
    st.broken += removeTets(mesh, keep);
    st.fallen += dropLoose(mesh, fixed);
    if (options.manifold) {
      const size_t mended = mendSurface(mesh, affected);
      st.mended += mended;
      if (mended) st.fallen += dropLoose(mesh, fixed);
    }
    guess = std::move(r.displacement);
  }
  return st;
}

size_t compactVertices(TetMesh& mesh) {
  const std::vector<uint8_t> used = usedVertices(mesh);
  std::vector<uint32_t> id(mesh.positions.size(), UINT32_MAX);
  uint32_t next = 0;
  for (size_t v = 0; v < used.size(); ++v)
    if (used[v]) {
      id[v] = next;
      if (!mesh.tints.empty()) mesh.tints[next] = mesh.tints[v];
      mesh.positions[next++] = mesh.positions[v];
    }
  const size_t gone = mesh.positions.size() - next;
  mesh.positions.resize(next);
  if (!mesh.tints.empty()) mesh.tints.resize(next);
  for (auto& q : mesh.tets)
    for (uint32_t& v : q) v = id[v];
  return gone;
}

/// 6√2·V / l³ with l the root mean square of the six edge lengths: 1 for a regular
/// tetrahedron, toward 0 as it flattens.
double meanRatio(const TetMesh& mesh, size_t t) {
  const auto& q = mesh.tets[t];
  double l2 = 0;
  for (int a = 0; a < 4; ++a)
    for (int b = a + 1; b < 4; ++b) {
      const DVec3 e = mesh.positions[q[size_t(a)]] - mesh.positions[q[size_t(b)]];
      l2 += glm::dot(e, e);
    }
  const double l = std::sqrt(l2 / 6);
  return 6 * std::sqrt(2.0) * mesh.volume(t) / (l * l * l);
}

DisplaceStats displace(TetMesh& mesh, const std::vector<Material>& materials, const DisplaceOptions& options) {
  if (options.moving.empty()) throw std::invalid_argument("displace: 'moving' names no material");
  checkIds(options.moving, materials.size(), "displace: 'moving'");
  if (!finite(options.offset)) throw std::invalid_argument("displace: 'offset' is not finite");
  if (options.steps < 1) throw std::invalid_argument("displace: 'steps' must be at least 1");
  if (!(options.stiffening >= 0) || !std::isfinite(options.stiffening))
    throw std::invalid_argument("displace: 'stiffening' must be a finite number >= 0");
  if (!(options.maxStiffening >= 1) || !std::isfinite(options.maxStiffening))
    throw std::invalid_argument("displace: 'max_stiffening' must be a finite number >= 1");
  if (!(options.stiffenBelow >= 0 && options.stiffenBelow <= 1))
    throw std::invalid_argument("displace: 'stiffen_below' must be in [0, 1]");
  if (!(options.minStepVolumeRatio > 0 && options.minStepVolumeRatio < 1))
    throw std::invalid_argument("displace: 'min_step_volume_ratio' must be in (0, 1)");
  if (options.halvings < 0 || options.halvings > 30) throw std::invalid_argument("displace: 'halvings' must be in [0, 30]");
  const size_t nv = mesh.positions.size();
  if (!options.anchored.empty() && options.anchored.size() != nv)
    throw std::invalid_argument("displace: 'anchored' has " + std::to_string(options.anchored.size()) +
                                " entries; the mesh has " + std::to_string(nv) + " vertices");

  std::vector<uint8_t> moving(nv, 0);
  for (size_t t = 0; t < mesh.tets.size(); ++t)
    if (std::find(options.moving.begin(), options.moving.end(), mesh.materials[t]) != options.moving.end())
      for (uint32_t v : mesh.tets[t]) moving[v] = 1;
  const std::vector<uint8_t> held = options.anchored.empty() ? lowestVertices(mesh, unitUp(options.up)) : options.anchored;

  DisplaceStats st;
  FemProblem pb;
  pb.fixed.assign(nv, 0);
  pb.prescribed.assign(nv, DVec3(0.0));
  for (size_t v = 0; v < nv; ++v) {
    if (moving[v]) {
      pb.fixed[v] = 7;
      ++st.moved;
    } else if (held[v]) {
      pb.fixed[v] = 7;
      ++st.anchored;
    }
  }

  // The offset is applied in increments, each solved on the geometry the last one left (an
  // updated-Lagrangian sequence of linear solves). Two things keep soft tetrahedra from
  // inverting under motions much larger than the cell:
  //  - Jacobian stiffening (Stein, Tezduyar and Benney, "Mesh moving techniques for
  //    fluid-structure interactions with large displacements", J. Appl. Mech. 70, 2003): a
  //    tetrahedron crushed to a fraction r of its volume before the operation has its modulus
  //    scaled by r^-stiffening, so the crushed dirt between a rising root and a brick pushes
  //    the brick instead of folding; one whose shape (mean ratio q) is below stiffenBelow
  //    by (stiffenBelow/q)^stiffening, so what an earlier operation crushed stays stiff;
  //  - step control: an increment that leaves any tetrahedron with less than
  //    `minStepVolumeRatio` of the volume it had before it is undone and retried at half the
  //    size (down to 1/1024 of a step, then the error).
  const std::vector<DVec3> original = mesh.positions;
  std::vector<double> before(mesh.tets.size());
  for (size_t t = 0; t < before.size(); ++t) before[t] = mesh.volume(t);
  std::vector<double> cur = before, next(before.size());
  pb.stiffnessScale.assign(mesh.tets.size(), 1.0);
  double done = 0;  // fraction of the offset applied
  double frac = 1.0 / double(options.steps);
  const double minFrac = std::ldexp(frac, -options.halvings);
  std::vector<DVec3> guess;
  while (done < 1) {
    frac = std::min(frac, 1 - done);
    for (size_t v = 0; v < nv; ++v)
      if (moving[v]) pb.prescribed[v] = frac * options.offset;
    if (options.stiffening > 0)
      for (size_t t = 0; t < cur.size(); ++t) {
        const double worse = std::max({1.0, before[t] / cur[t], options.stiffenBelow / meanRatio(mesh, t)});
        pb.stiffnessScale[t] = std::min(options.maxStiffening, std::pow(worse, options.stiffening));
      }
    pb.initialGuess = guess;
    const FemResult r = solveElastic(mesh, materials, pb, options.fem);
    st.fem.push_back(r.stats);
    const std::vector<DVec3> start = mesh.positions;
    for (size_t v = 0; v < nv; ++v) mesh.positions[v] += r.displacement[v];
    size_t bad = 0;
    for (size_t t = 0; t < mesh.tets.size(); ++t) {
      next[t] = mesh.volume(t);
      if (!(next[t] > options.minStepVolumeRatio * cur[t])) ++bad;
    }
    if (bad) {
      mesh.positions = start;
      if (frac / 2 < minFrac * (1 - 1e-12)) {
        mesh.positions = original;
        throw std::runtime_error("displace: " + std::to_string(bad) + " tetrahedra would invert (or lose more than " +
                                 std::to_string(int(std::lround(100 * (1 - options.minStepVolumeRatio)))) +
                                 "% of their volume in one increment) after " + std::to_string(int(std::lround(100 * done))) +
                                 "% of the offset, even at 1/" + std::to_string(1LL << options.halvings) +
                                 " of a step; use a smaller offset");
      }
      frac /= 2;
      ++st.retries;
      for (DVec3& u : guess) u *= 0.5;
      continue;
    }
    ++st.increments;
    done += frac;
    if (1 - done < 1e-12) done = 1;
    cur.swap(next);
    guess = r.displacement;  // the next increment is alike (the same size, or half): a warm start
    for (size_t v = 0; v < nv; ++v)
      if (pb.fixed[v]) guess[v] = DVec3(0.0);
    // A halved size stays for the rest of the operation: the crushed tetrahedra that needed
    // it are still there (trying the larger size again cost a wasted solve each time).
  }
  st.minVolumeRatio = INFINITY;
  for (size_t t = 0; t < before.size(); ++t) st.minVolumeRatio = std::min(st.minVolumeRatio, mesh.volume(t) / before[t]);
  return st;
}

void blendTint(TetMesh& mesh, uint32_t v, const Vec3& c, double w) {
  if (mesh.tints.empty()) mesh.tints.assign(mesh.positions.size(), Vec4(0.0f));
  w = std::clamp(w, 0.0, 1.0);
  Vec4& t = mesh.tints[v];
  // F = mix(M, T, a) -> mix(F, c, w) = mix(M, T', a'), a' = a + w(1 - a), T' = (a(1 - w)T + w c) / a'.
  const double a = t.w, a2 = a + w * (1 - a);
  if (a2 <= 0) return;
  const Vec3 rgb = Vec3((a * (1 - w) * DVec3(Vec3(t)) + w * DVec3(c)) / a2);
  t = Vec4(rgb, float(a2));
}

void clearTint(TetMesh& mesh, uint32_t v, double w) {
  if (mesh.tints.empty()) return;
  mesh.tints[v].w = float(double(mesh.tints[v].w) * (1 - std::clamp(w, 0.0, 1.0)));
}

size_t subtractRegion(TetMesh& mesh, size_t materialCount, const std::vector<uint16_t>& affects,
                      const std::function<double(const DVec3&)>& field, double eps, const DVec3& up, size_t* split,
                      size_t* fallen) {
  std::vector<uint8_t> affected(materialCount, affects.empty() ? 1 : 0);
  for (uint16_t id : affects) affected[id] = 1;
  std::vector<uint8_t> splittable(mesh.tets.size());
  for (size_t t = 0; t < splittable.size(); ++t) splittable[t] = affected[mesh.materials[t]];
  const size_t cut = cutByField(mesh, splittable, field);
  if (split) *split = cut;
  std::vector<double> value(mesh.positions.size());
  parallelFor(0, value.size(), [&](size_t v) { value[v] = field(mesh.positions[v]); }, 1024);
  std::vector<uint8_t> keep(mesh.tets.size(), 1);
  for (size_t t = 0; t < keep.size(); ++t) {
    if (!affected[mesh.materials[t]]) continue;
    for (uint32_t v : mesh.tets[t])
      if (value[v] < -eps) keep[t] = 0;
  }
  size_t removed = removeTets(mesh, keep);
  removed += mendEdges(mesh, affected);
  std::vector<uint8_t> held(mesh.positions.size(), 0);
  for (size_t t = 0; t < mesh.tets.size(); ++t)
    if (!affected[mesh.materials[t]])
      for (uint32_t v : mesh.tets[t]) held[v] = 1;
  if (std::find(held.begin(), held.end(), 1) == held.end() && !mesh.tets.empty()) held = lowestVertices(mesh, unitUp(up));
  size_t loose = dropLoose(mesh, asFixed(held));
  if (loose) {
    removed += mendEdges(mesh, affected);
    loose += dropLoose(mesh, asFixed(held));
  }
  if (fallen) *fallen = loose;
  return removed;
}

PolishStats polish(TetMesh& mesh, const std::vector<Material>& materials, const PolishOptions& options) {
  if (options.affects.empty()) throw std::invalid_argument("polish: 'affects' names no material");
  checkIds(options.affects, materials.size(), "polish: 'affects'");
  checkIds(options.shines, materials.size(), "polish: 'shines'");
  if (options.shiny >= int(materials.size())) throw std::invalid_argument("polish: 'shiny' names no material");
  if (!finite(options.position)) throw std::invalid_argument("polish: 'position' is not finite");
  if (!(options.size > 0) || !std::isfinite(options.size)) throw std::invalid_argument("polish: 'size' must be positive");
  std::vector<uint8_t> affected(materials.size(), 0);
  for (uint16_t id : options.affects) affected[id] = 1;
  unitUp(options.up);
  PolishStats st;
  const DVec3 c = options.position;
  const double r = options.size;
  auto sphere = [&](const DVec3& p) { return glm::length(p - c) - r; };

  // 1. Subtraction: cut the affected tetrahedra at the sphere, remove the pieces inside.
  st.removed = subtractRegion(mesh, materials.size(), options.affects, sphere, 1e-9 * r, options.up, &st.splitEdges, &st.fallen);

  // 2. Blending toward the shiny material.
  if (options.shiny >= 0) {
    std::vector<uint8_t> shines(materials.size(), 0);
    if (options.shines.empty())
      for (size_t m = 0; m < shines.size(); ++m) shines[m] = !affected[m];
    for (uint16_t id : options.shines) shines[id] = 1;
    std::vector<double> weight(mesh.positions.size(), 0.0);
    for (size_t t = 0; t < mesh.tets.size(); ++t) {
      if (!shines[mesh.materials[t]]) continue;
      const auto& q = mesh.tets[t];
      const DVec3 centroid = (mesh.positions[q[0]] + mesh.positions[q[1]] + mesh.positions[q[2]] + mesh.positions[q[3]]) * 0.25;
      const double w = 1 - glm::length(centroid - c) / r;
      if (w <= 0) continue;
      for (uint32_t v : q) weight[v] = std::max(weight[v], w);
      if (w >= 0.5 && mesh.materials[t] != uint16_t(options.shiny)) {
        mesh.materials[t] = uint16_t(options.shiny);
        ++st.shined;
      }
    }
    const Vec3 shinyColor = materials[size_t(options.shiny)].color;
    for (size_t v = 0; v < weight.size(); ++v)
      if (weight[v] > 0) {
        blendTint(mesh, uint32_t(v), shinyColor, weight[v]);
        ++st.tinted;
      }
  }
  return st;
}

}  // namespace sprig::solids
