#include "model/model.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "model/animate.h"
#include "growth_frame.h"
#include "model/tree_kind.h"
#include "core/mesh.h"
#include "core/parallel.h"
#include "tests/paths.h"
#include "tests/model/shipped_species.h"

using namespace sprig;

namespace {

/// A small tree without surface settings: the gallery shows its skeleton.
const std::string kSkeletonTree = R"(kind: tree
grammar: |
  lsystem: y
  derivation length: 3
  angle: 35
  axiom: !(0.12)A
  A --> F[+!(0.07)A][-!(0.07)A]
steps: 3
render: {width: 40, height: 32, samples: 1}
)";

/// The same tree with a `tree:` section: rendered as an exact BlobTree surface.
const std::string kSurfaceTree = kSkeletonTree + "tree: {junctions: smooth}\n";

/// Two spheres summed: a closed blob.
const std::string kBlob = R"(kind: blob
blob:
  blend:
    - point: {center: [-0.4, 0, 0], radius: 0.6}
    - point: {center: [0.4, 0, 0], radius: 0.5}
render: {width: 40, height: 32, samples: 1}
)";

/// A smooth point-primitive shell, three whorls.
const char* kShell = R"(kind: shell
shell:
  lambda: 1.3
  beta: 22.5
  r0: 0.2
  whorls: 3
  generating: point
  varices: false
render: {width: 40, height: 40, samples: 1}
)";

// The `kind:` line of a species file ("kind: shell"), without reading the rest.
std::string kindLine(const std::filesystem::path& file) {
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);)
    if (line.rfind("kind:", 0) == 0) return line.substr(0, line.find_last_not_of(" \r") + 1);
  return {};
}

bool sameImage(const Image& a, const Image& b) {
  return a.width == b.width && a.height == b.height && a.pixels == b.pixels;
}

}  // namespace

TEST_CASE("SpeciesModel::modes", "[model]") {
  SpeciesModel surface(parseSpecies(kSurfaceTree, "surface.yaml"));
  SpeciesModel skeleton(parseSpecies(kSkeletonTree, "skeleton.yaml"));
  SpeciesModel blob(parseSpecies(kBlob, "blob.yaml"));
  CHECK(surface.defaultMode() == GeometryMode::Exact);
  CHECK(skeleton.defaultMode() == GeometryMode::Skeleton);
  CHECK(blob.defaultMode() == GeometryMode::Exact);
  CHECK(surface.finalStage().step == 3);

  render::Scene scene;
  CHECK_THROWS_AS(blob.addToScene(scene, blob.finalStage(), GeometryMode::Skeleton, blob.species().render), UsageError);
}

TEST_CASE("SpeciesModel::stages", "[model]") {
  SECTION("tree: strip ends at the last step, animation frames are growthFrames") {
    SpeciesModel m(parseSpecies(kSurfaceTree, "surface.yaml"));
    std::vector<Stage> strip = m.stripStages(5);
    REQUIRE(!strip.empty());
    CHECK(strip.back().step == 3);
    std::vector<Stage> frames = m.animationFrames(2);
    std::vector<GrowthFrame> expected = growthFrames(0, 3, 2);
    REQUIRE(frames.size() == expected.size());
    for (size_t i = 0; i < frames.size(); ++i) {
      CHECK(frames[i].step == expected[i].stage);
      CHECK(frames[i].fraction == expected[i].fraction);
    }
    CHECK_THROWS_AS(m.stageFromIndex(4), UsageError);
  }
  SECTION("shell: ages grow to the final age, one whorl per stage index") {
    SpeciesModel m(parseSpecies(kShell, "shell.yaml"));
    const double end = m.finalStage().age;
    CHECK(end == Approx(3 * 348.0));
    std::vector<Stage> frames = m.animationFrames(3);
    REQUIRE(frames.size() >= 2);
    for (size_t i = 1; i < frames.size(); ++i) CHECK(frames[i].age > frames[i - 1].age);
    CHECK(frames.back().age == Approx(end));
    CHECK(m.stageFromIndex(1).age == Approx(348.0));
    CHECK(m.stageFromIndex(9).age == Approx(end));
  }
  SECTION("shell that starts at its final age: the strip is the final stage") {
    std::string text = kShell;
    text.replace(text.find("  generating"), 0, "  start: 1044\n  age: 1044\n");
    SpeciesModel m(parseSpecies(text, "shell.yaml"));
    const std::vector<Stage> strip = m.stripStages(5);
    REQUIRE(strip.size() == 1);
    CHECK(strip[0].age == Approx(m.finalStage().age));
    // Its animation stays at that age (before, it began at one whorl, below the start).
    for (const Stage& frame : m.animationFrames(3)) CHECK(frame.age == Approx(m.finalStage().age));
  }
  SECTION("blob: one stage") {
    SpeciesModel m(parseSpecies(kBlob, "blob.yaml"));
    CHECK(m.stripStages(5).size() == 1);
    CHECK(m.animationFrames(4).size() == 1);
  }
}

