#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <random>

#include "core/parallel.h"
#include "solids/fem.h"
#include "tests/solids/tet_block.h"

using namespace sprig;
using namespace sprig::solids;
using test::tetBlock;

namespace {

Material elastic(double youngs, double poisson, double density = 1000) {
  Material m;
  m.name = "test";
  m.youngsModulus = youngs;
  m.poissonRatio = poisson;
  m.density = density;
  return m;
}

bool onBox(const DVec3& p, const DVec3& lo, const DVec3& hi) {
  for (int a = 0; a < 3; ++a)
    if (p[a] == lo[a] || p[a] == hi[a]) return true;
  return false;
}

double minVolume(const TetMesh& m) {
  double v = INFINITY;
  for (size_t t = 0; t < m.tets.size(); ++t) v = std::min(v, m.volume(t));
  return v;
}

template <class T>
bool sameBytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

}  // namespace

TEST_CASE("solveElastic: the patch test", "[solids][fem]") {
  // A block of 6 × 5 × 4 cells whose interior vertices are moved randomly by up to 0.2 of
  // a cell (an irregular mesh); the linear field u = A·x + c is prescribed on every boundary
  // vertex. Constant-strain tetrahedra represent it exactly, so the solution is u inside too
  // and every tetrahedron's strain is sym(A) (Zienkiewicz and Taylor, vol. 1, §10.3).
  const DVec3 lo(0.0), hi(0.6, 0.5, 0.4);
  TetMesh m = tetBlock({6, 5, 4}, lo, hi - lo);
  const unsigned seed = 15;
  INFO("seed " << seed);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.02, 0.02);
  for (DVec3& p : m.positions)
    if (!onBox(p, lo, hi)) p += DVec3(jitter(rng), jitter(rng), jitter(rng));
  REQUIRE(minVolume(m) > 0);

  const DMat3 A = 1e-3 * glm::transpose(DMat3(1.0, 0.2, -0.3, 0.4, -0.5, 0.1, 0.25, 0.3, 0.7));  // A[j][i] = ∂u_i/∂x_j
  const DVec3 c(1e-3, -2e-3, 5e-4);
  auto exact = [&](const DVec3& x) { return A * x + c; };
  FemProblem pb;
  pb.fixed.assign(m.positions.size(), 0);
  pb.prescribed.assign(m.positions.size(), DVec3(0.0));
  size_t interior = 0;
  for (size_t v = 0; v < m.positions.size(); ++v) {
    if (onBox(m.positions[v], lo, hi)) {
      pb.fixed[v] = 7;
      pb.prescribed[v] = exact(m.positions[v]);
    } else {
      ++interior;
    }
  }
  REQUIRE(interior == 5 * 4 * 3);
  FemOptions opt;
  opt.tolerance = 1e-14;
  const Material mat = elastic(2e9, 0.3);
  const FemResult r = solveElastic(m, {mat}, pb, opt);

  const double eps[6] = {A[0][0], A[1][1], A[2][2], 0.5 * (A[2][1] + A[1][2]), 0.5 * (A[2][0] + A[0][2]),
                         0.5 * (A[1][0] + A[0][1])};
  const double scale = 1e-3;  // the size of sym(A)'s entries
  double worstStrain = 0, worstU = 0;
  for (const TetStress& s : r.tets)
    for (int k = 0; k < 6; ++k) worstStrain = std::max(worstStrain, std::abs(s.strain[size_t(k)] - eps[k]) / scale);
  for (size_t v = 0; v < m.positions.size(); ++v)
    worstU = std::max(worstU, glm::length(r.displacement[v] - exact(m.positions[v])) / (scale * 0.6));
  INFO("largest strain error relative to |sym A| " << worstStrain << ", displacement error " << worstU << ", "
                                                    << r.stats.iterations << " CG iterations");
  CHECK(worstStrain < 1e-9);
  CHECK(worstU < 1e-9);
  // Stress is D·ε, the same in every tetrahedron: σ_xx = λ·tr ε + 2μ·ε_xx.
  const double lambda = 2e9 * 0.3 / (1.3 * 0.4), mu = 2e9 / 2.6;
  const double tr = eps[0] + eps[1] + eps[2];
  for (const TetStress& s : r.tets) {
    CHECK(s.stress[0] == Approx(lambda * tr + 2 * mu * eps[0]).epsilon(1e-9));
    CHECK(s.stress[5] == Approx(2 * mu * eps[5]).epsilon(1e-9));
  }
}

