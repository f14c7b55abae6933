#include <catch2/catch.hpp>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/mesh_io.h"
#include "core/polymesh.h"
#include "core/srgb.h"
#include "tests/core/cube_mesh.h"
#include "tests/scratch_dir.h"
#include "tests/paths.h"

using namespace sprig;
namespace fs = std::filesystem;

namespace {

// The same cube as six quads in OFF.
constexpr const char* kQuadCubeOff = R"(OFF
# a unit cube of quads
8 6 12
0 0 0
1 0 0
0 1 0
1 1 0
0 0 1
1 0 1
0 1 1
1 1 1
4 0 2 3 1
4 4 5 7 6
4 0 1 5 4
4 2 6 7 3
4 0 4 6 2
4 1 3 7 5
)";

// Every diagnostic of what parse() throws as `file:line:col: error: message`, without the
// source line and caret.
template <class F>
std::vector<std::string> errorsOf(F&& parse) {
  try {
    parse();
  } catch (const InputError& e) {
    std::vector<std::string> out;
    for (Diagnostic d : e.diagnostics()) {
      d.sourceLine.clear();
      out.push_back(d.format());
    }
    return out;
  }
  FAIL("no InputError");
  return {};
}

std::vector<std::string> errorsOf(std::string_view bytes, MeshFileFormat format, const PolyMeshLimits& limits = {}) {
  return errorsOf([&] { parsePolyMesh(bytes, format, "m", limits); });
}

using Strings = std::vector<std::string>;

// The faces of a mesh as vertex lists, for comparisons.
std::vector<std::vector<uint32_t>> facesOf(const PolyMesh& m) {
  std::vector<std::vector<uint32_t>> faces;
  size_t c = 0;
  for (uint32_t n : m.faceSizes) {
    faces.emplace_back(m.faceVertices.begin() + long(c), m.faceVertices.begin() + long(c + n));
    c += n;
  }
  return faces;
}

PolyTopology topologyOf(const PolyMesh& m) {
  DiagnosticList d;
  PolyTopology t = checkPolyMesh(m, d);
  CHECK(d.items().empty());
  return t;
}

// Little-endian binary PLY with float x y z and uchar/uint faces (big: swap every value).
std::string binaryPly(const std::vector<Vec3>& v, const std::vector<std::vector<uint32_t>>& faces, bool big) {
  std::string out = std::string("ply\nformat ") + (big ? "binary_big_endian" : "binary_little_endian") +
                    " 1.0\nelement vertex " + std::to_string(v.size()) +
                    "\nproperty float x\nproperty float y\nproperty float z\nelement face " + std::to_string(faces.size()) +
                    "\nproperty list uchar uint vertex_indices\nend_header\n";
  auto put = [&](const void* p, size_t n) {
    char b[8];
    std::memcpy(b, p, n);
    if (big) std::reverse(b, b + n);
    out.append(b, n);
  };
  for (const Vec3& p : v) put(&p.x, 4), put(&p.y, 4), put(&p.z, 4);
  for (const auto& f : faces) {
    out.push_back(char(f.size()));
    for (uint32_t i : f) put(&i, 4);
  }
  return out;
}

}  // namespace