TEST_CASE("SpeciesModel::stripStages: every shipped species has a strip ending at its final stage", "[model]") {
  // The gallery draws one strip cell per stage; an empty strip is an empty image, which
  // the image writer refuses (Fig. 6's generating surface starts at its final age). The
  // strips of trees, shells and blobs follow from their parameters; an organism's is its
  // final stage or its frames' times, a solid's its operations (and building those reads
  // their meshes, seconds each), so the sweep is over the first three.
  PathPolicy policy;
  policy.root = SPRIG_SOURCE_DIR;
  for (const std::string& stem : test::shippedSpecies(SPRIG_SOURCE_DIR)) {
    INFO(stem);
    const std::filesystem::path file = std::filesystem::path(SPRIG_SOURCE_DIR) / "species" / (stem + ".yaml");
    const std::string kind = kindLine(file);
    if (kind != "kind: tree" && kind != "kind: shell" && kind != "kind: blob") continue;
    SpeciesModel model(loadSpecies(file, policy));
    const std::vector<Stage> strip = model.stripStages(5);
    REQUIRE(!strip.empty());
    CHECK(model.stageNumber(strip.back()) == model.stageNumber(model.finalStage()));
  }
}

TEST_CASE("renderModel::skeleton frames equal the growth engine's frames", "[model]") {
  Species species = parseSpecies(kSkeletonTree, "skeleton.yaml");
  SpeciesModel model(species);
  GrowthEngine seq(species);
  for (GrowthFrame f : {GrowthFrame{2, 0.5}, GrowthFrame{3, 1.0}}) {
    RenderJob job;
    job.width = 40;
    job.height = 32;
    job.mode = GeometryMode::Skeleton;
    job.stage.step = f.stage;
    job.stage.fraction = f.fraction;
    job.progress = false;
    CHECK(sameImage(renderModel(model, species.render, job), test::growthFrameImage(seq, species.render, f, 40, 32)));
  }
}

TEST_CASE("renderModel::deterministic across threads", "[model]") {
  for (const std::string& text : {kSurfaceTree, kBlob}) {
    Species species = parseSpecies(text, "species.yaml");
    RenderJob job;
    job.width = 40;
    job.height = 32;
    job.progress = false;
    Image one, two, again;
    {
      ThreadLimit limit(1);
      SpeciesModel m(species);
      one = renderModel(m, species.render, job);
    }
    {
      ThreadLimit limit(2);
      SpeciesModel m(species);
      two = renderModel(m, species.render, job);
      again = renderModel(m, species.render, job);
    }
    CHECK(sameImage(one, two));
    CHECK(sameImage(two, again));
    // Something was drawn: not every pixel is background.
    size_t differing = 0;
    const Vec4 corner = one.at(0, 0);
    for (int y = 0; y < one.height; ++y)
      for (int x = 0; x < one.width; ++x)
        if (glm::length(one.at(x, y) - corner) > 0.05f) ++differing;
    CHECK(differing > 20);
  }
}

TEST_CASE("SpeciesModel::buildMesh", "[model]") {
  SECTION("blob: closed and manifold, volume between the two spheres' union bounds") {
    SpeciesModel m(parseSpecies(kBlob, "blob.yaml"));
    ModelFigures fig;
    Mesh mesh = m.buildMesh(m.finalStage(), 0.04f, false, &fig);
    CHECK(fig.primitives == 2);
    CHECK(fig.triangles == mesh.triangleCount());
    MeshTopology topo = analyzeTopology(mesh);
    CHECK(topo.closed());
    CHECK(topo.manifold());
    const double v = signedVolume(mesh);
    const double big = 4.0 / 3.0 * kPi * 0.6 * 0.6 * 0.6;
    CHECK(v > big);  // the blend swells beyond the larger sphere alone
    CHECK(v < 4.0 * big);
  }
  SECTION("tree: the wood mesh is closed") {
    SpeciesModel m(parseSpecies(kSurfaceTree, "surface.yaml"));
    Mesh mesh = m.buildMesh(m.finalStage(), 0.02f, false);
    CHECK(mesh.triangleCount() > 100);
    CHECK(analyzeTopology(mesh).closed());
  }
}

