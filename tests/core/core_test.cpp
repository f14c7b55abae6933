#include <catch2/catch.hpp>

#include <sys/stat.h>

#include <filesystem>
#include <initializer_list>
#include <tuple>

#include "core/atomic_file.h"
#include "core/diagnostics.h"
#include "core/text.h"
#include "core/mesh.h"
#include "core/parallel.h"
#include "core/rng.h"

using namespace sprig;

TEST_CASE("Diagnostic::format", "[core]") {
  SECTION("location, message, source line and caret") {
    Diagnostic d{Severity::Error, {"a.lsys", 3, 5}, "unexpected ')'", "A(x))"};
    CHECK(d.format() == "a.lsys:3:5: error: unexpected ')'\n  A(x))\n      ^");
  }
  SECTION("no source line") {
    Diagnostic d{Severity::Error, {"s.yaml", 1, 1}, "bad", ""};
    CHECK(d.format() == "s.yaml:1:1: error: bad");
  }
  SECTION("InputError collects every diagnostic") {
    DiagnosticList list;
    list.error({"f", 1, 2}, "one");
    list.error({"f", 4, 1}, "two");
    try {
      list.throwIfErrors();
      FAIL("no throw");
    } catch (const InputError& e) {
      CHECK(std::string(e.what()) == "f:1:2: error: one\nf:4:1: error: two");
      CHECK(e.diagnostics().size() == 2);
    }
  }
  SECTION("lineOf and didYouMean") {
    CHECK(lineOf("a\nbc\r\nd", 2) == "bc");
    CHECK(lineOf("a\nbc", 3).empty());
    CHECK(didYouMean("grammer", {"grammar", "kind", "seed"}) == " (did you mean 'grammar'?)");
    CHECK(didYouMean("zzzzzz", {"grammar", "kind"}).empty());
  }
}

namespace {

/// CHECKs editDistance(a, b) == distance for each {a, b, distance}.
void checkDistances(std::initializer_list<std::tuple<const char*, const char*, int>> cases) {
  for (auto [a, b, distance] : cases) {
    CAPTURE(a, b);
    CHECK(editDistance(a, b) == distance);
  }
}

}  // namespace

TEST_CASE("editDistance", "[core]") {
  SECTION("Levenshtein edits count one each") {
    checkDistances({{"", "", 0}, {"abc", "", 3}, {"", "ab", 2},
                    {"kitten", "sitting", 3}, {"steps", "steeps", 1}, {"seed", "sed", 1}});
  }
  SECTION("an adjacent transposition is one edit") {
    checkDistances({{"ab", "ba", 1}, {"steps", "setps", 1}, {"angle", "angel", 1},
                    {"grammar", "gramamr", 1}, {"abcdef", "badcfe", 3}});
  }
  SECTION("optimal string alignment: a transposed pair is not edited again") {
    // Full Damerau distance of ("ca", "abc") is 2; OSA, which never edits a
    // transposed pair again, gives 3.
    CHECK(editDistance("ca", "abc") == 3);
  }
  SECTION("symmetric") {
    for (auto [a, b] : {std::pair{"tropism", "tropsim"}, std::pair{"radii", "raddi"}, std::pair{"x", "yxz"}})
      CHECK(editDistance(a, b) == editDistance(b, a));
  }
  SECTION("didYouMean finds a swapped pair of letters in a short word") {
    // "widht" is 2 Levenshtein edits from both "wide" and "width" (the first listed won);
    // with transpositions "width" is 1 edit away and wins.
    CHECK(didYouMean("widht", {"wide", "width"}) == " (did you mean 'width'?)");
    CHECK(didYouMean("kidn", {"seed", "kind"}) == " (did you mean 'kind'?)");
    CHECK(didYouMean("agnle", {"angle", "axiom"}) == " (did you mean 'angle'?)");
  }
}

TEST_CASE("Rng", "[core]") {
  SECTION("the sequence is fixed by the seed") {
    Rng a(42), b(42), c(43);
    uint32_t x = a.next32();
    CHECK(x == b.next32());
    CHECK(x != c.next32());
  }
  SECTION("uniform lies in [0,1) with the right mean") {
    Rng r(7);
    double sum = 0;
    for (int i = 0; i < 100000; ++i) {
      double u = r.uniform();
      REQUIRE(u >= 0.0);
      REQUIRE(u < 1.0);
      sum += u;
    }
    CHECK(sum / 100000 == Approx(0.5).margin(0.005));
  }
  SECTION("normal has the requested mean and deviation") {
    Rng r(9);
    double s = 0, s2 = 0;
    const int n = 200000;
    for (int i = 0; i < n; ++i) {
      double v = r.normal(3.0, 2.0);
      s += v;
      s2 += v * v;
    }
    double mean = s / n;
    CHECK(mean == Approx(3.0).margin(0.02));
    CHECK(std::sqrt(s2 / n - mean * mean) == Approx(2.0).margin(0.02));
  }
  SECTION("derived seeds depend on every id") {
    CHECK(deriveSeed(1, {2, 3}) != deriveSeed(1, {3, 2}));
    CHECK(deriveSeed(1, {2, 3}) == deriveSeed(1, {2, 3}));
  }
}