TEST_CASE("readPolyMesh round trip of Sprig's writers", "[core]") {
  test::TempDir dir("polymesh");
  for (bool attributes : {false, true}) {
    DYNAMIC_SECTION("attributes " << attributes) {
      Mesh cube = test::cube(attributes);
      std::vector<std::vector<uint32_t>> faces;
      for (const auto& t : cube.triangles) faces.push_back({t.x, t.y, t.z});
      for (const char* name : {"cube.ply", "cube.obj", "CUBE.OBJ", "cube.off"}) {
        fs::path path = dir.path / name;
        if (std::string(name) == "cube.off") {
          std::string off = attributes ? "COFF\n" : "OFF\n";
          off += "8 12 0\n";
          auto put = [&](long v) { off += std::to_string(v), off += ' '; };
          for (size_t i = 0; i < 8; ++i) {
            for (int k = 0; k < 3; ++k) put(long(cube.positions[i][k]));
            if (attributes)
              for (int c = 0; c < 3; ++c) put(std::lround(linearToSrgb(cube.colors[i][c]) * 255));
            off += '\n';
          }
          for (const auto& t : cube.triangles) {
            put(3), put(t.x), put(t.y), put(t.z);
            off += '\n';
          }
          writeFileAtomic(path, off);
        } else {
          writeMesh(cube, path);
        }
        PolyMesh m = readPolyMesh(path, name);
        CHECK(m.positions == cube.positions);
        CHECK(facesOf(m) == faces);
        REQUIRE(m.faceLocs.size() == 12);
        REQUIRE(m.colors.size() == (attributes ? 8u : 0u));
        for (size_t i = 0; i < m.colors.size(); ++i)
          for (int c = 0; c < 3; ++c) CHECK(m.colors[i][c] == Approx(cube.colors[i][c]).margin(0.003));
        PolyTopology t = topologyOf(m);
        CHECK(t.closed());
        CHECK(t.manifold());
      }
    }
  }
  SECTION("face locations") {
    writeMesh(test::cube(false), dir.path / "cube.obj");
    PolyMesh m = readPolyMesh(dir.path / "cube.obj", "c.obj");
    // "# written by Sprig", mtllib, 8 vertices, usemtl: the first face is on line 12.
    CHECK(m.faceLocs[0].file == "c.obj");
    CHECK(m.faceLocs[0].line == 12);
    CHECK(m.faceLocs[0].col == 1);
    writePly(test::cube(false), dir.path / "cube.ply");
    PolyMesh b = readPolyMesh(dir.path / "cube.ply");
    CHECK(b.faceLocs[0].file == (dir.path / "cube.ply").string());
    CHECK(b.faceLocs[0].line == 0);
    CHECK(b.faceLocs[0].col == 0);
  }
  SECTION("unknown extension and missing file") {
    CHECK_THROWS_WITH(readPolyMesh("x/mesh.stl"), "cannot tell the mesh format of 'x/mesh.stl': use the extension .obj, .ply or .off");
    CHECK(errorsOf([&] { readPolyMesh(dir.path / "none.off", "none.off"); }) ==
          Strings{"none.off: error: cannot find file"});
  }
}

