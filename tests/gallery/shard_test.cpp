#include "gallery/shard.h"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <unistd.h>

#include "core/diagnostics.h"
#include "gallery/manifest.h"
#include "core/atomic_file.h"
#include "tests/scratch_dir.h"

using namespace sprig;
namespace fs = std::filesystem;
using test::TempDir;

namespace {

void write(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

}  // namespace

TEST_CASE("parseShard", "[gallery]") {
  Shard s = parseShard("1/3");
  CHECK(s.index == 1);
  CHECK(s.count == 3);
  CHECK(parseShard("0/1").count == 1);
  for (const char* bad : {"3/3", "-1/2", "1/0", "1", "a/b", "1/2/3", "0.5/2", ""})
    CHECK_THROWS_WITH(parseShard(bad), Catch::Contains("expected I/N with 0 <= I < N"));
}

TEST_CASE("shardFromEnvironment", "[gallery]") {
  std::map<std::string, std::string> env;
  auto get = [&](const char* name) -> const char* {
    auto it = env.find(name);
    return it == env.end() ? nullptr : it->second.c_str();
  };
  CHECK(!shardFromEnvironment(get));
  auto checkShard = [&](int index, int count) {  // env names shard index/count
    auto s = shardFromEnvironment(get);
    REQUIRE(s);
    CHECK(s->index == index);
    CHECK(s->count == count);
  };
  SECTION("Slurm job arrays, with and without an offset") {
    env = {{"SLURM_ARRAY_TASK_ID", "2"}, {"SLURM_ARRAY_TASK_COUNT", "4"}};
    checkShard(2, 4);
    env = {{"SLURM_ARRAY_TASK_ID", "5"}, {"SLURM_ARRAY_TASK_COUNT", "4"}, {"SLURM_ARRAY_TASK_MIN", "3"}};
    CHECK(shardFromEnvironment(get)->index == 2);
    env = {{"SLURM_ARRAY_TASK_ID", "4"}, {"SLURM_ARRAY_TASK_COUNT", "4"}};
    CHECK_THROWS_AS(shardFromEnvironment(get), UsageError);
    env = {{"SLURM_ARRAY_TASK_ID", "1"}};
    CHECK_THROWS_WITH(shardFromEnvironment(get), Catch::Contains("SLURM_ARRAY_TASK_COUNT is not"));
  }
  SECTION("Slurm job arrays with a step: --array=1-7:3 is tasks 1, 4 and 7 of 3") {
    for (int id : {1, 4, 7}) {
      env = {{"SLURM_ARRAY_TASK_ID", std::to_string(id)}, {"SLURM_ARRAY_TASK_COUNT", "3"},
             {"SLURM_ARRAY_TASK_MIN", "1"}, {"SLURM_ARRAY_TASK_STEP", "3"}};
      checkShard((id - 1) / 3, 3);
    }
    env = {{"SLURM_ARRAY_TASK_ID", "5"}, {"SLURM_ARRAY_TASK_COUNT", "3"}, {"SLURM_ARRAY_TASK_MIN", "1"},
           {"SLURM_ARRAY_TASK_STEP", "3"}};
    CHECK_THROWS_WITH(shardFromEnvironment(get), Catch::Contains("is not SLURM_ARRAY_TASK_MIN=1 plus a multiple of "
                                                                 "SLURM_ARRAY_TASK_STEP=3"));
    env = {{"SLURM_ARRAY_TASK_ID", "1"}, {"SLURM_ARRAY_TASK_COUNT", "3"}, {"SLURM_ARRAY_TASK_STEP", "0"}};
    CHECK_THROWS_AS(shardFromEnvironment(get), UsageError);
    // A list such as --array=1,5,9 comes with step 1: task 5 is past the count.
    env = {{"SLURM_ARRAY_TASK_ID", "5"}, {"SLURM_ARRAY_TASK_COUNT", "3"}, {"SLURM_ARRAY_TASK_MIN", "1"},
           {"SLURM_ARRAY_TASK_STEP", "1"}};
    CHECK_THROWS_WITH(shardFromEnvironment(get), Catch::Contains("shard 4 of 3 is out of range"));
  }
  SECTION("Kubernetes indexed jobs") {
    env = {{"JOB_COMPLETION_INDEX", "1"}, {"SPRIG_SHARD_COUNT", "3"}};
    checkShard(1, 3);
    env = {{"JOB_COMPLETION_INDEX", "x"}, {"SPRIG_SHARD_COUNT", "3"}};
    CHECK_THROWS_WITH(shardFromEnvironment(get), Catch::Contains("expected a whole number"));
  }
}

TEST_CASE("shardItems", "[gallery]") {
  SECTION("the shards of N partition the items, each item exactly once") {
    for (int n = 1; n <= 5; ++n) {
      std::vector<int> seen(11, 0);
      for (int i = 0; i < n; ++i)
        for (size_t k : shardItems({i, n}, 11)) ++seen[k];
      for (int c : seen) CHECK(c == 1);
    }
  }
  CHECK(shardItems({1, 3}, 8) == std::vector<size_t>{1, 4, 7});
  CHECK(shardItems({2, 3}, 2).empty());
}

TEST_CASE("galleryInputHash", "[gallery]") {
  TempDir tmp("shard-test");
  fs::create_directories(tmp.path / "species");
  write(tmp.path / "g.lsys", "axiom: F\n");
  write(tmp.path / "bark.png", "pixels");
  write(tmp.path / "species" / "a.yaml", "kind: tree\ngrammar: ../g.lsys\ntree: {bark: {image: ../bark.png}}\n");
  const fs::path a = tmp.path / "species" / "a.yaml";
  const std::string h = galleryInputHash(a, "q=draft");
  CHECK(h.size() == 32);
  CHECK(galleryInputHash(a, "q=draft") == h);
  CHECK(galleryInputHash(a, "q=final") != h);
  SECTION("a changed grammar changes the hash") {
    write(tmp.path / "g.lsys", "axiom: FF\n");
    CHECK(galleryInputHash(a, "q=draft") != h);
  }
  SECTION("a changed texture changes the hash") {
    write(tmp.path / "bark.png", "other pixels");
    CHECK(galleryInputHash(a, "q=draft") != h);
  }
  SECTION("a changed species file changes the hash") {
    write(a, "kind: tree\ngrammar: ../g.lsys\ntree: {bark: {image: ../bark.png}}\n# note\n");
    CHECK(galleryInputHash(a, "q=draft") != h);
  }
}

TEST_CASE("manifestJson", "[gallery]") {
  Manifest m;
  m.shard = {1, 2};
  m.quality = "final";
  ManifestEntry e;
  e.item.source = "species/a \"quoted\".yaml";
  e.item.name = "A <b>";
  e.item.description = "line one\nline two";
  e.item.kind = "tree";
  e.item.preview = "a.png";
  e.item.animation = "a.gif";
  e.item.stages = {1, 3, 5};
  e.item.modules = 123456789;
  e.item.triangles = 42;
  e.item.frames = 17;
  e.item.renderSeconds = 0.125;
  e.hash = "0123456789abcdef0123456789abcdef";
  e.outputs = {"a.png", "a.gif"};
  m.entries.push_back(e);
  m.entries.push_back(ManifestEntry{});
  Manifest r = parseManifest(manifestJson(m), "m.json");
  CHECK(r.shard.index == 1);
  CHECK(r.shard.count == 2);
  CHECK(r.quality == "final");
  REQUIRE(r.entries.size() == 2);
  CHECK(r.entries[0].item.source == e.item.source);
  CHECK(r.entries[0].item.description == e.item.description);
  CHECK(r.entries[0].item.stages == e.item.stages);
  CHECK(r.entries[0].item.modules == e.item.modules);
  CHECK(r.entries[0].item.frames == 17);
  CHECK(r.entries[0].item.renderSeconds == 0.125);
  CHECK(r.entries[0].outputs == e.outputs);
  CHECK(r.entries[0].hash == e.hash);
  CHECK(manifestJson(r) == manifestJson(m));
  CHECK_THROWS_WITH(parseManifest("{\"format\": 1, \"items\": [", "bad.json"), Catch::StartsWith("bad.json:"));
}

TEST_CASE("removeDeadTemporaries", "[gallery]") {
  TempDir tmp("shard-test");
  const std::string mine = ".sprig-tmp-" + std::to_string(getpid()) + "-0-a.png";
  write(tmp.path / mine, "live");
  write(tmp.path / ".sprig-tmp-999999999-0-b.png", "dead");  // no such process
  write(tmp.path / "c.png", "kept");
  CHECK(removeDeadTemporaries(tmp.path, 600) == 0);  // too young to be sure on a shared folder
  CHECK(removeDeadTemporaries(tmp.path, 0) == 1);
  CHECK(fs::exists(tmp.path / mine));
  CHECK(fs::exists(tmp.path / "c.png"));
  CHECK(!fs::exists(tmp.path / ".sprig-tmp-999999999-0-b.png"));
}
