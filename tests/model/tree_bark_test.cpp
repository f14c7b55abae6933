#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/mesh.h"
#include "core/mesh_clean.h"
#include "model/model.h"
#include "model/species.h"
#include "model/tree_kind.h"
#include "render/scene.h"
#include "tests/paths.h"

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

TEST_CASE("tree bark: the branch bark ridge arcs over the lateral, darker above it than below", "[model]") {
  // The same tree with and without `ridge_arc`: the ratio of their colours is 1 − the arc's
  // darkness wherever the arc lies (the seam's darkening is the same in both).
  std::string withArc = kTree;
  const std::string key = "ridge_darkening: 0.5}";
  withArc.replace(withArc.find(key), key.size(), "ridge_darkening: 0.5, ridge_arc: 0.7, ridge_arc_relief: 1}");
  Species plainSpecies = parseSpecies(kTree, "bark.yaml"), arcSpecies = parseSpecies(withArc, "arc.yaml");
  SpeciesModel plainModel(plainSpecies), arcModel(arcSpecies);
  render::Scene plain, arc;
  plainModel.addToScene(plain, plainModel.finalStage(), GeometryMode::Exact, plainSpecies.render);
  arcModel.addToScene(arc, arcModel.finalStage(), GeometryMode::Exact, arcSpecies.render);
  plain.commit();
  arc.commit();
  const TrunkProbe p{plain}, a{arc};
  constexpr double kPi = 3.14159265358979323846;
  auto ratio = [&](double theta, double y) {
    return luminance(a.at(theta, y)) / std::max(1e-6, luminance(p.at(theta, y)));
  };
  // Above the lateral, horizontal rays would meet the lateral itself (it rises at 40° from
  // the trunk); rays falling at 60° toward the trunk pass above it. They aim at radius 0.14
  // at height y and meet the bark (r ≈ 0.15) about 0.017 higher.
  auto fromAbove = [](const render::Scene& scene, double theta, double y) {
    const double e = 60.0 * kPi / 180.0;
    const Vec3 dir(static_cast<float>(-std::cos(e) * std::cos(theta)), static_cast<float>(-std::sin(e)),
                   static_cast<float>(-std::cos(e) * std::sin(theta)));
    const Vec3 target(static_cast<float>(0.14 * std::cos(theta)), static_cast<float>(y),
                      static_cast<float>(0.14 * std::sin(theta)));
    auto hit = scene.intersect(target - 2.0f * dir, dir, 0.0f, 10.0f);
    REQUIRE(hit);
    return hit->color;
  };
  auto ratioAbove = [&](double theta, double y) {
    return luminance(fromAbove(arc, theta, y)) / std::max(1e-6, luminance(fromAbove(plain, theta, y)));
  };
  // Along each line up the trunk (every 2.5°), the darkest point; the apex is the highest
  // of those among the lines that reach the crest's full darkness.
  auto darkestOn = [&](double theta, double& y0) {
    double r0 = 2;
    for (int j = 0; j <= 100; ++j) {
      const double y = 1.0 + 0.5 * j / 100;
      const double r = ratioAbove(theta, y);
      if (r < r0) r0 = r, y0 = y;
    }
    return r0;
  };
  double apexTheta = 0, apexY = -1, apexRatio = 2;
  for (int i = 0; i < 144; ++i) {
    const double theta = 2 * kPi * i / 144;
    double y = 0;
    const double r = darkestOn(theta, y);
    if (r < 0.4 && y > apexY) apexY = y, apexTheta = theta, apexRatio = r;
  }
  INFO("apex: ratio " << apexRatio << " at theta " << apexTheta << ", y " << apexY);
  // The crest: 1 − 0.7 at its darkest, above the branch's footprint (the lateral, r 0.05 at
  // 40°, pierces the trunk, r 0.15, about 0.18 above P at y = 1; its footprint reaches
  // 0.05 / sin 40° = 0.08 higher).
  CHECK(apexRatio == Approx(0.3).margin(0.05));  // (samples 0.005 apart on a crest 0.035 wide)
  CHECK(apexY > 1.2);
  CHECK(apexY < 1.45);
  // Below the branch on the same line, on the trunk's far side, and on the basal internode
  // below P: unchanged.
  for (int j = 0; j <= 20; ++j) {
    const double y = 0.5 + 0.45 * j / 20;
    CHECK(ratio(apexTheta, y) == Approx(1.0).margin(1e-4));
    CHECK(ratio(apexTheta + kPi, y + 0.5) == Approx(1.0).margin(1e-4));
  }
  // The arms run down both sides: 0.45 rad to either side (1.35 r_B around) the crest, as
  // dark, lies lower (by 0.8·(√(1.35² + 0.64) − 0.8)·r_B = 0.031 on the chart).
  for (double side : {-0.45, 0.45}) {
    double y0 = 0;
    const double r0 = darkestOn(apexTheta + side, y0);
    INFO("side " << side << ": darkest " << r0 << " at y " << y0);
    CHECK(r0 < 0.4);
    CHECK(y0 < apexY - 0.015);
  }
}

TEST_CASE("fig_tree_18b: the raised branch bark ridge meshes to one closed piece", "[model]") {
  // The figure as shipped (ridge_arc_height set) and without its ridge_arc_height line.
  const std::string path = std::string(SPRIG_SOURCE_DIR) + "/species/fig_tree_18b_pcm_ridge_arc.yaml";
  std::ifstream in(path);
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  const size_t line = text.find("    ridge_arc_height:");
  REQUIRE(line != std::string::npos);
  const std::string plainText = text.substr(0, line) + text.substr(text.find('\n', line) + 1);
  auto wood = [](const std::string& yaml, const std::string& name) -> Mesh {
    const Species species = parseSpecies(yaml, name);
    SpeciesModel model(species);
    // Cells of 0.012 (the automatic size is 2.5 times finer): the ridge, 0.064 wide and
    // 0.032 high, still spans several cells, and the test stays fast.
    return model.buildMesh(model.finalStage(), 0.012f, false);
  };
  const Mesh raised = wood(text, "fig_tree_18b.yaml"), plain = wood(plainText, "plain.yaml");
  size_t components = 0;
  triangleComponents(raised, &components);
  CHECK(components == 1);
  const MeshTopology topo = analyzeTopology(raised);
  INFO("boundary " << topo.boundaryEdges << ", non-manifold " << topo.nonManifoldEdges << ", inconsistent "
                   << topo.inconsistentEdges);
  CHECK(topo.closed());
  CHECK(topo.manifold());
  // The ridge adds a little wood (a band about 0.04 wide and 0.02 high along the arc) and
  // nothing else changes.
  const double vRaised = signedVolume(raised), vPlain = signedVolume(plain);
  std::printf("fig_tree_18b wood: %zu triangles, volume %.6f (without the raised ridge %.6f)\n",
              raised.triangleCount(), vRaised, vPlain);
  CHECK(vRaised > vPlain + 1e-4);
  CHECK(vRaised < vPlain * 1.01);
}
