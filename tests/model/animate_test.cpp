#include "model/animate.h"

#include <catch2/catch.hpp>
#include <OpenImageIO/imageio.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <tuple>

#include "growth_frame.h"
#include "model/growth.h"
#include "model/tree_kind.h"
#include "core/atomic_file.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "lsystem/turtle.h"
#include "tests/scratch_dir.h"

using namespace sprig;
namespace fs = std::filesystem;
using test::TempDir;

namespace {

/// A `kind: tree` species: the lines of its grammar block (indented by two spaces) and the
/// top-level keys that follow the grammar.
std::string treeSpecies(const char* grammarLines, const char* keys) {
  return std::string("kind: tree\ngrammar: |\n") + grammarLines + keys;
}

/// A node-rewriting plant: old internodes stay, each step adds new ones at the apices.
const std::string kNodeRewriting = treeSpecies(R"(  lsystem: node
  derivation length: 4
  angle: 30
  axiom: A
  A --> F[+A][-A]FA
)",
                                               R"(steps: 4
turtle:
  width: 0.2
render: {width: 48, height: 40, samples: 1}
)");

/// Edge rewriting: every F is rewritten into two new ones in every step.
const std::string kEdgeRewriting = treeSpecies(R"(  lsystem: edge
  derivation length: 3
  axiom: F
  F --> FF
)",
                                               "render: {width: 32, height: 32, samples: 1}\n");

/// A stochastic bush: frames must keep the same branches from stage to stage.
const std::string kStochastic = treeSpecies(R"(  lsystem: bush
  derivation length: 4
  seed: 7
  angle: 25
  axiom: A
  A --> F[+A]A : 1
  A --> F[-A][&A]A : 1
  A --> F@O(0.2) : 1
)",
                                            "render: {width: 40, height: 32, samples: 1}\n");

}  // namespace

TEST_CASE("growthFrames", "[model]") {
  auto f = growthFrames(2, 5, 4);
  REQUIRE(f.size() == 1 + 3 * 4);
  // {frame, stage, fraction}: the first frame, the next stage's first and last, the last.
  const std::tuple<size_t, int, double> expected[] = {{0, 2, 1.0}, {1, 3, 0.25}, {4, 3, 1.0}, {f.size() - 1, 5, 1.0}};
  for (auto [i, stage, fraction] : expected) {
    CAPTURE(i);
    CHECK(f[i].stage == stage);
    CHECK(f[i].fraction == fraction);
  }
  CHECK(growthFrames(3, 3, 6).size() == 1);
}

TEST_CASE("Turtle::run growth fraction", "[model][lsystem]") {
  Species s = parseSpecies(kNodeRewriting, "node.yaml");
  GrowthEngine plain(s);  // the strings as derived, without growth settings
  std::vector<lsystem::Skeleton> stages;
  for (int k = 1; k <= 3; ++k) stages.push_back(plain.skeletonAt(k));
  GrowthEngine seq(s);
  REQUIRE(seq.lastStep() == 4);

  SECTION("fraction 1 is the full stage, bit for bit") {
    for (int k = 1; k <= 3; ++k) {
      lsystem::Skeleton a = seq.skeletonAt(k, 1.0);
      const lsystem::Skeleton& b = stages[static_cast<size_t>(k - 1)];
      REQUIRE(a.internodes.size() == b.internodes.size());
      for (size_t i = 0; i < a.internodes.size(); ++i) {
        CHECK(a.internodes[i].start == b.internodes[i].start);
        CHECK(a.internodes[i].end == b.internodes[i].end);
        CHECK(a.internodes[i].baseRadius == b.internodes[i].baseRadius);
      }
    }
  }
  SECTION("node rewriting: new internodes grow from nothing, so fraction 0 is the previous stage") {
    CHECK(seq.growthStart(3) == 0.0);
    lsystem::Skeleton a = seq.skeletonAt(3, 0.0);
    const lsystem::Skeleton& b = stages[1];
    REQUIRE(a.internodes.size() == b.internodes.size());
    for (size_t i = 0; i < a.internodes.size(); ++i) {
      CHECK(glm::length(a.internodes[i].start - b.internodes[i].start) < 1e-12);
      CHECK(glm::length(a.internodes[i].end - b.internodes[i].end) < 1e-12);
    }
  }
  SECTION("half grown: new internodes have half their length and radius, old ones are untouched") {
    lsystem::Skeleton half = seq.skeletonAt(3, 0.5);
    lsystem::Skeleton full = seq.skeletonAt(3, 1.0);
    REQUIRE(half.internodes.size() == full.internodes.size());
    int grown = 0;
    for (size_t i = 0; i < half.internodes.size(); ++i) {
      const auto& h = half.internodes[i];
      const auto& f = full.internodes[i];
      REQUIRE(h.step == f.step);
      if (f.step == 3) {
        ++grown;
        CHECK(h.length() == Approx(0.5 * f.length()));
        CHECK(h.baseRadius == Approx(0.5 * f.baseRadius));
      } else {
        CHECK(h.length() == Approx(f.length()));
      }
    }
    // Stage 3 adds 2 internodes per apex of stage 2 (3^2 apices): 18 new internodes.
    CHECK(grown == 18);
  }
}

