#include <catch2/catch.hpp>

#include <vector>

#include "blobtree/detail/marching_tets.h"

using namespace sprig;
using namespace sprig::blobtree::detail;

TEST_CASE("TetEmitter::edge", "[blobtree]") {
  // One active cell (index 0) whose corner 0 is inside and corners 1..7 outside: all seven
  // edges 0 -> d cross, numbered 0..6 by d.
  std::vector<uint8_t> crossMask{0xfe};
  std::vector<uint32_t> vertexBase{0, 7};
  std::vector<uint32_t> owners(8, kNoCell);
  owners[0] = 0;
  std::vector<glm::uvec3> tris(2);
  TetEmitter em{owners.data(), vertexBase.data(), crossMask.data(), tris.data()};
  SECTION("an edge from the low corner is numbered by its direction") {
    CHECK(em.edge(0, 1) == 0);
    CHECK(em.edge(0, 2) == 1);
    CHECK(em.edge(7, 0) == 6);
  }
  SECTION("an edge whose low end has no active cell throws instead of reading past the tables") {
    // Edge 1 -> 3 has its low end at corner 1, owned by the neighbour at +x: not active.
    // Before the fix the owner's crossMask entry was read before the kNoCell check, an
    // out-of-bounds read at index 2^32 − 1 (a crash or an AddressSanitizer report).
    CHECK_THROWS_AS(em.edge(1, 3), std::logic_error);
  }
  SECTION("an owner without a crossing on that edge throws") {
    crossMask[0] = 0x02;  // only edge 0 -> 1 crosses
    CHECK_THROWS_AS(em.edge(0, 2), std::logic_error);
  }
  SECTION("a tetrahedron with one corner inside gives one triangle") {
    const int t[4] = {0, 1, 3, 7};
    const bool in[4] = {true, false, false, false};
    owners[1] = owners[3] = 0;  // not used: every edge runs from corner 0
    em.run(t, in);
    CHECK(em.out == tris.data() + 1);
    glm::uvec3 tri = tris[0];
    std::vector<uint32_t> ids{tri.x, tri.y, tri.z};
    std::sort(ids.begin(), ids.end());
    CHECK(ids == std::vector<uint32_t>{0, 2, 6});  // edges 0->1, 0->3, 0->7
  }
}
