#include "model/yaml_reader.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>

using namespace sprig;
namespace fs = std::filesystem;

namespace {

std::shared_ptr<const YamlFile> parseOk(const std::string& text, DiagnosticList& diags) {
  auto f = YamlFile::parse(text, "t.yaml", diags);
  REQUIRE(f);
  return f;
}

/// A file parsed from text and a MapReader over its top-level map, both reporting to diags.
struct TopReader {
  DiagnosticList diags;
  std::shared_ptr<const YamlFile> file;
  MapReader reader;
  explicit TopReader(const std::string& text, std::string context = "test")
      : file(parseOk(text, diags)), reader(file->rootNode(), diags, std::move(context)) {}
};

/// CHECKs that diags' messages from index `first` on are `expected`, one by one.
void checkMessages(const DiagnosticList& diags, size_t first, std::initializer_list<const char*> expected) {
  for (const char* message : expected) {
    CAPTURE(first);
    CHECK(diags.items()[first++].message == message);
  }
}

}  // namespace

TEST_CASE("YamlFile::parse", "[model]") {
  DiagnosticList diags;
  SECTION("syntax errors become 1-based file:line:col") {
    auto f = YamlFile::parse("a: 1\nb: [1, 2\nc: 3\n", "t.yaml", diags);
    CHECK(!f);
    REQUIRE(diags.items().size() == 1);
    CHECK(diags.items()[0].loc.file == "t.yaml");
    CHECK(diags.items()[0].loc.line >= 2);
    CHECK(diags.items()[0].message.rfind("YAML syntax error: ", 0) == 0);
  }
  SECTION("duplicate keys are reported at the second key, nested maps too") {
    auto f = YamlFile::parse("a: 1\nb:\n  x: 1\n  x: 2\na: 3\n", "t.yaml", diags);
    REQUIRE(f);
    REQUIRE(diags.items().size() == 2);
    CHECK(diags.items()[0].format().rfind("t.yaml:4:3: error: duplicate key 'x' (first defined at line 3)", 0) == 0);
    CHECK(diags.items()[1].format().rfind("t.yaml:5:1: error: duplicate key 'a' (first defined at line 1)", 0) == 0);
  }
  SECTION("alias bombs hit the node cap") {
    std::string bomb = "a: &a [x, x, x, x, x, x, x, x, x, x]\n";
    char prev = 'a';
    for (char c = 'b'; c <= 'i'; ++c, ++prev) {
      bomb += std::string(1, c) + ": &" + c + " [";
      for (int i = 0; i < 10; ++i) bomb += std::string(i ? ", " : "") + "*" + prev;
      bomb += "]\n";
    }
    auto f = YamlFile::parse(bomb, "bomb.yaml", diags);
    CHECK(!f);
    REQUIRE(diags.hasErrors());
    CHECK(diags.items()[0].message == "YAML document has more than 1000000 nodes (alias bomb?)");
  }
  SECTION("a self-referencing alias is refused, not followed forever") {
    auto f = YamlFile::parse("a: &x [*x]\n", "t.yaml", diags);
    CHECK(!f);
    CHECK(diags.hasErrors());
  }
  SECTION("loads a file from disk with its path as the diagnostic file") {
    fs::path p = fs::temp_directory_path() / "sprig_yaml_reader_test.yaml";
    { std::ofstream(p) << "k: 2\n"; }
    auto f = YamlFile::load(p, diags);
    REQUIRE(f);
    CHECK(f->displayPath() == p.string());
    CHECK(f->rootNode().loc().line == 1);
    fs::remove(p);
    CHECK(!YamlFile::load(p, diags));
    CHECK(diags.hasErrors());
  }
}

TEST_CASE("MapReader::number", "[model]") {
  auto&& [diags, f, m] = TopReader("a: 2.5\nb: .nan\nc: -.inf\nd: 12\ne: abc\nf: \"3\"\ng: [1]\nh: 1e3\n");
  CHECK(m.number("a", 0) == 2.5);
  CHECK(m.number("missing", 7.0) == 7.0);
  CHECK(m.number("b", 1.0) == 1.0);
  CHECK(m.number("c", 1.0) == 1.0);
  CHECK(m.number("d", 1.0, 0, 10) == 1.0);
  CHECK(m.number("e", 1.0) == 1.0);
  CHECK(m.number("f", 1.0) == 1.0);
  CHECK(m.number("g", 1.0) == 1.0);
  CHECK(m.number("h", 1.0) == 1000.0);
  m.finish();
  REQUIRE(diags.items().size() == 6);
  CHECK(diags.items()[0].format().rfind("t.yaml:2:4: error: 'b' must be a finite number, got '.nan'", 0) == 0);
  checkMessages(diags, 1,
                {"'c' must be a finite number, got '-.inf'",
                 "'d' is 12, out of range [0, 10]",
                 "'e' must be a number, got 'abc'",
                 "'f' must be a number, got string '3'",
                 "'g' must be a number, got a sequence"});
}