TEST_CASE("solveElastic: a cantilever deflects as beam theory predicts", "[solids][fem]") {
  // A steel-like beam L = 1 m, square section h = b = 0.1 m, clamped at x = 0 (every vertex
  // fixed), a total load P = 1 kN down (−y) spread over the tip face by tributary area.
  // Timoshenko: δ = P·L³/(3·E·I) + P·L/(κ·G·A), I = b·h³/12, κ = 5/6. Resolution: NH cells
  // through the height, 10·NH along the length (5 tetrahedra per cell).
  const int NH = 10;
  const double L = 1, h = 0.1, E = 2e11, nu = 0.3, P = 1000;
  const TetMesh m = tetBlock({10 * NH, NH, NH}, DVec3(0.0), DVec3(L, h, h));
  FemProblem pb;
  pb.fixed.assign(m.positions.size(), 0);
  pb.forces.assign(m.positions.size(), DVec3(0.0));
  std::vector<size_t> tip;
  double weights = 0;
  for (size_t v = 0; v < m.positions.size(); ++v) {
    const DVec3& p = m.positions[v];
    if (p.x == 0) pb.fixed[v] = 7;
    if (p.x == L) {
      const double w = ((p.y == 0 || p.y == h) ? 0.5 : 1.0) * ((p.z == 0 || p.z == h) ? 0.5 : 1.0);
      pb.forces[v].y = w;
      weights += w;
      tip.push_back(v);
    }
  }
  for (size_t v : tip) pb.forces[v].y *= -P / weights;
  const FemResult r = solveElastic(m, {elastic(E, nu)}, pb);
  double tipY = 0;
  for (size_t v : tip) tipY += r.displacement[v].y;
  tipY /= double(tip.size());
  const double I = h * h * h * h / 12, G = E / (2 * (1 + nu));
  const double bending = P * L * L * L / (3 * E * I), shear = P * L / (5.0 / 6.0 * G * h * h);
  const double theory = bending + shear;
  INFO(m.tets.size() << " tetrahedra, " << r.stats.freeDofs << " free dofs: tip deflection " << -tipY << " m, Timoshenko "
                     << theory << " m (Euler-Bernoulli " << bending << "), ratio " << -tipY / theory << "; "
                     << r.stats.iterations << " CG iterations, assembly " << r.stats.assemblySeconds << " s, solve "
                     << r.stats.solveSeconds << " s");
  CHECK(-tipY / theory > 0.95);
  CHECK(-tipY / theory < 1.05);
  CHECK(r.stats.converged);
}

TEST_CASE("solveElastic: a column under its own weight", "[solids][fem]") {
  // A column 1 m tall (y), 0.2 m square, fixed at its base, ν = 0: each fibre is a bar under
  // its own weight, u_y(y) = −ρ·g/E·(H·y − y²/2); the top sinks by ρ·g·H²/(2E).
  const double H = 1, E = 1e7, rho = 2000, g = 9.81;
  const TetMesh m = tetBlock({2, 10, 2}, DVec3(0.0), DVec3(0.2, H, 0.2));
  FemProblem pb;
  pb.fixed.assign(m.positions.size(), 0);
  for (size_t v = 0; v < m.positions.size(); ++v)
    if (m.positions[v].y == 0) pb.fixed[v] = 7;
  pb.acceleration = DVec3(0, -g, 0);
  const FemResult r = solveElastic(m, {elastic(E, 0.0, rho)}, pb);
  const double top = rho * g * H * H / (2 * E);
  for (size_t v = 0; v < m.positions.size(); ++v) {
    const double y = m.positions[v].y;
    const double want = -rho * g / E * (H * y - y * y / 2);
    INFO("vertex " << v << " at y = " << y << ": u_y " << r.displacement[v].y << ", bar theory " << want);
    CHECK(std::abs(r.displacement[v].y - want) < 0.01 * top);
    CHECK(std::abs(r.displacement[v].x) < 0.01 * top);  // the 5-tetrahedron cells are not symmetric
  }
}

TEST_CASE("solveElastic: fixed components do not move", "[solids][fem]") {
  // A cube under gravity and a point force: the base is clamped at zero, one top corner is
  // held at a prescribed displacement, and one side only in x (a roller).
  TetMesh m = tetBlock({4, 4, 4}, DVec3(0.0), DVec3(1.0));
  FemProblem pb;
  const size_t n = m.positions.size();
  pb.fixed.assign(n, 0);
  pb.prescribed.assign(n, DVec3(0.0));
  pb.forces.assign(n, DVec3(0.0));
  pb.acceleration = DVec3(0, -9.81, 0);
  size_t corner = 0;
  for (size_t v = 0; v < n; ++v) {
    const DVec3& p = m.positions[v];
    if (p.y == 0) pb.fixed[v] = 7;
    else if (p.x == 0) pb.fixed[v] = 1;
    if (p == DVec3(1.0)) corner = v;
    pb.forces[v] = DVec3(10.0 * p.x, 5.0, -3.0 * p.z);
  }
  pb.fixed[corner] = 7;
  pb.prescribed[corner] = DVec3(1e-4, -2e-4, 3e-5);
  const FemResult r = solveElastic(m, {elastic(1e6, 0.3)}, pb);
  size_t moving = 0;
  for (size_t v = 0; v < n; ++v) {
    INFO("vertex " << v);
    for (int i = 0; i < 3; ++i)
      if (pb.fixed[v] & (1 << i)) CHECK(r.displacement[v][i] == pb.prescribed[v][i]);
      else if (r.displacement[v][i] != 0) ++moving;
  }
  // Every free component moved: 125 vertices, 25 clamped, 20 more held in x, the corner.
  CHECK(moving == size_t(125 * 3 - 25 * 3 - 20 - 3));
}