TEST_CASE("parsePolyMesh OBJ", "[core]") {
  SECTION("corner forms, negative indices, ignored records") {
    PolyMesh m = parsePolyMesh(R"(# comment
mtllib a.mtl
o thing
g group
s 1
usemtl red
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vn 0 0 1
f 1/1/1 2//1 3/1 4
f -4 -2 -1   # a comment after a face
)",
                               MeshFileFormat::Obj, "a.obj");
    CHECK(facesOf(m) == std::vector<std::vector<uint32_t>>{{0, 1, 2, 3}, {0, 2, 3}});
    CHECK(m.faceLocs[1].line == 14);
    CHECK(m.colors.empty());
    CHECK(m.cornerCount() == 7);
    Box3 b = m.bounds();
    CHECK(b.lo == Vec3(0));
    CHECK(b.hi == Vec3(1, 1, 0));
  }
  SECTION("errors, each at its place") {
    CHECK(errorsOf("v 0 0 0\nv 1 nan 0\nv 1e999 0 0\nv 0 0\nf 1 2\n", MeshFileFormat::Obj) ==
          Strings{"m:2:5: error: 'nan' is not a finite number", "m:3:3: error: '1e999' is not a finite number",
                  "m:4:1: error: a vertex needs x y z or x y z r g b, found 2 numbers",
                  "m:5:1: error: a face needs at least 3 vertices, found 2"});
    CHECK(errorsOf("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\nf 1 2 0\nf -4 1 2\nf 1/x 2 3\n", MeshFileFormat::Obj) ==
          Strings{"m:5:7: error: vertex index 0: OBJ indices start at 1 (or count back from -1)",
                  "m:6:3: error: vertex index -4 reaches before the first vertex (3 vertices so far)",
                  "m:7:3: error: expected a face corner v, v/vt, v//vn or v/vt/vn, found '1/x'",
                  "m:4:7: error: vertex index 4 is out of range: the file has 3 vertices"});
    CHECK(errorsOf("v 0 0 0\n  usemt red\nl 1 2\n", MeshFileFormat::Obj) ==
          Strings{"m:2:3: error: unknown OBJ record 'usemt' (did you mean 'usemtl'?): Sprig reads v and f and ignores "
                  "vt, vn, o, g, s, usemtl and mtllib",
                  "m:3:1: error: unknown OBJ record 'l' (did you mean 'o'?): Sprig reads v and f and ignores vt, vn, o, g, s, usemtl and mtllib"});
    CHECK(errorsOf("v 0 0 0 1 0 0\nv 1 0 0\nv 0 0 0 2 0 0\n", MeshFileFormat::Obj) ==
          Strings{"m:3:9: error: color '2' is outside [0, 1]",
                  "m:2:1: error: this vertex has no color but the vertex at line 1 has one: give every vertex a color or none"});
  }
  SECTION("a NUL byte or binary data is one error, without the bytes") {
    std::string text = "v 0 0 0\nv 1 ";
    text += '\0';
    text += "\x01\x02garbage\n";
    Strings errors = errorsOf(text, MeshFileFormat::Obj);
    CHECK(errors == Strings{"m:2:5: error: byte 0x00 (NUL) at byte offset 12 is not text: an OBJ file must be UTF-8 text (is this a binary file?)"});
    try {
      parsePolyMesh(text, MeshFileFormat::Obj, "m");
    } catch (const InputError& e) {
      CHECK(std::string(e.what()).find('\x01') == std::string::npos);
    }
    CHECK(errorsOf(binaryPly({Vec3(0)}, {}, false), MeshFileFormat::Obj).size() == 1);
  }
  SECTION("limits") {
    PolyMeshLimits limits;
    limits.maxVertices = 2;
    CHECK(errorsOf("v 0 0 0\nv 1 0 0\nv 0 1 0\n", MeshFileFormat::Obj, limits) ==
          Strings{"m:3:1: error: more than 2 vertices (3): the limit is PolyMeshLimits::maxVertices = 2"});
    limits = {};
    limits.maxFileBytes = 10;
    CHECK(errorsOf("v 0 0 0\nv 1 0 0\n", MeshFileFormat::Obj, limits) ==
          Strings{"m: error: the file has 16 bytes, more than the limit of 10 bytes (PolyMeshLimits::maxFileBytes)"});
  }
  SECTION("at most kMaxPolyMeshErrors errors") {
    std::string text;
    for (int i = 0; i < 100; ++i) text += "v x 0 0\n";
    Strings errors = errorsOf(text, MeshFileFormat::Obj);
    REQUIRE(errors.size() == kMaxPolyMeshErrors);
    CHECK(errors.back() == "m:50:3: error: too many errors (50); stopping");
  }
}