TEST_CASE("MapReader::integer", "[model]") {
  auto&& [diags, f, m] = TopReader("a: 5\nb: 2.5\nc: -3\nd: 99999999999999999999\n");
  CHECK(m.integer("a", 0, 0, 10) == 5);
  CHECK(m.integer("b", 1) == 1);
  CHECK(m.integer("c", 1, 0) == 1);
  CHECK(m.integer("d", 1) == 1);
  m.finish();
  REQUIRE(diags.items().size() == 3);
  checkMessages(diags, 0,
                {"'b' must be an integer, got '2.5'",
                 "'c' is -3, must be at least 0",
                 "'d' must be an integer, got '99999999999999999999'"});
}

TEST_CASE("MapReader::finish", "[model]") {
  auto&& [diags, f, top] = TopReader("steps: 3\nsede: 4\nturtle:\n  angel: 20\n  extra: 1\n", "species file");
  CHECK(top.integer("steps", 0) == 3);
  top.integer("seed", 0);
  auto t = top.section("turtle");
  REQUIRE(t);
  MapReader turtle(*t, diags, "turtle");
  CHECK(turtle.number("angle", 25.0) == 25.0);
  turtle.allow({"extra"});
  turtle.finish();
  top.finish();
  REQUIRE(diags.items().size() == 2);
  CHECK(diags.items()[0].format().rfind("t.yaml:4:3: error: unknown key 'angel' in turtle (did you mean 'angle'?)", 0) ==
        0);
  CHECK(diags.items()[1].message == "unknown key 'sede' in species file (did you mean 'seed'?)");
  CHECK_THROWS_AS(diags.throwIfErrors(), InputError);
}

TEST_CASE("MapReader::typed", "[model]") {
  auto&& [diags, f, m] = TopReader(
      "b1: yes\nb2: maybe\ns: hello\nv: [1, 2, 3]\nv2: [1, 2]\nc1: '#ff8000'\nc2: [0.5, 2, 0]\n"
      "ch: rond\nsec: 5\nseq: [a, b]\nreq: ~\n");
  CHECK(m.boolean("b1", false));
  CHECK(!m.boolean("b2", false));
  CHECK(m.string("s") == "hello");
  CHECK(m.vec3("v", Vec3(0)) == Vec3(1, 2, 3));
  CHECK(m.vec3("v2", Vec3(9)) == Vec3(9));
  Vec3 c = m.color("c1", Vec3(0));
  CHECK(c.x == Approx(1.0));
  CHECK(c.y == Approx(0.2158605).epsilon(1e-4));  // sRGB 128 in linear light
  CHECK(c.z == Approx(0.0));
  CHECK(m.color("c2", Vec3(0)) == Vec3(0));
  CHECK(m.choice("ch", "box", {"box", "round"}) == "box");
  CHECK(!m.section("sec"));
  CHECK(m.sequence("seq").size() == 2);
  CHECK(!m.requiredString("req"));
  CHECK(!m.requiredString("absent"));
  m.finish();
  std::vector<std::string> msgs;
  for (const auto& d : diags.items()) msgs.push_back(d.message);
  REQUIRE(msgs.size() == 7);
  CHECK(msgs[0] == "'b2' must be true or false, got 'maybe'");
  CHECK(msgs[1] == "'v2' must be [x, y, z], got 2 elements");
  CHECK(msgs[2] == "'c2'[1] is 2, out of range [0, 1]");
  CHECK(msgs[3] == "'ch' must be one of box, round, got 'rond' (did you mean 'round'?)");
  CHECK(msgs[4] == "'sec' must be a map, got '5'");
  CHECK(msgs[5] == "'req' must be a string, got nothing");
  CHECK(msgs[6] == "missing required key 'absent' in test");
}

