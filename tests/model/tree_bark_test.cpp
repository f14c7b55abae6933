#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "model/model.h"
#include "model/species.h"
#include "model/tree_kind.h"
#include "render/scene.h"

using namespace sprig;

namespace {

// A trunk of three internodes (radii 0.15, 0.13, 0.11, rolled 137.5° between them as on a
// phyllotactic spiral) with a short lateral (radius 0.05) at y = 1, PCM junctions, and
// girth-dependent bark with lenticels and a darkened ridge.
const char* kTree = R"(kind: tree
name: bark_test
grammar: |
  lsystem: bark_test
  derivation length: 0
  axiom: !(0.3)F(1)[&(40)!(0.1)F(0.3)]/(137.5)!(0.26)F(1)/(137.5)!(0.22)F(1)
  endlsystem
turtle:
  width_scale: 1
tree:
  junctions: pcm
  tips: hemisphere
  bark: {ridge_width: 0.05, mature_radius: 0.15, lenticels: 0.5, lenticel_frequency: 10, ridge_darkening: 0.5}
)";

double luminance(const Vec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

/// The trunk's surface colour seen by a horizontal ray toward the axis at height y, angle theta.
struct TrunkProbe {
  const render::Scene& scene;
  Vec3 at(double theta, double y) const {
    const Vec3 dir(static_cast<float>(-std::cos(theta)), 0.0f, static_cast<float>(-std::sin(theta)));
    const Vec3 origin = -2.0f * dir + Vec3(0.0f, static_cast<float>(y), 0.0f);
    auto hit = scene.intersect(origin, dir, 0.0f, 10.0f);
    REQUIRE(hit);
    return hit->color;
  }
};

/// The largest colour change between neighbouring samples of a path of n steps.
/// at: where along the path (0..1) the largest change ends.
template <class Path>
double maxJump(const Path& path, int n, double* at = nullptr) {
  double worst = 0;
  Vec3 prev = path(0.0);
  for (int i = 1; i <= n; ++i) {
    const Vec3 c = path(double(i) / n);
    const double jump = std::abs(luminance(c) - luminance(prev));
    if (jump > worst) {
      worst = jump;
      if (at) *at = double(i) / n;
    }
    prev = c;
  }
  return worst;
}

}  // namespace

TEST_CASE("tree bark: furrows along each branch, continuous through junctions", "[model]") {
  Species species = parseSpecies(kTree, "bark.yaml");
  SpeciesModel model(species);
  render::Scene scene;
  model.addToScene(scene, model.finalStage(), GeometryMode::Exact, species.render);
  scene.commit();
  const TrunkProbe trunk{scene};
  constexpr double kPi = 3.14159265358979323846;

  SECTION("the colour varies much less along the axis than around it") {
    // Middle internode (radius 0.13, 16 furrows of 0.05), away from both junctions; steps of
    // half a ridge width along and around.
    const double r = 0.13, d = 0.025;
    double along = 0, around = 0;
    int n = 0;
    for (int i = 0; i < 240; ++i) {
      const double theta = 2 * kPi * i / 240;
      for (double y : {1.40, 1.47, 1.55}) {
        const double c = luminance(trunk.at(theta, y));
        along += std::abs(luminance(trunk.at(theta, y + d)) - c);
        around += std::abs(luminance(trunk.at(theta + d / r, y)) - c);
        ++n;
      }
    }
    along /= n;
    around /= n;
    INFO("mean |Δ| along " << along << ", around " << around);
    CHECK(around > 0.01);
    CHECK(along < 0.4 * around);
  }
  SECTION("a ray whose direction has an x component of 1.8e-16 hits the near side") {
    // θ = 3π/2: the ray runs along x = 0, a plane of the surface cells' grid. Before the
    // cells shared their faces bit for bit, it ran inside a crack one ulp wide between the
    // cells at x < 0 and x >= 0, met only the far side of the trunk (t = 2.135) and
    // coloured the near side with the far side's bark.
    const double theta = 1.5 * kPi;
    const Vec3 dir(static_cast<float>(-std::cos(theta)), 0.0f, static_cast<float>(-std::sin(theta)));
    REQUIRE(dir.x != 0.0f);
    REQUIRE(std::abs(dir.x) < 1e-15f);
    const Vec3 origin = -2.0f * dir + Vec3(0.0f, 0.93f, 0.0f);
    auto hit = scene.intersect(origin, dir, 0.0f, 10.0f);
    REQUIRE(hit);
    // The same ray turned a little off the axis, where it always hit the near side.
    const double off = theta + 1e-4;
    const Vec3 dir2(static_cast<float>(-std::cos(off)), 0.0f, static_cast<float>(-std::sin(off)));
    auto hit2 = scene.intersect(-2.0f * dir2 + Vec3(0.0f, 0.93f, 0.0f), dir2, 0.0f, 10.0f);
    REQUIRE(hit2);
    INFO("t " << hit->t << " at z " << hit->position.z << "; off axis t " << hit2->t);
    CHECK(hit->position.z < 0.0f);
    CHECK(hit->t == Approx(hit2->t).margin(1e-3));
  }
  SECTION("no seam: colour changes shrink with the step across the junction and the u wrap") {
    // A vertical line through the joint of the middle and top internodes (different bark
    // classes blending) and a circle round the trunk just below the lateral's junction
    // (every cone's u wraps once on it). A seam would keep its jump at any step; a
    // continuous colour's largest step shrinks about in proportion.
    for (double theta : {0.3, 2.2, 4.1}) {
      auto line = [&](double s) { return trunk.at(theta, 1.8 + 0.4 * s); };
      const double coarse = maxJump(line, 400), fine = maxJump(line, 1600);
      INFO("line at theta " << theta << ": max step " << coarse << " at 1/400, " << fine << " at 1/1600");
      CHECK(coarse > 0.002);
      CHECK(fine < 0.5 * coarse);
    }
    // The circle passes through θ = 3π/2, whose ray has an x component of cos(3π/2) = 1.8e-16
    // (see the regression section above).
    auto circle = [&](double s) { return trunk.at(2 * kPi * s, 0.93); };
    double atCoarse = 0, atFine = 0;
    const double coarse = maxJump(circle, 1500, &atCoarse), fine = maxJump(circle, 6000, &atFine);
    INFO("circle: max step " << coarse << " at 1/1500 (at " << atCoarse << "), " << fine << " at 1/6000 (at " << atFine
                             << ")");
    CHECK(fine < 0.5 * coarse);
  }
}