TEST_CASE("GrowthEngine::growthStart", "[model]") {
  SECTION("F -> FF: every module is new; starting at half keeps the total length continuous") {
    GrowthEngine seq(parseSpecies(kEdgeRewriting, "edge.yaml"));
    for (int k = 1; k <= 3; ++k) {
      CHECK(seq.growthStart(k) == Approx(0.5));
      const double previous = seq.skeletonAt(k - 1, 1.0).totalLength();
      CHECK(seq.skeletonAt(k, 0.0).totalLength() == Approx(previous));
      CHECK(seq.skeletonAt(k, 1.0).totalLength() == Approx(2 * previous));
    }
  }
  SECTION("the frame box holds every stage") {
    GrowthEngine seq(parseSpecies(kStochastic, "bush.yaml"));
    for (int k = 0; k <= seq.lastStep(); ++k) {
      DBox3 b = seq.skeletonAt(k, 1.0).bounds();
      if (b.empty()) continue;
      CHECK(seq.frameBox().lo.x <= b.lo.x);
      CHECK(seq.frameBox().hi.y >= b.hi.y);
    }
  }
  SECTION("stochastic choices stay the same: a branch of stage 3 is the same branch at stage 4") {
    GrowthEngine seq(parseSpecies(kStochastic, "bush.yaml"));
    lsystem::Skeleton s3 = seq.skeletonAt(3, 1.0);
    lsystem::Skeleton s4 = seq.skeletonAt(4, 0.0);
    REQUIRE(s4.internodes.size() == s3.internodes.size());
    for (size_t i = 0; i < s3.internodes.size(); ++i)
      CHECK(glm::length(s3.internodes[i].end - s4.internodes[i].end) < 1e-12);
  }
}