TEST_CASE("parsePolyMesh PLY", "[core]") {
  std::vector<Vec3> v = {Vec3(0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0)};
  std::vector<std::vector<uint32_t>> faces = {{0, 1, 3, 2}};
  SECTION("binary, both byte orders") {
    for (bool big : {false, true}) {
      PolyMesh m = parsePolyMesh(binaryPly(v, faces, big), MeshFileFormat::Ply, "q.ply");
      CHECK(m.positions == v);
      CHECK(facesOf(m) == faces);
      PolyTopology t = topologyOf(m);
      CHECK(t.boundaryEdges == 4);
    }
  }
  SECTION("ASCII, other types, skipped elements and properties, float colors") {
    PolyMesh m = parsePolyMesh(R"(ply
format ascii 1.0
comment skipped elements and properties
element material 1
property list uchar float weights
property uchar id
element vertex 3
property double x
property short y
property float nx
property int z
property float red
property float green
property float blue
element face 1
property uchar flags
property list int ushort vertex_index
property float quality
end_header
2 0.5 0.25 7
0.5 -2 0 3 1 0.5 0
1.5 2 0 3 0 0 1
0 2 0 -4 0.25 0.25 0.25
9 3 0 1 2 0.5
)",
                               MeshFileFormat::Ply, "a.ply");
    CHECK(m.positions == std::vector<Vec3>{{0.5f, -2, 3}, {1.5f, 2, 3}, {0, 2, -4}});
    CHECK(m.colors == std::vector<Vec3>{{1, 0.5f, 0}, {0, 0, 1}, {0.25f, 0.25f, 0.25f}});
    CHECK(facesOf(m) == std::vector<std::vector<uint32_t>>{{0, 1, 2}});
    CHECK(m.faceLocs[0].line == 24);
    CHECK(m.faceLocs[0].col == 1);
  }
  SECTION("truncated binary data") {
    std::string bytes = binaryPly(v, {{0, 1, 3, 2}, {0, 1, 2}}, false);
    size_t header = bytes.find("end_header\n") + 11;
    CHECK(errorsOf(bytes.substr(0, bytes.size() - 5), MeshFileFormat::Ply) ==
          Strings{"m: error: face 1 (byte " + std::to_string(header + 48 + 17) +
                  "): list count 3 for 'vertex_indices' needs more data than the file holds (truncated?)"});
    CHECK(errorsOf(bytes.substr(0, bytes.size() - 13), MeshFileFormat::Ply) ==
          Strings{"m: error: face 1 (byte " + std::to_string(header + 48 + 17) + "): the file ends inside face 1 of 2 (truncated?)"});
    CHECK(errorsOf(bytes + "xyz", MeshFileFormat::Ply) ==
          Strings{"m: error: 3 bytes follow the last element (byte " + std::to_string(bytes.size()) +
                  "): the header's counts do not match the data"});
  }
  SECTION("counts beyond the file size or the limits fail before allocating") {
    std::string head = "ply\nformat binary_little_endian 1.0\nelement vertex 4294967295\nproperty float x\nproperty float y\n"
                       "property float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n";
    CHECK(errorsOf(head + std::string(20, 'x'), MeshFileFormat::Ply) ==
          Strings{"m:3:16: error: more than 50000000 vertices (4294967295): the limit is PolyMeshLimits::maxVertices = 50000000"});
    std::string small = head;
    small.replace(small.find("4294967295"), 10, "1000");
    CHECK(errorsOf(small + std::string(20, 'x'), MeshFileFormat::Ply) ==
          Strings{"m:3:16: error: element 'vertex' declares 1000 entries of at least 12 bytes each, but the file has 20 "
                  "bytes after its header (truncated, or a wrong count?)"});
  }
  SECTION("bad values and indices") {
    const std::string kOneVertexHead =
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n";
    std::vector<Vec3> bad = v;
    bad[2].y = std::numeric_limits<float>::quiet_NaN();
    std::string bytes = binaryPly(bad, {{0, 1, 3, 9}}, false);
    size_t header = bytes.find("end_header\n") + 11;
    CHECK(errorsOf(bytes, MeshFileFormat::Ply) ==
          Strings{"m: error: vertex 2 (byte " + std::to_string(header + 24) + "): property 'y' is not a finite number",
                  "m: error: face 0 (byte " + std::to_string(header + 48) +
                      "): vertex index 9 is out of range: the file has 4 vertices"});
    CHECK(errorsOf(kOneVertexHead + "element face 1\nproperty list char int vertex_indices\nend_header\n0 0 inf\n-1\n",
                   MeshFileFormat::Ply) == Strings{"m:10:5: error: 'inf' is not a finite number"});
    CHECK(errorsOf(kOneVertexHead + "element face 2\nproperty list char int vertex_indices\nend_header\n0 0 0\n-1\n2 0 0\n",
                   MeshFileFormat::Ply) == Strings{"m:11:1: error: bad list count -1 for 'vertex_indices'"});
    CHECK(errorsOf(kOneVertexHead + "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n2 0 0\n",
                   MeshFileFormat::Ply) == Strings{"m:11:1: error: a face needs at least 3 vertices, found 2"});
  }
  SECTION("header errors") {
    CHECK(errorsOf("solid x\n", MeshFileFormat::Ply) == Strings{"m:1:1: error: not a PLY file: the first line must be 'ply'"});
    CHECK(errorsOf("ply\nformat ascii 1.0\nelement vertex 0\n", MeshFileFormat::Ply) ==
          Strings{"m:1:1: error: the PLY header has no 'end_header' line"});
    CHECK(errorsOf("ply\nformat ascii 1.0\nelement vertex 0\nproperty flaot x\nend_header\n", MeshFileFormat::Ply) ==
          Strings{"m:4:10: error: unknown PLY type 'flaot'"});
    CHECK(errorsOf("ply\nformat ascii 1.0\nelemnt vertex 0\nend_header\n", MeshFileFormat::Ply) ==
          Strings{"m:3:1: error: unknown PLY header line 'elemnt' (did you mean 'element'?)"});
    CHECK(errorsOf("ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\n"
                   "end_header\n",
                   MeshFileFormat::Ply) ==
          Strings{"m:1:1: error: the PLY file has no 'face' element: Sprig reads meshes, not point clouds"});
    CHECK(errorsOf("ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\nproperty ushort red\n"
                   "end_header\n",
                   MeshFileFormat::Ply) == Strings{"m:5:1: error: color property 'red' must be uchar or float"});
  }
}

