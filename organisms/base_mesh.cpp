#include "organisms/base_mesh.h"

#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <tuple>

#include "core/types.h"

namespace sprig::organisms {

namespace {

void addFace(ControlMesh& m, std::initializer_list<uint32_t> vs) {
  m.faceSizes.push_back(uint32_t(vs.size()));
  m.faceVertices.insert(m.faceVertices.end(), vs.begin(), vs.end());
}

/// Rings of `around` vertices (ring-major), quads between consecutive rings, with the
/// winding that makes the normals point away from the y axis when rings climb along +y.
void ringQuads(ControlMesh& m, uint32_t first, int around, int rings) {
  const auto at = [&](int ring, int k) { return first + uint32_t(ring * around + (k % around)); };
  for (int r = 0; r + 1 < rings; ++r)
    for (int k = 0; k < around; ++k) addFace(m, {at(r, k), at(r, k + 1), at(r + 1, k + 1), at(r + 1, k)});
}

Vec3 ringPoint(double radius, double y, int k, int around) {
  const double phi = 2.0 * kPi * k / around;
  return Vec3(float(radius * std::cos(phi)), float(y), float(-radius * std::sin(phi)));
}

}  // namespace

ControlMesh cubeSphere(float radius, int n) {
  if (n < 1) throw std::invalid_argument("a cube-sphere needs at least 1 quad per cube edge");
  ControlMesh m;
  std::map<std::tuple<int, int, int>, uint32_t> index;  // lattice point of the cube -> vertex
  const auto vertex = [&](int i, int j, int k) {
    auto [it, added] = index.try_emplace({i, j, k}, uint32_t(m.positions.size()));
    if (added) {
      Vec3 c(float(2 * i - n), float(2 * j - n), float(2 * k - n));
      m.positions.push_back(radius * glm::normalize(c));
    }
    return it->second;
  };
  // Each face: an axis, its side, and two in-face axes (u, v) with u x v = outward normal.
  struct FaceAxes { int axis, side, u, v; };
  const FaceAxes faces[6] = {{0, 1, 1, 2}, {0, 0, 2, 1}, {1, 1, 2, 0}, {1, 0, 0, 2}, {2, 1, 0, 1}, {2, 0, 1, 0}};
  for (const FaceAxes& f : faces) {
    const auto lattice = [&](int a, int b) {
      int c[3];
      c[f.axis] = f.side * n;
      c[f.u] = a;
      c[f.v] = b;
      return vertex(c[0], c[1], c[2]);
    };
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) addFace(m, {lattice(a, b), lattice(a + 1, b), lattice(a + 1, b + 1), lattice(a, b + 1)});
  }
  return m;
}

ControlMesh torus(float majorRadius, float minorRadius, int around, int across) {
  if (around < 3 || across < 3) throw std::invalid_argument("a torus needs at least 3 x 3 quads");
  ControlMesh m;
  for (int i = 0; i < around; ++i) {
    const double phi = 2.0 * kPi * i / around;
    for (int j = 0; j < across; ++j) {
      const double th = 2.0 * kPi * j / across;
      const double r = majorRadius + minorRadius * std::cos(th);
      m.positions.emplace_back(float(r * std::cos(phi)), float(minorRadius * std::sin(th)), float(-r * std::sin(phi)));
    }
  }
  const auto at = [&](int i, int j) { return uint32_t((i % around) * across + (j % across)); };
  for (int i = 0; i < around; ++i)
    for (int j = 0; j < across; ++j) addFace(m, {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
  return m;
}

ControlMesh cylinder(float radius, float height, int around, int rings, bool caps) {
  if (caps) return revolution([radius](double) { return double(radius); }, 0.0, double(height), around, rings);
  if (around < 3 || rings < 1) throw std::invalid_argument("a cylinder needs at least 3 x 1 quads");
  ControlMesh m;
  for (int r = 0; r <= rings; ++r)
    for (int k = 0; k < around; ++k) m.positions.push_back(ringPoint(radius, double(height) * r / rings, k, around));
  ringQuads(m, 0, around, rings + 1);
  return m;
}

ControlMesh plane(float size, int n) {
  if (n < 1) throw std::invalid_argument("a plane needs at least 1 quad per side");
  ControlMesh m;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j)
      m.positions.emplace_back(size * (float(j) / float(n) - 0.5f), 0.0f, size * (float(i) / float(n) - 0.5f));
  const auto at = [&](int i, int j) { return uint32_t(i * (n + 1) + j); };
  // x along j, z along i: (x, z) -> normal +y needs the order (i,j), (i+1,j), (i+1,j+1), (i,j+1).
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) addFace(m, {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
  return m;
}

ControlMesh revolution(const std::function<double(double)>& radius, double t0, double t1, int around, int rings) {
  if (around < 3 || rings < 1) throw std::invalid_argument("a surface of revolution needs at least 3 x 1 quads");
  if (!(t1 > t0)) throw std::invalid_argument("a surface of revolution needs t1 > t0");
  std::vector<double> r(size_t(rings) + 1);
  for (int i = 0; i <= rings; ++i) {
    const double t = t0 + (t1 - t0) * i / rings;
    r[size_t(i)] = radius(t);
    if (!std::isfinite(r[size_t(i)]) || r[size_t(i)] < 0)
      throw std::invalid_argument("the profile radius at t = " + std::to_string(t) + " is " + std::to_string(r[size_t(i)]) +
                                  " (it must be finite and >= 0)");
  }
  // Interior rings must have a radius: a ring of radius 0 would pinch the surface.
  for (int i = 1; i < rings; ++i)
    if (r[size_t(i)] <= 0)
      throw std::invalid_argument("the profile radius is 0 inside the range (at ring " + std::to_string(i) +
                                  "): only the ends may close at a pole");
  ControlMesh m;
  const int first = r.front() > 0 ? 0 : 1, last = r.back() > 0 ? rings : rings - 1;
  for (int i = first; i <= last; ++i)
    for (int k = 0; k < around; ++k) m.positions.push_back(ringPoint(r[size_t(i)], t0 + (t1 - t0) * i / rings, k, around));
  const int ringCount = last - first + 1;
  ringQuads(m, 0, around, ringCount);
  const auto ring = [&](int i, int k) { return uint32_t((i - first) * around + (k % around)); };
  // Each end: a polygon cap, or triangles around a pole vertex where the radius is 0.
  // Ascending k runs counter-clockwise seen from +y: the top keeps it, the bottom reverses it.
  if (first == 1) {
    const uint32_t pole = uint32_t(m.positions.size());
    m.positions.emplace_back(0.0f, float(t0), 0.0f);
    for (int k = 0; k < around; ++k) addFace(m, {pole, ring(1, k + 1), ring(1, k)});
  } else {
    m.faceSizes.push_back(uint32_t(around));
    for (int k = around - 1; k >= 0; --k) m.faceVertices.push_back(ring(0, k));
  }
  if (last == rings - 1) {
    const uint32_t pole = uint32_t(m.positions.size());
    m.positions.emplace_back(0.0f, float(t1), 0.0f);
    for (int k = 0; k < around; ++k) addFace(m, {pole, ring(last, k), ring(last, k + 1)});
  } else {
    m.faceSizes.push_back(uint32_t(around));
    for (int k = 0; k < around; ++k) m.faceVertices.push_back(ring(last, k));
  }
  return m;
}

}  // namespace sprig::organisms