TEST_CASE("restingFrame: a stage rests on the ground of its frame", "[model]") {
  const Box3 frame{Vec3(-1, 0, -1), Vec3(1, 2, 1)};
  const Box3 stage{Vec3(-0.1f, 0.5f, -0.1f), Vec3(0.1f, 0.7f, 0.1f)};
  const Box3 r = restingFrame(frame, stage, true);
  CHECK(r.lo.y == 0.5f);  // the ground is at the stage's lowest point
  CHECK(r.size() == frame.size());
  CHECK(r.lo.x == frame.lo.x);
  CHECK(r.lo.z == frame.lo.z);
  CHECK(restingFrame(frame, stage, false).lo.y == 0.0f);  // the ground at a fixed height
  CHECK(restingFrame(frame, Box3{}, true).lo.y == 0.0f);  // an empty stage
}

TEST_CASE("renderModel: the stages of a strip share one horizon", "[model]") {
  // A young top shell is a small shell high in the final shell's frame: before the stages
  // were staged on their frame, its ground faded out around the small shell and its
  // horizon sat rows away from the final shell's.
  PathPolicy policy;
  policy.root = SPRIG_SOURCE_DIR;
  const Species species = loadSpecies(std::filesystem::path(SPRIG_SOURCE_DIR) / "species" / "shell_top.yaml", policy);
  SpeciesModel model(species);
  const std::vector<Stage> stages = model.stripStages(5);
  REQUIRE(stages.size() >= 2);
  RenderJob job;
  job.width = 48;
  job.height = 36;
  job.samples = 1;
  job.progress = false;
  job.stage = stages.front();
  const Image young = renderModel(model, species.render, job);
  job.stage = stages.back();
  const Image grown = renderModel(model, species.render, job);
  // The shell stands in the middle: the four columns at each side are ground and sky.
  float worst = 0;
  for (int y = 0; y < job.height; ++y)
    for (int x : {0, 1, 2, 3, job.width - 4, job.width - 3, job.width - 2, job.width - 1})
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(young.at(x, y)[c] - grown.at(x, y)[c]));
  CHECK(worst < 0.03f);
}

TEST_CASE("FrameSequence: frames equal renderModel, the scene reused where it serves any camera", "[model][frames]") {
  // A turntable (the gallery's blobs, organisms and solids) and a held stage, at 1 and 2 threads.
  const std::string organism = R"(kind: organism
organism:
  base: {cube_sphere: {radius: 1, quads: 2}}
  levels: 2
  detail:
    - rock: {amplitude: 0.05, levels: [1, 2]}
render: {width: 40, height: 32, samples: 1}
)";
  struct Case {
    const std::string* text;
    bool meshScene;  ///< the scene holds triangles only: built once for the whole turntable
  };
  for (const Case& c : {Case{&organism, true}, Case{&kBlob, false}, Case{&kSurfaceTree, false}}) {
    for (int threads : {1, 2}) {
      ThreadLimit limit(threads);
      Species species = parseSpecies(*c.text, "species.yaml");
      SpeciesModel model(species);
      FrameSequence sequence(model);
      RenderJob job;
      job.width = 40;
      job.height = 32;
      job.progress = false;
      job.mode = model.defaultMode();
      job.stage = model.finalStage();
      for (int i = 0; i < 3; ++i) {
        SpeciesRender turn = species.render;
        turn.view.azimuthDeg += 120.0 * i;
        SpeciesModel fresh(species);
        CHECK(sameImage(sequence.render(turn, job), renderModel(fresh, turn, job)));
      }
      // Implicit cells are reused only where the turned camera gives them the same size.
      CHECK(sequence.builtScenes() + sequence.reusedScenes() == 3);
      if (c.meshScene) CHECK(sequence.builtScenes() == 1);
      // The same camera again: the picture itself.
      SpeciesModel fresh(species);
      const Image held = sequence.render(species.render, job);
      CHECK(sameImage(held, renderModel(fresh, species.render, job)));
      CHECK(sequence.reusedImages() == 0);
      CHECK(sameImage(sequence.render(species.render, job), held));
      CHECK(sequence.reusedImages() == 1);
      // Another stage rebuilds.
      if (species.kind == "tree") {
        const int built = sequence.builtScenes();
        job.stage = model.stageFromIndex(1);
        CHECK(sameImage(sequence.render(species.render, job), renderModel(fresh, species.render, job)));
        CHECK(sequence.builtScenes() == built + 1);
      }
    }
  }
}