TEST_CASE("parallelFor", "[core]") {
  std::vector<int> v(10000, 0);
  parallelFor(0, v.size(), [&](size_t i) { v[i] = static_cast<int>(i) * 2; }, 64);
  for (size_t i = 0; i < v.size(); ++i) REQUIRE(v[i] == static_cast<int>(i) * 2);
  {
    ThreadLimit one(1);
    CHECK(threadCount() == 1);
  }
}

TEST_CASE("writeFileAtomic", "[core]") {
  namespace fs = std::filesystem;
  fs::path dir = fs::temp_directory_path() / "sprig_core_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  SECTION("writes and replaces") {
    writeFileAtomic(dir / "a.txt", "one");
    writeFileAtomic(dir / "a.txt", "two");
    CHECK(readFile(dir / "a.txt") == "two");
  }
  SECTION("an uncommitted temporary leaves nothing") {
    {
      TempPath tmp(dir / "b.png");
      writeFileAtomic(tmp.path(), "partial");
      CHECK(tmp.path().extension() == ".png");
    }
    CHECK(!fs::exists(dir / "b.png"));
    int n = 0;
    for ([[maybe_unused]] auto& e : fs::directory_iterator(dir)) ++n;
    CHECK(n == 0);
  }
  SECTION("a missing folder is an error, not a crash") {
    CHECK_THROWS_AS(writeFileAtomic(dir / "no" / "such" / "x", "y"), std::runtime_error);
  }
  fs::remove_all(dir);
}

TEST_CASE("readFile reads regular files only, never blocking on a FIFO", "[core]") {
  namespace fs = std::filesystem;
  fs::path dir = fs::temp_directory_path() / "sprig_core_readfile_test";
  fs::remove_all(dir);
  fs::create_directories(dir / "folder");
  writeFileAtomic(dir / "a.txt", "abc");
  REQUIRE(::mkfifo((dir / "fifo").c_str(), 0600) == 0);
  CHECK(readFile(dir / "a.txt") == "abc");
  CHECK(notRegularFileReason(dir / "a.txt").empty());
  auto reasonOf = [](const fs::path& p) -> std::string {
    try {
      readFile(p);
    } catch (const FileReadError& e) {
      return e.reason();
    }
    return "read";
  };
  // The FIFO has no writer: opening it for reading without the check would block forever.
  CHECK(reasonOf(dir / "fifo") == "is a FIFO, not a regular file");
  CHECK(reasonOf(dir / "folder") == "is a folder, not a regular file");
  CHECK(reasonOf(dir / "none") == "cannot find file");
  CHECK(reasonOf(dir / "a.txt" / "x") == "cannot find file");
  CHECK_THROWS_WITH(readFile(dir / "a.txt", 2), "'" + (dir / "a.txt").string() + "' has 3 bytes, more than the limit of 2 bytes");
  CHECK_THROWS_WITH(requireRegularFile(dir / "fifo"), "'" + (dir / "fifo").string() + "' is a FIFO, not a regular file");
  CHECK_THROWS_WITH(readInputFile(dir / "folder", "f", 10, "L"), "f: error: is a folder, not a regular file");
  fs::remove_all(dir);
}

TEST_CASE("analyzeTopology", "[core]") {
  // A tetrahedron, outward oriented.
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  auto t = analyzeTopology(m);
  CHECK(t.closed());
  CHECK(t.manifold());
  CHECK(signedVolume(m) == Approx(1.0 / 6.0));
  m.triangles.pop_back();
  t = analyzeTopology(m);
  CHECK(t.boundaryEdges == 3);
  m.triangles.push_back({1, 3, 2});  // flipped
  t = analyzeTopology(m);
  CHECK(t.inconsistentEdges == 3);
}

TEST_CASE("Diagnostic::format shows a window of a long line around the caret", "[core]") {
  std::string line(400000, 'x');
  Diagnostic d{Severity::Error, SourceLoc{"g.lsys", 2, 200000}, "too deep", line};
  std::string out = d.format();
  CHECK(out.size() < 2 * kDiagnosticWindow + 100);
  CHECK(out.find("\n  ...xxx") != std::string::npos);
  CHECK(out.find("xxx...\n") != std::string::npos);
  // Stored cut: a list of errors on a long line does not copy the line each time.
  DiagnosticList list;
  list.error(SourceLoc{"g.lsys", 2, 200000}, "too deep", line);
  CHECK(list.items()[0].sourceLine.size() <= 4 * kDiagnosticWindow);
  CHECK(list.items()[0].format() == out);
  Diagnostic shortLine{Severity::Error, SourceLoc{"g.lsys", 1, 3}, "m", "abcdef"};
  CHECK(shortLine.format() == "g.lsys:1:3: error: m\n  abcdef\n    ^");
}

TEST_CASE("findNonText", "[core]") {
  CHECK(!findNonText("plain\ttext\r\n caf\xc3\xa9 \xe2\x82\xac \xf0\x9f\x8c\xb1"));
  auto nul = findNonText(std::string("ab\ncd\0", 6));
  REQUIRE(nul);
  CHECK(nul->offset == 5);
  CHECK(nul->line == 2);
  CHECK(nul->col == 3);
  CHECK(nul->what == "byte 0x00 (NUL)");
  CHECK(findNonText("a\xff")->offset == 1);
  CHECK(findNonText("\xc0\xaf"));       // overlong
  CHECK(findNonText("\xed\xa0\x80"));   // surrogate
  CHECK(findNonText("\xe2\x82"));        // truncated
  CHECK(findNonText("\x1b[31m"));         // escape sequence
}