TEST_CASE("parsePolyMesh OFF", "[core]") {
  SECTION("a quad cube is closed and manifold") {
    PolyMesh m = parsePolyMesh(kQuadCubeOff, MeshFileFormat::Off, "cube.off");
    CHECK(m.positions.size() == 8);
    CHECK(m.faceCount() == 6);
    CHECK(m.cornerCount() == 24);
    CHECK(m.faceLocs[5].line == 17);
    PolyTopology t = topologyOf(m);
    CHECK(t.closed());
    CHECK(t.manifold());
    Mesh tri = triangulate(m);
    CHECK(tri.triangleCount() == 12);
    CHECK(signedVolume(tri) == Approx(1.0));
    MeshTopology tt = analyzeTopology(tri);
    CHECK(tt.closed());
    CHECK(tt.manifold());
    PolyMesh back = toPolyMesh(tri);
    CHECK(back.faceCount() == 12);
    CHECK(back.faceLocs.empty());
    CHECK(topologyOf(back).closed());
  }
  SECTION("counts on the header line, COFF colors as bytes or floats, face colors") {
    PolyMesh m = parsePolyMesh("COFF 3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0\n0 1 0 0.5 0.5 0.5 1.0\n3 0 1 2 1 0 0\n",
                               MeshFileFormat::Off, "c.off");
    REQUIRE(m.colors.size() == 3);
    CHECK(m.colors[0] == Vec3(1, 0, 0));
    CHECK(m.colors[1] == Vec3(0, 1, 0));
    CHECK(m.colors[2].x == Approx(srgbToLinear(0.5f)));
  }
  SECTION("errors") {
    CHECK(errorsOf("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", MeshFileFormat::Off) ==
          Strings{"m:6:7: error: vertex index 3 is out of range: the file has 3 vertices"});
    CHECK(errorsOf("NOFF\n", MeshFileFormat::Off) ==
          Strings{"m:1:1: error: the OFF variant 'NOFF' is not supported: Sprig reads OFF and COFF"});
    CHECK(errorsOf("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n# the faces are missing\n", MeshFileFormat::Off) ==
          Strings{"m:7:1: error: the file ends after 0 of 1 faces"});
    CHECK(errorsOf("OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2 0.5 0.5\n3 0 1 2\n", MeshFileFormat::Off) ==
          Strings{"m:4:3: error: 'nan' is not a finite number",
                  "m:6:1: error: this face has 3 vertices but its line holds 5 values (expected the indices and 0, 1, 3 or 4 color values)",
                  "m:7:1: error: unexpected '3' after the last face: the header's counts do not match the data"});
    CHECK(errorsOf("OFF\n20000000 20000000 0\n0 0 0\n", MeshFileFormat::Off) ==
          Strings{"m:2:1: error: the header declares 20000000 vertices and 20000000 faces, more than the 6 bytes that "
                  "follow can hold (truncated, or a wrong count?)"});
    PolyMeshLimits limits;
    limits.maxFaces = 1;
    CHECK(errorsOf("OFF\n3 2 0\n", MeshFileFormat::Off, limits) ==
          Strings{"m:2:1: error: more than 1 faces (2): the limit is PolyMeshLimits::maxFaces = 1"});
  }
}