TEST_CASE("resolveReference", "[model]") {
  fs::path dir = fs::temp_directory_path() / "sprig_resolve_test";
  fs::remove_all(dir);
  fs::create_directories(dir / "lib/species");
  fs::create_directories(dir / "lib/grammars");
  { std::ofstream(dir / "lib/grammars/g.lsys") << "axiom: F\n"; }
  { std::ofstream(dir / "outside.lsys") << "axiom: F\n"; }
  DiagnosticList diags;
  auto f = YamlFile::parse("g: x\n", (dir / "lib/species/s.yaml").string(), diags);
  REQUIRE(f);
  YNode at = f->rootNode();
  PathPolicy policy;
  policy.root = dir / "lib";

  auto ok = resolveReference(at, "../grammars/g.lsys", policy, diags);
  REQUIRE(ok);
  CHECK(fs::equivalent(*ok, dir / "lib/grammars/g.lsys"));
  CHECK(!diags.hasErrors());

  CHECK(!resolveReference(at, "../../outside.lsys", policy, diags));
  CHECK(!resolveReference(at, (dir / "outside.lsys").string(), policy, diags));
  CHECK(!resolveReference(at, "https://example.com/g.lsys", policy, diags));
  CHECK(!resolveReference(at, "file:///etc/passwd", policy, diags));
  CHECK(!resolveReference(at, "../grammars/missing.lsys", policy, diags));
  REQUIRE(diags.items().size() == 5);
  CHECK(diags.items()[0].message.rfind("refusing path '../../outside.lsys': it leaves the library root", 0) == 0);
  CHECK(diags.items()[1].message.rfind("refusing absolute path", 0) == 0);
  CHECK(diags.items()[2].message == "refusing URI 'https://example.com/g.lsys': only local files can be referenced");
  CHECK(diags.items()[3].message.rfind("refusing URI 'file:///etc/passwd'", 0) == 0);
  CHECK(diags.items()[4].message.rfind("cannot find file '../grammars/missing.lsys'", 0) == 0);

  DiagnosticList diags2;
  policy.allowOutside = true;
  CHECK(resolveReference(at, "../../outside.lsys", policy, diags2));
  CHECK(resolveReference(at, (dir / "outside.lsys").string(), policy, diags2));
  CHECK(!diags2.hasErrors());
  fs::remove_all(dir);
}

TEST_CASE("pathRefusal: a missing file in the current folder is inside the root '.'", "[model]") {
  PathPolicy policy;  // root "."
  // weakly_canonical leaves a relative path that does not exist relative: it must be made
  // absolute first, or every missing name looks like an escape.
  CHECK(pathRefusal("hornbeem.lsys", "hornbeem.lsys", policy).empty());
  CHECK(pathRefusal("no/such/dir/x.lsys", "no/such/dir/x.lsys", policy).empty());
  CHECK(pathRefusal("../x.lsys", "../x.lsys", policy) ==
        "refusing path '../x.lsys': it leaves the library root '.' (pass --root FOLDER to read from a wider root, or --allow-outside-paths)");
  CHECK(pathRefusal("/etc/passwd", "/etc/passwd", policy).rfind("refusing absolute path '/etc/passwd'", 0) == 0);
  policy.allowOutside = true;
  CHECK(pathRefusal("/etc/passwd", "/etc/passwd", policy).empty());
}

TEST_CASE("defaultLibraryRoot", "[model]") {
  fs::path dir = fs::weakly_canonical(fs::temp_directory_path()) / "sprig_default_root_test";
  fs::remove_all(dir);
  fs::create_directories(dir / "marked/a/b");
  fs::create_directories(dir / "checkout/species/trees");
  fs::create_directories(dir / "plain/x");
  fs::create_directories(dir / "obj");
  { std::ofstream(dir / "marked/.sprig-root") << "\n"; }
  // A marker file at or above the species file's folder.
  CHECK(defaultLibraryRoot(dir / "marked/a/b/s.yaml") == dir / "marked");
  CHECK(defaultLibraryRoot(dir / "marked/s.yaml") == dir / "marked");
  // The parent of the species/ folder the file lies in, at any depth below it.
  CHECK(defaultLibraryRoot(dir / "checkout/species/s.yaml") == dir / "checkout");
  CHECK(defaultLibraryRoot(dir / "checkout/species/trees/s.yaml") == dir / "checkout");
  // Else the species file's own folder; a vlab object folder is its own root.
  CHECK(defaultLibraryRoot(dir / "plain/x/s.yaml") == dir / "plain/x");
  CHECK(defaultLibraryRoot(dir / "obj") == dir / "obj");
  fs::remove_all(dir);
}