TEST_CASE("solveElastic: the same bytes at 1 and 2 threads", "[solids][fem]") {
  // Two materials in alternating slabs, gravity and a clamped base: a few thousand vertices,
  // so the parallel loops split.
  TetMesh m = tetBlock({12, 12, 12}, DVec3(0.0), DVec3(1.0));
  for (size_t t = 0; t < m.tets.size(); ++t) m.materials[t] = uint16_t((t / 5) % 3 == 0);
  const std::vector<Material> mats = {elastic(1e7, 0.3, 1500), elastic(5e8, 0.2, 2400)};
  FemProblem pb;
  pb.fixed.assign(m.positions.size(), 0);
  for (size_t v = 0; v < m.positions.size(); ++v)
    if (m.positions[v].y == 0) pb.fixed[v] = 7;
  pb.acceleration = DVec3(0.3, -9.81, 0.1);
  FemResult one, two;
  {
    ThreadLimit limit(1);
    one = solveElastic(m, mats, pb);
  }
  {
    ThreadLimit limit(2);
    two = solveElastic(m, mats, pb);
  }
  REQUIRE(one.displacement.size() == m.positions.size());
  CHECK(sameBytes(one.displacement, two.displacement));
  CHECK(sameBytes(one.tets, two.tets));
  CHECK(one.stats.iterations == two.stats.iterations);
  CHECK(one.stats.nonZeros == two.stats.nonZeros);
}

TEST_CASE("solveElastic: bad input throws", "[solids][fem]") {
  const TetMesh m = tetBlock({2, 2, 2}, DVec3(0.0), DVec3(1.0));
  const std::vector<Material> mats = {elastic(1e6, 0.3)};
  FemProblem held;
  held.fixed.assign(m.positions.size(), 0);
  for (size_t v = 0; v < m.positions.size(); ++v)
    if (m.positions[v].y == 0) held.fixed[v] = 7;
  SECTION("a NaN force") {
    FemProblem pb = held;
    pb.forces.assign(m.positions.size(), DVec3(0.0));
    pb.forces[7].y = NAN;
    CHECK_THROWS_WITH(solveElastic(m, mats, pb), Catch::Contains("force at vertex 7 is not finite"));
  }
  SECTION("an infinite acceleration") {
    FemProblem pb = held;
    pb.acceleration.z = INFINITY;
    CHECK_THROWS_WITH(solveElastic(m, mats, pb), Catch::Contains("acceleration is not finite"));
  }
  SECTION("nothing fixed") {
    FemProblem pb;
    pb.acceleration = DVec3(0, -9.81, 0);
    CHECK_THROWS_WITH(solveElastic(m, mats, pb), Catch::Contains("singular"));
  }
  SECTION("only vertices on one line fixed: the block can turn about it") {
    FemProblem pb;
    pb.fixed.assign(m.positions.size(), 0);
    for (size_t v = 0; v < m.positions.size(); ++v)
      if (m.positions[v].y == 0 && m.positions[v].z == 0) pb.fixed[v] = 7;
    CHECK_THROWS_WITH(solveElastic(m, mats, pb), Catch::Contains("singular"));
  }
  SECTION("a second, loose block") {
    TetMesh two = m;
    const uint32_t base = uint32_t(two.positions.size());
    for (const DVec3& p : m.positions) two.positions.push_back(p + DVec3(2, 0, 0));
    for (auto q : m.tets) {
      for (uint32_t& v : q) v += base;
      two.tets.push_back(q);
      two.materials.push_back(0);
    }
    FemProblem pb = held;
    pb.fixed.resize(two.positions.size(), 0);
    CHECK_THROWS_WITH(solveElastic(two, mats, pb), Catch::Contains("tetrahedron 40 can move rigidly"));
  }
  SECTION("an inverted tetrahedron") {
    TetMesh bad = m;
    std::swap(bad.tets[3][0], bad.tets[3][1]);
    CHECK_THROWS_WITH(solveElastic(bad, mats, held), Catch::Contains("tetrahedron 3 has non-positive"));
  }
  SECTION("a material id with no material") {
    TetMesh bad = m;
    bad.materials[5] = 1;
    CHECK_THROWS_WITH(solveElastic(bad, mats, held), Catch::Contains("material id 1"));
  }
  SECTION("ν = 0.5") {
    CHECK_THROWS_WITH(solveElastic(m, {elastic(1e6, 0.5)}, held), Catch::Contains("Poisson ratio"));
  }
}