TEST_CASE("animateSpecies", "[model]") {
  ProgressSettings::setQuiet(true);
  TempDir tmp("animate-test");
  Species s = parseSpecies(kStochastic, "bush.yaml");
  AnimateOptions opt;
  opt.firstStage = 1;
  opt.framesPerStage = 2;
  opt.progressLabel.clear();

  SECTION("a frame folder: every frame equals a single render of its stage and fraction") {
    AnimateResult r = animateSpecies(s, tmp.path / "frames", opt);
    const auto frames = growthFrames(1, 4, 2);
    REQUIRE(r.frames == static_cast<int>(frames.size()));
    GrowthEngine seq(s);
    for (size_t i : {size_t(0), size_t(3), frames.size() - 1}) {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%05zu.png", i);
      REQUIRE(fs::is_regular_file(tmp.path / "frames" / name));
      writeImage(test::growthFrameImage(seq, s.render, frames[i], s.render.image.width, s.render.image.height),
                         tmp.path / "single.png");
      CHECK(readFile(tmp.path / "frames" / name) == readFile(tmp.path / "single.png"));
    }
    CHECK(!fs::exists(tmp.path / "frames" / "frame_00007.png"));
  }
  SECTION("a GIF has one subimage per frame and leaves no temporary behind") {
    AnimateResult r = animateSpecies(s, tmp.path / "bush.gif", opt);
    auto in = OIIO::ImageInput::open((tmp.path / "bush.gif").string());
    REQUIRE(in);
    int n = 0;
    while (in->seek_subimage(n, 0)) ++n;
    CHECK(n == r.frames);
    SECTION("a hold repeats the last frame hold * fps times") {
      opt.holdSeconds = 0.5;
      opt.fps = 8;
      animateSpecies(s, tmp.path / "held.gif", opt);
      auto held = OIIO::ImageInput::open((tmp.path / "held.gif").string());
      REQUIRE(held);
      int m = 0;
      while (held->seek_subimage(m, 0)) ++m;
      CHECK(m == r.frames + 4);
    }
    REQUIRE(in->seek_subimage(0, 0));
    CHECK(in->spec().width == 40);
    in->close();
    for (const auto& e : fs::directory_iterator(tmp.path)) CHECK(e.path().filename().string().rfind(".sprig-tmp-", 0) != 0);
  }
  SECTION("MP4 without ffmpeg is a clear input error; unknown extensions are refused") {
    if (findFfmpeg().empty()) {
      CHECK_THROWS_WITH(animateSpecies(s, tmp.path / "x.mp4", opt), Catch::Contains("ffmpeg command is not installed"));
      CHECK(!fs::exists(tmp.path / "x.mp4"));
    }
    CHECK_THROWS_AS(animationFormatFor(tmp.path / "x.avi"), std::invalid_argument);
    CHECK(animationFormatFor(tmp.path / "out") == AnimationFormat::Frames);
  }
}

TEST_CASE("animateSpecies with wind", "[model][wind]") {
  ProgressSettings::setQuiet(true);
  TempDir tmp("animate-wind-test");
  Species s = parseSpecies(kStochastic, "bush.yaml");
  AnimateOptions opt;
  opt.firstStage = 4;
  opt.progressLabel.clear();
  opt.fps = 4;
  opt.windSeconds = 1;
  const AnimateResult still = animateSpecies(s, tmp.path / "still", opt);
  REQUIRE(still.frames == 1);
  auto frame = [&](const char* folder, int i) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%05d.png", i);
    return readFile(tmp.path / folder / name);
  };
  SECTION("zero wind is the still tree, byte for byte") {
    opt.windSpeed = 0;
    CHECK(animateSpecies(s, tmp.path / "calm", opt).frames == 1);
    CHECK(frame("calm", 0) == frame("still", 0));
  }
  SECTION("wind: windSeconds * fps frames, moving, the same bytes twice and at 1 and 2 threads") {
    opt.windSpeed = 12;
    opt.windDirectionDeg = 90;
    REQUIRE(animateSpecies(s, tmp.path / "windy", opt).frames == 4);
    {
      ThreadLimit one(1);
      animateSpecies(s, tmp.path / "windy1", opt);
    }
    {
      ThreadLimit two(2);
      animateSpecies(s, tmp.path / "windy2", opt);
    }
    for (int i = 0; i < 4; ++i) {
      CHECK(frame("windy", i) == frame("windy1", i));
      CHECK(frame("windy", i) == frame("windy2", i));
    }
    CHECK(frame("windy", 0) != frame("still", 0));
    CHECK(frame("windy", 1) != frame("windy", 2));
  }
  SECTION("bad wind is refused") {
    opt.windSpeed = -1;
    CHECK_THROWS_AS(animateSpecies(s, tmp.path / "bad", opt), std::invalid_argument);
  }
}
