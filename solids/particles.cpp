#include "solids/particles.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/parallel.h"
#include "core/progress.h"
#include "core/rng.h"
#include "solids/operators.h"
#include "textures/noise.h"

namespace sprig::solids {

namespace {

constexpr double kPi = 3.14159265358979323846;

bool finite(const DVec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// Closest point of triangle abc to p (Ericson, Real-Time Collision Detection, §5.1.5).
DVec3 closestOnTriangle(const DVec3& p, const DVec3& a, const DVec3& b, const DVec3& c) {
  const DVec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const DVec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const DVec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

/// A uniform grid of items (triangles or vertices) by cell, compressed rows.
struct Buckets {
  DVec3 lo{0.0};
  double cell = 1;
  std::array<int64_t, 3> n{1, 1, 1};
  std::vector<uint32_t> start, items;

  std::array<int64_t, 3> cellOf(const DVec3& p) const {
    std::array<int64_t, 3> c;
    for (int k = 0; k < 3; ++k) c[size_t(k)] = std::clamp(int64_t(std::floor((p[k] - lo[k]) / cell)), int64_t(0), n[size_t(k)] - 1);
    return c;
  }
  size_t index(int64_t i, int64_t j, int64_t k) const { return size_t(i + n[0] * (j + n[1] * k)); }

  /// Builds from per-item boxes [blo, bhi] (every cell they overlap holds the item).
  void build(const std::vector<std::pair<DVec3, DVec3>>& boxes, const DVec3& boxLo, const DVec3& boxHi, double cellSize) {
    lo = boxLo;
    cell = cellSize;
    // Counted in double before any cast: a huge or non-finite quotient is refused, not wrapped.
    constexpr double kMaxCells = double(size_t(1) << 28);
    double cells = 1;
    for (int k = 0; k < 3; ++k) {
      const double q = std::ceil((boxHi[k] - boxLo[k]) / cell) + 1;
      if (!(q <= kMaxCells)) throw std::invalid_argument("particle tools: the surface's lookup grid would need more than 2^28 cells");
      const double nk = std::max(1.0, q);
      cells *= nk;
      if (!(cells <= kMaxCells)) throw std::invalid_argument("particle tools: the surface's lookup grid would need more than 2^28 cells");
      n[size_t(k)] = int64_t(nk);
    }
    const size_t total = size_t(n[0] * n[1] * n[2]);
    std::vector<uint32_t> count(total + 1, 0);
    auto each = [&](size_t i, auto&& f) {
      const auto a = cellOf(boxes[i].first), b = cellOf(boxes[i].second);
      for (int64_t z = a[2]; z <= b[2]; ++z)
        for (int64_t y = a[1]; y <= b[1]; ++y)
          for (int64_t x = a[0]; x <= b[0]; ++x) f(index(x, y, z));
    };
    for (size_t i = 0; i < boxes.size(); ++i) each(i, [&](size_t c) { ++count[c + 1]; });
    for (size_t c = 0; c < total; ++c) count[c + 1] += count[c];
    start = count;
    items.resize(count[total]);
    for (size_t i = 0; i < boxes.size(); ++i) each(i, [&](size_t c) { items[count[c]++] = uint32_t(i); });
  }
};

/// The visible surface with lookups: nearest point, vertical rays, vertices near a point.
struct Surface {
  const TetMesh& mesh;
  std::vector<InterfaceTriangle> tris;
  std::vector<DVec3> normal;
  DVec3 up, e1, e2;  ///< up and two horizontal axes
  DVec3 lo{INFINITY}, hi{-INFINITY};
  double meanEdge = 0;
  Buckets triGrid;   ///< triangles by 3-D cell
  Buckets columns;   ///< triangles by horizontal cell (one layer along up), in (e1, e2, up) coordinates
  DVec3 colLo{0.0};
  std::vector<uint32_t> eligible;  ///< vertices of visible faces of affected materials
  Buckets vertGrid;

  DVec3 frame(const DVec3& p) const { return DVec3(glm::dot(p, e1), glm::dot(p, e2), glm::dot(p, up)); }

  Surface(const TetMesh& m, const DVec3& upDir, const std::vector<uint8_t>& affected, double stepHint, double radius)
      : mesh(m), up(upDir) {
    tris = visibleInterface(m);
    const DVec3 helper = std::abs(up.x) < 0.9 ? DVec3(1, 0, 0) : DVec3(0, 1, 0);
    e1 = glm::normalize(glm::cross(helper, up));
    e2 = glm::cross(up, e1);
    normal.resize(tris.size());
    std::vector<std::pair<DVec3, DVec3>> boxes(tris.size()), cols(tris.size());
    double edges = 0;
    DVec3 flo(INFINITY), fhi(-INFINITY);
    std::vector<uint8_t> isEligible(m.positions.size(), 0);
    for (size_t t = 0; t < tris.size(); ++t) {
      const DVec3 a = m.positions[tris[t].v[0]], b = m.positions[tris[t].v[1]], c = m.positions[tris[t].v[2]];
      const DVec3 n = glm::cross(b - a, c - a);
      normal[t] = glm::length(n) > 0 ? glm::normalize(n) : up;
      boxes[t] = {glm::min(a, glm::min(b, c)), glm::max(a, glm::max(b, c))};
      const DVec3 fa = frame(a), fb = frame(b), fc = frame(c);
      cols[t] = {glm::min(fa, glm::min(fb, fc)), glm::max(fa, glm::max(fb, fc))};
      lo = glm::min(lo, boxes[t].first);
      hi = glm::max(hi, boxes[t].second);
      flo = glm::min(flo, cols[t].first);
      fhi = glm::max(fhi, cols[t].second);
      edges += glm::length(b - a) + glm::length(c - b) + glm::length(a - c);
      if (affected[tris[t].material])
        for (uint32_t v : tris[t].v) isEligible[v] = 1;
    }
    if (tris.empty()) return;
    meanEdge = edges / (3.0 * double(tris.size()));
    const double step = stepHint;
    triGrid.build(boxes, lo, hi, std::max(step, meanEdge));
    for (auto& c : cols) c.first.z = c.second.z = 0;  // one layer
    colLo = flo;
    columns.build(cols, DVec3(flo.x, flo.y, 0), DVec3(fhi.x, fhi.y, 0), std::max(meanEdge, 1e-9));
    std::vector<std::pair<DVec3, DVec3>> vboxes;
    for (size_t v = 0; v < isEligible.size(); ++v)
      if (isEligible[v]) {
        eligible.push_back(uint32_t(v));
        vboxes.push_back({m.positions[v], m.positions[v]});
      }
    vertGrid.build(vboxes, lo, hi, std::max(radius, 1e-9));
  }

  /// The nearest point of the visible faces to p within one cell of the triangle grid: (triangle, point); -1 if none.
  std::pair<int64_t, DVec3> nearest(const DVec3& p) const {
    const auto c = triGrid.cellOf(p);
    double best = INFINITY;
    int64_t bt = -1;
    DVec3 bp(0.0);
    for (int64_t z = std::max<int64_t>(0, c[2] - 1); z <= std::min(triGrid.n[2] - 1, c[2] + 1); ++z)
      for (int64_t y = std::max<int64_t>(0, c[1] - 1); y <= std::min(triGrid.n[1] - 1, c[1] + 1); ++y)
        for (int64_t x = std::max<int64_t>(0, c[0] - 1); x <= std::min(triGrid.n[0] - 1, c[0] + 1); ++x) {
          const size_t cell = triGrid.index(x, y, z);
          for (uint32_t i = triGrid.start[cell]; i < triGrid.start[cell + 1]; ++i) {
            const uint32_t t = triGrid.items[i];
            const auto& v = tris[t].v;
            const DVec3 q = closestOnTriangle(p, mesh.positions[v[0]], mesh.positions[v[1]], mesh.positions[v[2]]);
            const double d = glm::dot(q - p, q - p);
            if (d < best || (d == best && int64_t(t) < bt)) best = d, bt = t, bp = q;
          }
        }
    return {bt, bp};
  }

  /// The highest point of an upward-or-downward face straight below p (along −up) lower than
  /// p by more than a millionth of the model: (triangle, point); -1 if none.
  std::pair<int64_t, DVec3> below(const DVec3& p) const {
    const DVec3 f = frame(p);
    const double limit = f.z - 1e-6 * (glm::length(hi - lo) + 1e-30);
    const auto c = columns.cellOf(DVec3(f.x, f.y, 0));
    const size_t cell = columns.index(c[0], c[1], 0);
    double bestH = -INFINITY;
    int64_t bt = -1;
    for (uint32_t i = columns.start[cell]; i < columns.start[cell + 1]; ++i) {
      const uint32_t t = columns.items[i];
      const auto& v = tris[t].v;
      const DVec3 a = frame(mesh.positions[v[0]]), b = frame(mesh.positions[v[1]]), cc = frame(mesh.positions[v[2]]);
      const double det = (b.x - a.x) * (cc.y - a.y) - (cc.x - a.x) * (b.y - a.y);
      if (std::abs(det) < 1e-300) continue;
      const double s = ((f.x - a.x) * (cc.y - a.y) - (cc.x - a.x) * (f.y - a.y)) / det;
      const double r = ((b.x - a.x) * (f.y - a.y) - (f.x - a.x) * (b.y - a.y)) / det;
      if (s < 0 || r < 0 || s + r > 1) continue;
      const double h = a.z + s * (b.z - a.z) + r * (cc.z - a.z);
      if (h < limit && (h > bestH || (h == bestH && int64_t(t) < bt))) bestH = h, bt = t;
    }
    if (bt < 0) return {-1, DVec3(0.0)};
    return {bt, p - up * (f.z - bestH)};
  }
};

struct Stop {
  DVec3 p;
  uint32_t tri;
};

struct Path {
  std::vector<Stop> stops;
  uint32_t drips = 0;
  bool lost = false;
};

/// A smooth seeded vector field of three Perlin noises (the meander of a wash), about
/// [-1, 1] per component.
struct VectorNoise {
  textures::PerlinNoise x, y, z;
  explicit VectorNoise(uint64_t seed)
      : x(deriveSeed(seed, {0x4d45414e44ull, 0})), y(deriveSeed(seed, {0x4d45414e44ull, 1})), z(deriveSeed(seed, {0x4d45414e44ull, 2})) {}
  DVec3 operator()(const DVec3& p) const { return DVec3(x(p), y(p), z(p)); }
};

Path walk(const Surface& s, const ParticleOptions& o, double step, size_t index, const VectorNoise& noise) {
  Path path;
  Rng rng(deriveSeed(o.seed, {0x5041525449434cull, uint64_t(index)}));
  const DVec3 flo = s.frame(s.lo), fhi = s.frame(s.hi);
  // The footprint of the box in the horizontal frame (the frame of a box's corners).
  DVec3 a(INFINITY), b(-INFINITY);
  for (int c = 0; c < 8; ++c) {
    const DVec3 corner((c & 1) ? s.hi.x : s.lo.x, (c & 2) ? s.hi.y : s.lo.y, (c & 4) ? s.hi.z : s.lo.z);
    a = glm::min(a, s.frame(corner));
    b = glm::max(b, s.frame(corner));
  }
  (void)flo;
  (void)fhi;
  const double u = rng.uniform(a.x, b.x), w = rng.uniform(a.y, b.y);
  const DVec3 top = s.e1 * u + s.e2 * w + s.up * (b.z + 1.0);
  auto [t, p] = s.below(top);
  if (t < 0) {
    path.lost = true;
    return path;
  }
  path.stops.push_back({p, uint32_t(t)});
  const DVec3 g = -s.up;
  const double cosFall = std::cos(o.fallingAngleDeg * kPi / 180);
  const double level = std::sin(kPi / 180);
  const size_t steps = size_t(std::floor(o.life * o.speed / step + 1e-9));
  const double attract = o.tool == ParticleTool::Wash && !s.mesh.tints.empty() ? o.attraction : 0.0;
  const double meander = o.tool == ParticleTool::Wash ? o.meander : 0.0;
  for (size_t k = 0; k < steps; ++k) {
    const DVec3 n = s.normal[size_t(t)];
    if (glm::dot(n, g) > cosFall) {
      auto [t2, p2] = s.below(p);
      if (t2 < 0) {
        path.lost = true;
        break;
      }
      ++path.drips;
      t = t2, p = p2;
      path.stops.push_back({p, uint32_t(t)});
      continue;
    }
    DVec3 dir = g - glm::dot(g, n) * n;
    const double len = glm::length(dir);
    if (len < level) break;  // level: at rest
    dir /= len;
    DVec3 side(0.0);
    if (meander > 0) {
      // Meanders: the smooth noise field's part across the fall line, the same for every drop here.
      const DVec3 f = noise(p / o.meanderScale);
      side += meander * (f - glm::dot(f, dir) * dir - glm::dot(f, n) * n);
    }
    if (attract > 0) {
      // Rivulets: steer sideways (never uphill) toward cleaner surface, down the gradient of
      // the tint amount over the face. Tints change only between batches, so this reads a
      // fixed state while paths run in parallel.
      const auto& v = s.tris[size_t(t)].v;
      const DVec3 q0 = s.mesh.positions[v[0]], q1 = s.mesh.positions[v[1]], q2 = s.mesh.positions[v[2]];
      const double twiceArea = glm::length(glm::cross(q1 - q0, q2 - q0));
      if (twiceArea > 0) {
        const double a0 = s.mesh.tints[v[0]].a, a1 = s.mesh.tints[v[1]].a, a2 = s.mesh.tints[v[2]].a;
        const DVec3 grad = (a0 * glm::cross(n, q2 - q1) + a1 * glm::cross(n, q0 - q2) + a2 * glm::cross(n, q1 - q0)) / twiceArea;
        side += attract * o.radius * (-grad - glm::dot(-grad, dir) * dir - glm::dot(-grad, n) * n);
      }
    }
    if (side != DVec3(0.0)) {
      const double sl = glm::length(side);
      if (sl > 1) side /= sl;  // at most 45 degrees off the fall line
      dir = glm::normalize(dir + side);
    }
    const auto [t2, p2] = s.nearest(p + dir * step);
    if (t2 < 0) {
      path.lost = true;
      break;
    }
    if (glm::length(p2 - p) < 0.1 * step) break;  // a crease it cannot leave
    t = t2, p = p2;
    path.stops.push_back({p, uint32_t(t)});
  }
  return path;
}

std::vector<uint8_t> affectedFlags(const std::vector<uint16_t>& affects, size_t count, const char* tool) {
  for (uint16_t id : affects)
    if (id >= count)
      throw std::invalid_argument(std::string(tool) + ": 'affects' names material id " + std::to_string(id) + ", but there are " +
                                  std::to_string(count) + " materials");
  std::vector<uint8_t> out(count, affects.empty() ? 1 : 0);
  for (uint16_t id : affects) out[id] = 1;
  return out;
}

const char* toolName(ParticleTool t) { return t == ParticleTool::Wash ? "wash" : t == ParticleTool::Erode ? "erode" : "lichen"; }

}  // namespace

ParticleOptions particleDefaults(ParticleTool tool) {
  ParticleOptions o;
  o.tool = tool;
  o.strength = 0.01;
  if (tool == ParticleTool::Erode) {
    o.particles = 2000;
    o.radius = 0.03;
  } else if (tool == ParticleTool::Lichen) {
    o.particles = 40000;
    o.speed = 0.05;
    o.radius = 0.05;
    o.strength = 0.1;
    o.color = Vec3(0.32f, 0.36f, 0.12f);
  }
  return o;
}

size_t dirt(TetMesh& mesh, const std::vector<Material>& materials, const DirtOptions& options) {
  const std::vector<uint8_t> affected = affectedFlags(options.affects, materials.size(), "dirt");
  for (int c = 0; c < 3; ++c)
    if (!std::isfinite(options.color[c]) || options.color[c] < 0) throw std::invalid_argument("dirt: 'color' must be finite and not negative");
  if (!(options.amount >= 0 && options.amount <= 1)) throw std::invalid_argument("dirt: 'amount' must lie in [0, 1]");
  std::vector<uint8_t> on(mesh.positions.size(), 0);
  for (const InterfaceTriangle& t : visibleInterface(mesh))
    if (affected[t.material])
      for (uint32_t v : t.v) on[v] = 1;
  size_t count = 0;
  for (size_t v = 0; v < on.size(); ++v)
    if (on[v]) {
      blendTint(mesh, uint32_t(v), options.color, options.amount);
      ++count;
    }
  return count;
}

ParticleStats runParticles(TetMesh& mesh, const std::vector<Material>& materials, const ParticleOptions& o) {
  const char* name = toolName(o.tool);
  const std::string tool = name;
  const std::vector<uint8_t> affected = affectedFlags(o.affects, materials.size(), name);
  if (o.particles < 0) throw std::invalid_argument(tool + ": 'particles' must not be negative");
  auto positive = [&](double v, const char* key) {
    if (!(v > 0) || !std::isfinite(v)) throw std::invalid_argument(tool + ": '" + key + "' must be positive and finite");
  };
  positive(o.life, "life");
  positive(o.speed, "speed");
  positive(o.radius, "radius");
  if (!(o.step >= 0) || !std::isfinite(o.step)) throw std::invalid_argument(tool + ": 'step' must not be negative");
  if (!(o.attraction >= 0) || !std::isfinite(o.attraction)) throw std::invalid_argument(tool + ": 'attraction' must be finite and not negative");
  if (!(o.meander >= 0) || !std::isfinite(o.meander)) throw std::invalid_argument(tool + ": 'meander' must be finite and not negative");
  positive(o.meanderScale, "meander_scale");
  if (!(o.strength >= 0 && o.strength <= 1)) throw std::invalid_argument(tool + ": 'strength' must lie in [0, 1]");
  if (!(o.fallingAngleDeg >= 0 && o.fallingAngleDeg <= 180)) throw std::invalid_argument(tool + ": 'falling_angle' must lie in [0, 180]");
  if (!(o.topAngleDeg >= 0 && o.topAngleDeg <= 90)) throw std::invalid_argument(tool + ": 'top_angle' must lie in [0, 90]");
  if (!finite(o.up) || glm::length(o.up) == 0) throw std::invalid_argument(tool + ": 'up' must be a finite, non-zero vector");
  for (int c = 0; c < 3; ++c)
    if (!std::isfinite(o.color[c]) || o.color[c] < 0) throw std::invalid_argument(tool + ": 'color' must be finite and not negative");

  ParticleStats st;
  st.passes.assign(mesh.positions.size(), 0);
  const DVec3 up = glm::normalize(o.up);
  const Surface s(mesh, up, affected, o.step > 0 ? o.step : 0.5 * o.radius, o.radius);
  if (s.tris.empty() || o.particles == 0) return st;
  const double step = o.step > 0 ? o.step : 0.5 * o.radius;
  if (o.life * o.speed / step > 1e6) throw std::invalid_argument(tool + ": life * speed / step is more than a million steps per particle");
  const double cosTop = std::cos(o.topAngleDeg * kPi / 180);
  std::vector<DVec3> craters;

  // Vertices within radius of p, with weight 1 - d/radius.
  auto act = [&](const Stop& stop) {
    const double nu = glm::dot(s.normal[stop.tri], up);
    if (o.tool == ParticleTool::Lichen && nu < cosTop) return;
    const auto c = s.vertGrid.cellOf(stop.p);
    for (int64_t z = std::max<int64_t>(0, c[2] - 1); z <= std::min(s.vertGrid.n[2] - 1, c[2] + 1); ++z)
      for (int64_t y = std::max<int64_t>(0, c[1] - 1); y <= std::min(s.vertGrid.n[1] - 1, c[1] + 1); ++y)
        for (int64_t x = std::max<int64_t>(0, c[0] - 1); x <= std::min(s.vertGrid.n[0] - 1, c[0] + 1); ++x) {
          const size_t cell = s.vertGrid.index(x, y, z);
          for (uint32_t i = s.vertGrid.start[cell]; i < s.vertGrid.start[cell + 1]; ++i) {
            const uint32_t v = s.eligible[s.vertGrid.items[i]];
            const double d = glm::length(mesh.positions[v] - stop.p);
            if (d >= o.radius) continue;
            const double w = o.strength * (1 - d / o.radius);
            if (o.tool == ParticleTool::Wash) clearTint(mesh, v, w);
            else blendTint(mesh, v, o.color, w * nu);
            ++st.passes[v];
            ++st.vertexHits;
          }
        }
  };

  const VectorNoise noise(o.seed);
  Progress progress(tool + " particles", uint64_t(o.particles));
  constexpr size_t kBatch = 4096;
  std::vector<Path> paths;
  for (size_t first = 0; first < size_t(o.particles); first += kBatch) {
    const size_t count = std::min(kBatch, size_t(o.particles) - first);
    paths.assign(count, Path{});
    parallelFor(0, count, [&](size_t i) { paths[i] = walk(s, o, step, first + i, noise); }, 16);
    for (const Path& path : paths) {
      if (path.stops.empty()) {
        ++st.lost;
        continue;
      }
      ++st.landed;
      st.steps += path.stops.size() - 1;
      st.drips += path.drips;
      if (path.lost) ++st.lost;
      if (o.tool == ParticleTool::Erode) {
        if (!path.lost) craters.push_back(path.stops.back().p);
        continue;
      }
      for (const Stop& stop : path.stops) act(stop);
    }
    progress.advance(count);
  }
  progress.finish();

  if (o.tool == ParticleTool::Erode && !craters.empty()) {
    // The union of the spheres: the smallest |x - c| - radius over the centres near x.
    std::vector<std::pair<DVec3, DVec3>> boxes;
    for (const DVec3& c : craters) boxes.push_back({c, c});
    Buckets grid;
    grid.build(boxes, s.lo - DVec3(o.radius), s.hi + DVec3(o.radius), o.radius);
    auto field = [&](const DVec3& p) {
      const auto c = grid.cellOf(p);
      double best = o.radius;  // outside every sphere near p: positive
      for (int64_t z = std::max<int64_t>(0, c[2] - 1); z <= std::min(grid.n[2] - 1, c[2] + 1); ++z)
        for (int64_t y = std::max<int64_t>(0, c[1] - 1); y <= std::min(grid.n[1] - 1, c[1] + 1); ++y)
          for (int64_t x = std::max<int64_t>(0, c[0] - 1); x <= std::min(grid.n[0] - 1, c[0] + 1); ++x) {
            const size_t cell = grid.index(x, y, z);
            for (uint32_t i = grid.start[cell]; i < grid.start[cell + 1]; ++i)
              best = std::min(best, glm::length(p - craters[grid.items[i]]) - o.radius);
          }
      return best;
    };
    size_t fallen = 0;
    st.removed = subtractRegion(mesh, materials.size(), o.affects, field, 1e-9 * o.radius, up, nullptr, &fallen);
    st.removed += fallen;
  }
  return st;
}

}  // namespace sprig::solids
