// cpfg's environmental programs (`-e FILE.e`): the environment file, the protocol's text,
// and derivations with Sprig's test program (tests/lsystem/enviro/) over pipes, files and
// shared memory, compared with the strings the real cpfg derived with the same program
// (tests/assets/cpfg/enviro/*/cpfg.str, commands in that folder's README).

#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "core/diagnostics.h"
#include "lsystem/cpfg_environment.h"
#include "lsystem/derive.h"
#include "lsystem/grammar.h"
#include "lsystem/view_file.h"
#include "tests/lsystem/cpfg_compare.h"
#include "tests/paths.h"
#include "tests/scratch_dir.h"

using namespace sprig;
using namespace sprig::lsystem;

namespace {

std::string enviroAsset(const std::string& name) {
  return std::string(SPRIG_SOURCE_DIR) + "/tests/assets/cpfg/enviro/" + name;
}

/// The test program (built beside sprig) on PATH, as vlab's programs are for cpfg.
void putTestProgramOnPath() {
  static bool done = false;
  if (done) return;
  const char* old = std::getenv("PATH");
  const std::string path = std::string(SPRIG_BINARY_DIR) + ":" + (old ? old : "/usr/bin:/bin");
  ::setenv("PATH", path.c_str(), 1);
  done = true;
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

/// No child left unreaped (the test process starts no other).
bool noChildLeft() { return ::waitpid(-1, nullptr, WNOHANG) == -1 && errno == ECHILD; }

/// The object in folder derived with its environment file, by Sprig.
ModuleString deriveWithEnvironment(const std::string& folder, const std::string& efile, int restarts = 0) {
  putTestProgramOnPath();
  const Grammar g = loadGrammar(enviroAsset(folder + "/plant.l"));
  const ViewFile view = loadViewFile(enviroAsset(folder + "/plant.v"));
  DeriveOptions opt;
  opt.queryTurtle = cpfgTurtleSettings(&view, TurtleSettings{});
  opt.environmentAfterEachStep = view.environmentBefore;
  opt.environment = std::make_shared<EnvironmentProgram>(readEnvironmentFile(enviroAsset(folder + "/" + efile)),
                                                         enviroAsset(folder));
  Deriver d(g, opt);
  for (int r = 0; r < restarts; ++r) {
    d.derive();
    d.restart();
  }
  return d.derive();
}

EnvironmentSpec specOf(const std::string& text) {
  test::TempDir dir("enviro_spec");
  const std::string path = dir.path.string() + "/x.e";
  std::ofstream(path) << text;
  return readEnvironmentFile(path);
}

}  // namespace

TEST_CASE("readEnvironmentFile", "[lsystem][cpfg][enviro]") {
  SECTION("cpfg's directives") {
    EnvironmentSpec s = specOf("executable: honda81 -e plant.e density.spec\ncommunication type: files 7\n"
                               "turtle position:P:%.4f %.4f %.0f\nturtle up: %g %g %g\nverbose: off\nfollowing module: no\n");
    CHECK(s.command == std::vector<std::string>{"honda81", "-e", "plant.e", "density.spec"});
    CHECK(s.transport == EnvironmentSpec::Transport::Files);
    CHECK(s.maxQueries == 7);
    CHECK(s.position == std::optional<std::string>("P:%.4f %.4f %.0f"));
    CHECK(s.up == std::optional<std::string>(" %g %g %g"));
    CHECK(!s.heading);
    CHECK(!s.followingModule);
    CHECK(specOf("executable: x &\n").command == std::vector<std::string>{"x"});
    CHECK(specOf("executable: x\n").maxQueries == 100);
    CHECK(specOf("executable: x\ncommunication type: memory\n").transport == EnvironmentSpec::Transport::Memory);
  }
  SECTION("errors name the line and the directive") {
    CHECK_THAT(errorOf([] { specOf("executable: x\ninterpreted modules: F\n"); }),
               Catch::Contains("x.e:2:1: error: cpfg's environment directive 'interpreted modules' (the turtle's geometry "
                               "of the module after ?E sent to the program) is not supported"));
    CHECK_THAT(errorOf([] { specOf("executable: x\nturtle positon: %g\n"); }),
               Catch::Contains("x.e:2:1: error: unknown directive 'turtle positon' in an environment file"));
    CHECK_THAT(errorOf([] { specOf("executable: x\nturtle position: %s\n"); }),
               Catch::Contains("x.e:2:1: error: 'turtle position:' must be a printf format with 1 to 3 floating "
                               "conversions (%f, %g, %e), got ' %s'"));
    // A NUL byte would end printf's format inside '%.3' (fuzz/regressions/enviro/nul_in_format.e).
    CHECK_THAT(errorOf([] { specOf(std::string("executable: x\nturtle heading: %.3\0%f %f\n", 40)); }),
               Catch::Contains("x.e:2:1: error: 'turtle heading:' must be a printf format with 1 to 3 floating"));
    CHECK_THAT(errorOf([] { specOf("turtle position: %g\n"); }),
               Catch::Contains("x.e: error: the environment file names no program ('executable:')"));
    CHECK_THAT(errorOf([] { specOf("executable: x\ncommunication type: sockets\n"); }),
               Catch::Contains("error: cpfg's communication type 'sockets' is not supported"));
  }
}

TEST_CASE("formatEnvironmentQuery and parseEnvironmentAnswer", "[lsystem][cpfg][enviro]") {
  EnvironmentSpec s;
  s.position = "P:%.4f %.4f %.0f";
  s.heading = "%g %g %g";
  EnvironmentQuery q;
  q.distance = 12;
  q.params = {0.5f, 2.f};
  q.next = "F";
  q.nextParams = {1.25f};
  q.position = {1.f, -2.5f, 0.4f};
  q.heading = {0.f, 1.f, 0.f};
  CHECK(formatEnvironmentQuery(s, q) == "12 E(0.5,2)F(1.25)\nP:1.0000 -2.5000 0\n0 1 0\n");
  s.followingModule = false;
  q.params.clear();
  CHECK(formatEnvironmentQuery(s, q) == "12 E\nP:1.0000 -2.5000 0\n0 1 0\n");

  auto a = parseEnvironmentAnswer("40 E(0.3,,7)");
  REQUIRE(a);
  CHECK(a->distance == 40);
  REQUIRE(a->params.size() == 3);
  CHECK(*a->params[0] == 0.3f);
  CHECK(!a->params[1]);
  CHECK(*a->params[2] == 7.f);
  CHECK(parseEnvironmentAnswer("3 E")->params.empty());
  CHECK(!parseEnvironmentAnswer("E(1)"));
  CHECK(!parseEnvironmentAnswer("3 E(1"));
  CHECK(!parseEnvironmentAnswer("3 E(x)"));
  CHECK(!parseEnvironmentAnswer("3 F(1)"));
}

TEST_CASE("cpfg parity: environmental programs", "[lsystem][cpfg][enviro]") {
  SECTION("pipes, chunks of 3 queries, position and heading") {
    test::checkSameAsCpfg(deriveWithEnvironment("field_pipes", "field.e"), loadGrammar(enviroAsset("field_pipes/plant.l")).symbols(),
                          test::readCpfgString(enviroAsset("field_pipes/cpfg.str")));
  }
  SECTION("the view file's 'environment display: before': the final string holds answers") {
    test::checkSameAsCpfg(deriveWithEnvironment("field_before", "field.e"), loadGrammar(enviroAsset("field_before/plant.l")).symbols(),
                          test::readCpfgString(enviroAsset("field_before/cpfg.str")));
  }
  SECTION("shared memory and semaphores, no following module") {
    test::checkSameAsCpfg(deriveWithEnvironment("field_memory", "field.e"), loadGrammar(enviroAsset("field_memory/plant.l")).symbols(),
                          test::readCpfgString(enviroAsset("field_memory/cpfg.str")));
  }
  SECTION("files and semaphores, chunks of 7: collisions") {
    const std::string want = test::readCpfgString(enviroAsset("occupancy_files/cpfg.str"));
    const Grammar grammar = loadGrammar(enviroAsset("occupancy_files/plant.l"));
    const SymbolTable& symbols = grammar.symbols();
    test::checkSameAsCpfg(deriveWithEnvironment("occupancy_files", "occupancy.e"), symbols, want);
    // a derivation started over restarts the program (its cells are free again)
    test::checkSameAsCpfg(deriveWithEnvironment("occupancy_files", "occupancy.e", 1), symbols, want);
    // no file of the exchange is left in the object's folder
    for (const auto& e : std::filesystem::directory_iterator(enviroAsset("occupancy_files")))
      CHECK(e.path().filename().string().rfind(".to_field", 0) != 0);
  }
  CHECK(noChildLeft());
}

TEST_CASE("EnvironmentProgram: a program that fails", "[lsystem][cpfg][enviro]") {
  putTestProgramOnPath();
  test::TempDir tmp("enviro_fail");
  const std::string folder = tmp.path.string();
  const std::string grammar = folder + "/plant.l";
  std::ofstream(grammar) << "derivation length: 2\naxiom: A\nA --> F?E(0)A\n";
  auto run = [&](const std::string& executable, const std::string& transport, double timeout = 10) {
    const std::string efile = folder + "/t.e";
    std::ofstream(efile) << "executable: " << executable << "\ncommunication type: " << transport
                         << "\nturtle position: %g %g %g\n";
    return errorOf([&] {
      DeriveOptions opt;
      opt.environment = std::make_shared<EnvironmentProgram>(readEnvironmentFile(efile), folder, EnvironmentOptions{timeout});
      Deriver d(loadGrammar(grammar), opt);
      d.derive();
    });
  };
  const std::string who = "sprig: error: environmental program 'sprig_enviro_test' (" + folder + "/t.e) ";
  for (const char* transport : {"pipes", "files", "memory"}) {
    INFO(transport);
    CHECK(run("sprig_enviro_test exit", transport) == who + "exited (status 4) before it answered");
    CHECK(run("sprig_enviro_test garbage", transport) ==
          who + "sent a malformed answer 'this is no answer' (expected 'distance E(values)')");
    CHECK(run("sprig_enviro_test wrongdist", transport) ==
          "sprig: error: environmental program 'sprig_enviro_test' answered for the module at distance 99991, which is no ?E "
          "module it was sent");
    CHECK(run("sprig_enviro_test hang", transport, 0.3) == who + "did not answer within 0.3 s (--enviro-timeout)");
    CHECK(run("sprig_enviro_test nostart", transport, 0.3) == who + "did not start within 0.3 s (--enviro-timeout)");
    CHECK(noChildLeft());
  }
  CHECK(run("no_such_program_here", "pipes") ==
        "sprig: error: environmental program 'no_such_program_here' (" + folder + "/t.e) was not found on PATH");
  CHECK(run("./missing", "files") ==
        "sprig: error: environmental program './missing' (" + folder + "/t.e) is not an executable file in " + folder);
  CHECK(noChildLeft());
}
