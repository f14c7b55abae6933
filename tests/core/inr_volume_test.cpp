#include <catch2/catch.hpp>

#include <cstring>
#include <string>
#include <vector>

#include "core/inr_volume.h"

using namespace sprig;

namespace {

// An INR file: header lines padded to 256 bytes, then the voxel bytes.
std::string inr(const std::string& lines, const std::string& voxels) {
  std::string h = "#INRIMAGE-4#{\n" + lines;
  const std::string end = "##}\n";
  while ((h.size() + end.size()) % 256 != 0) h += '\n';
  return h + end + voxels;
}

std::string floats(const std::vector<float>& v) {
  std::string s(v.size() * 4, '\0');
  std::memcpy(s.data(), v.data(), s.size());
  return s;
}

std::string errorOf(const std::string& bytes) {
  try {
    parseInrVolume(bytes, "v.inr");
  } catch (const InputError& e) {
    Diagnostic d = e.diagnostics().front();
    d.sourceLine.clear();
    return d.format();
  }
  return "no error";
}

}  // namespace

TEST_CASE("INR volumes: header, voxel types and byte order") {
  SECTION("float little-endian, voxel size and origin") {
    const ScalarVolume v = parseInrVolume(
        inr("XDIM=2\nYDIM=1\nZDIM=2\nVDIM=1\nTYPE=float\nPIXSIZE=32 bits\nCPU=decm\nVX=0.5\nVY=1\nVZ=2\nTZ=-3\n",
            floats({1, 2, 3, 4})),
        "v.inr");
    CHECK(v.dims == std::array<int, 3>{2, 1, 2});
    CHECK(v.voxel == std::array<double, 3>{0.5, 1, 2});
    CHECK(v.origin == std::array<double, 3>{0, 0, -3});
    CHECK(v.at(1, 0, 0) == 2.0f);
    CHECK(v.at(0, 0, 1) == 3.0f);
  }
  SECTION("unsigned and signed fixed, big-endian 16 bits") {
    const std::string be = std::string("\x01\x02", 2) + std::string("\xff\xfe", 2);
    const ScalarVolume u =
        parseInrVolume(inr("XDIM=2\nYDIM=1\nZDIM=1\nTYPE=unsigned fixed\nPIXSIZE=16 bits\nCPU=sun\n", be), "v.inr");
    CHECK(u.values == std::vector<float>{258.0f, 65534.0f});
    const ScalarVolume s =
        parseInrVolume(inr("XDIM=2\nYDIM=1\nZDIM=1\nTYPE=signed fixed\nPIXSIZE=16 bits\nCPU=sgi\n", be), "v.inr");
    CHECK(s.values == std::vector<float>{258.0f, -2.0f});
    const ScalarVolume b =
        parseInrVolume(inr("XDIM=1\nYDIM=1\nZDIM=2\nTYPE=unsigned fixed\nPIXSIZE=8 bits\nSCALE=2**0\n", "\x07\xc8"), "v.inr");
    CHECK(b.values == std::vector<float>{7.0f, 200.0f});
  }
  SECTION("errors at their line and column") {
    CHECK(errorOf("P5\n") == "v.inr:1:1: error: not an INRIMAGE-4 volume: the file must start with '#INRIMAGE-4#{'");
    CHECK(errorOf(inr("XDIM=2\nYDIM=0\n", "")) == "v.inr:3:6: error: YDIM=0 is outside 1..4096 (VolumeLimits::maxDimension)");
    CHECK(errorOf(inr("XDIM=1\nYDIM=1\nZDIM=1\nTYPE=float\nPIXSIZE=32 bits\nVDIM=3\n", "")) ==
          "v.inr:7:6: error: VDIM=3: only scalar volumes (VDIM=1) are read");
    CHECK(errorOf(inr("XDIM=1\nYDIM=1\nZDIM=1\nTYPE=float\nPIXSIZE=32 bits\nSCALE=2**3\n", "")) ==
          "v.inr:7:7: error: SCALE=2**3: fixed-point scaling is not implemented (only 2**0)");
    CHECK(errorOf(inr("XDIM=1\nYDIM=1\nZDIM=1\nTYPE=float\nPIXSIZE=32 bits\nCOLOR=red\n", "")) ==
          "v.inr:7:1: error: unknown INR header key 'COLOR'");
    CHECK(errorOf(inr("XDIM=1\nYDIM=1\nZDIM=1\nTYPE=float\nPIXSIZE=16 bits\n", "")) ==
          "v.inr:6:1: error: a float volume has PIXSIZE 32 or 64 bits");
    CHECK(errorOf(inr("XDIM=1\nYDIM=1\nTYPE=float\nPIXSIZE=32 bits\n", "")).find("the header lacks ZDIM") != std::string::npos);
    CHECK(errorOf(inr("XDIM=2\nYDIM=1\nZDIM=1\nTYPE=float\nPIXSIZE=32 bits\n", floats({1}))) ==
          "v.inr: error: the header describes 8 bytes of voxels but 4 follow it");
    CHECK(errorOf(inr("XDIM=1\nYDIM=1\nZDIM=1\nTYPE=float\nPIXSIZE=32 bits\n", floats({NAN}))) ==
          "v.inr: error: voxel 0 is not a finite number");
    CHECK(errorOf(inr("XDIM=1\nYDIM\x01=1\n", "")) == "v.inr:3:5: error: byte 1 is not text: the INR header must be text");
    CHECK(errorOf("#INRIMAGE-4#{\nXDIM=1\n") == "v.inr:3:1: error: the header ends without '##}' and a newline");
  }
  SECTION("the voxel limit is checked before allocating") {
    VolumeLimits limits;
    limits.maxVoxels = 7;
    try {
      parseInrVolume(inr("XDIM=2\nYDIM=2\nZDIM=2\nTYPE=float\nPIXSIZE=32 bits\n", ""), "v.inr", limits);
      FAIL("no error");
    } catch (const InputError& e) {
      CHECK(std::string(e.what()).find("the volume has 8 voxels, more than the limit of 7 (VolumeLimits::maxVoxels)") !=
            std::string::npos);
    }
  }
}
