#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>

#include "core/inr_volume.h"
#include "core/polymesh.h"
#include "organisms/iso_surface.h"
#include "tests/paths.h"

using namespace sprig;

namespace {

// Volume enclosed by a closed polygon mesh (divergence theorem over fans), positive when
// the faces are counter-clockwise seen from outside.
double enclosedVolume(const PolyMesh& m) {
  double v = 0;
  size_t corner = 0;
  for (uint32_t n : m.faceSizes) {
    const uint32_t* f = m.faceVertices.data() + corner;
    for (uint32_t c = 1; c + 1 < n; ++c)
      v += glm::dot(glm::dvec3(m.positions[f[0]]), glm::cross(glm::dvec3(m.positions[f[c]]), glm::dvec3(m.positions[f[c + 1]])));
    corner += n;
  }
  return v / 6;
}

// A density volume (1 at the centre falling linearly) of n^3 voxels of size h whose
// iso-value 0.5 is the sphere of radius r about the volume's centre.
ScalarVolume ball(int n, double h, double r) {
  ScalarVolume v;
  v.dims = {n, n, n};
  v.voxel = {h, h, h};
  v.values.resize(size_t(n) * n * n);
  const double c = (n - 1) * h / 2;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const double d = std::sqrt((i * h - c) * (i * h - c) + (j * h - c) * (j * h - c) + (k * h - c) * (k * h - c));
        v.values[(size_t(k) * n + j) * n + i] = float(0.5 + (r - d) / (2 * r));
      }
  return v;
}

}  // namespace

TEST_CASE("isoSurface: a closed, outward quad mesh of the region above iso", "[organisms]") {
  SECTION("a ball: closed manifold quads enclosing 4/3 pi r^3") {
    const double r = 0.8;
    const PolyMesh m = organisms::isoSurface(ball(40, 0.05, r), 0.5);
    DiagnosticList diags;
    const PolyTopology t = checkPolyMesh(m, diags);
    CHECK_FALSE(diags.hasErrors());
    CHECK(t.closed());
    CHECK(t.manifold());
    for (uint32_t n : m.faceSizes) CHECK(n == 4);
    const double exact = 4.0 / 3.0 * M_PI * r * r * r;
    CHECK(enclosedVolume(m) == Approx(exact).epsilon(0.01));
    const Box3 box = m.bounds();
    CHECK(box.hi.x - box.lo.x == Approx(2 * r).epsilon(0.02));
  }
  SECTION("a region touching the volume's border is closed there") {
    ScalarVolume v = ball(10, 1, 3);
    for (float& x : v.values) x = 1;  // everything inside
    v.values[0] = 0;                  // but one corner voxel
    const PolyMesh m = organisms::isoSurface(v, 0.5);
    DiagnosticList diags;
    CHECK(checkPolyMesh(m, diags).closed());
    CHECK(enclosedVolume(m) > 0);
  }
  SECTION("an iso value that does not cross the volume") {
    CHECK_THROWS_WITH(organisms::isoSurface(ball(8, 1, 2), 5.0),
                      Catch::Contains("the iso value 5.000000 does not cross the volume"));
  }
  SECTION("the CT skull of CGAL's free data: 18,914 closed quads") {
    const std::filesystem::path skull = std::filesystem::path(SPRIG_SOURCE_DIR) / "species/meshes/skull_2.9.inr";
    REQUIRE(std::filesystem::exists(skull));  // make deps extracts it (docs/MESHES.md)
    const PolyMesh m = organisms::isoSurface(readInrVolume(skull), 2.9);
    DiagnosticList diags;
    const PolyTopology t = checkPolyMesh(m, diags);
    CHECK(m.faceCount() == 18914);
    CHECK(t.closed());
    CHECK(t.manifold());
    CHECK(enclosedVolume(m) > 0);
  }
}