TEST_CASE("checkPolyMesh", "[core]") {
  SECTION("an open grid counts its boundary edges") {
    // 3 x 2 quads on a 4 x 3 vertex grid: 2 * (3 + 2) boundary edges.
    std::string off = "OFF\n12 6 0\n";
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 4; ++x) off += std::to_string(x) + " " + std::to_string(y) + " 0\n";
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 3; ++x) {
        int a = y * 4 + x;
        off += "4 " + std::to_string(a) + " " + std::to_string(a + 1) + " " + std::to_string(a + 5) + " " + std::to_string(a + 4) + "\n";
      }
    PolyTopology t = topologyOf(parsePolyMesh(off, MeshFileFormat::Off, "grid.off"));
    CHECK(t.boundaryEdges == 10);
    CHECK(!t.closed());
    CHECK(t.manifold());
  }
  SECTION("a third face on an edge is an error at that face") {
    PolyMesh m = parsePolyMesh("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\n  f 1 2 5\n",
                               MeshFileFormat::Obj, "fan.obj");
    DiagnosticList d;
    PolyTopology t = checkPolyMesh(m, d);
    CHECK(t.nonManifoldEdges == 1);
    CHECK(!t.manifold());
    REQUIRE(d.items().size() == 1);
    CHECK(d.items()[0].format() ==
          "fan.obj:8:3: error: this face is the third on the edge between vertices 0 and 1 (0-based) (the others are at "
          "line 6 and line 7): a base mesh must be manifold");
  }
  SECTION("a flipped face is an error at its location") {
    std::string off = kQuadCubeOff;
    off.replace(off.find("4 1 3 7 5"), 9, "4 5 7 3 1");
    PolyMesh m = parsePolyMesh(off, MeshFileFormat::Off, "flip.off");
    DiagnosticList d;
    PolyTopology t = checkPolyMesh(m, d);
    CHECK(t.inconsistentEdges == 4);
    CHECK(t.closed());
    REQUIRE(d.items().size() == 4);
    CHECK(d.items()[0].loc.line == 17);
    CHECK(d.items()[0].loc.col == 1);
    CHECK(d.items()[0].message ==
          "this face runs along the edge between vertices 1 and 3 (0-based) in the same direction as the face at line 12: "
          "one of them is flipped (faces must be counter-clockwise seen from outside)");
  }
  SECTION("repeated vertices and bad indices; faces without locations are named") {
    PolyMesh m;
    m.positions = {Vec3(0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
    m.faceSizes = {3, 3, 2};
    m.faceVertices = {0, 1, 1, 0, 1, 7, 0, 1};
    DiagnosticList d;
    checkPolyMesh(m, d);
    REQUIRE(d.items().size() == 3);
    CHECK(d.items()[0].format() == "error: face 0: the face repeats vertex 1 (0-based)");
    CHECK(d.items()[1].format() == "error: face 1: vertex index 7 is out of range (3 vertices)");
    CHECK(d.items()[2].format() == "error: face 2: a face needs at least 3 vertices, found 2");
  }
}

TEST_CASE("readPolyMesh of CGAL's free meshes", "[core]") {
  const fs::path tarball = "/usr/share/doc/libcgal-demo/data.tar.gz";
  if (!fs::exists(tarball)) {
    WARN("SKIP: " << tarball << " is missing (scripts/install-deps.sh installs libcgal-demo)");
    return;
  }
  test::TempDir dir("cgal-meshes");
  fs::path out = dir.path / "meshes";
  std::string cmd = std::string("bash '") + SPRIG_SOURCE_DIR + "/scripts/extract-meshes.sh' '" + out.string() + "'";
  REQUIRE(std::system(cmd.c_str()) == 0);
  struct Expected {
    const char* file;
    size_t vertices, faces, boundaryEdges;
  };
  const Expected expected[] = {
      {"mannequin-devil.off", 12977, 25888, 64}, {"head.off", 1487, 2918, 58},  {"fandisk.off", 6475, 12946, 0},
      {"torus_quad.off", 25, 25, 0},             {"sphere.off", 162, 320, 0},   {"cactus.off", 620, 1236, 0},
      {"mushroom.off", 2337, 4608, 64},
  };
  for (const Expected& e : expected) {
    INFO(e.file);
    PolyMesh m = readPolyMesh(out / e.file, e.file);
    CHECK(m.positions.size() == e.vertices);
    CHECK(m.faceCount() == e.faces);
    PolyTopology t = topologyOf(m);
    CHECK(t.boundaryEdges == e.boundaryEdges);
    CHECK(t.manifold());
  }
  // A second run finds everything up to date and prints nothing.
  std::string again = cmd + " > '" + (dir.path / "log").string() + "' 2>&1";
  REQUIRE(std::system(again.c_str()) == 0);
  CHECK(readFile(dir.path / "log").empty());
}
