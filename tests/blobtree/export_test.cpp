#include <catch2/catch.hpp>

#include <tiny_gltf.h>
#include <unistd.h>

#include <filesystem>
#include <sstream>

#include "blobtree/blobtree.h"
#include "blobtree/compiled.h"
#include "blobtree/polygonize.h"
#include "core/atomic_file.h"
#include "core/mesh_io.h"

using namespace sprig;
using namespace sprig::blobtree;
namespace fs = std::filesystem;

TEST_CASE("polygonize::export", "[blobtree]") {
  // A ball on a stem: polygonized, then written in every format and read back.
  BlobTree tree;
  TextureAttr tex;
  tex.uvScale = Vec2(2.0f, 1.0f);
  std::vector<NodeId> kids = {tree.point(Vec3(0, 1, 0), 0.5f, tex), tree.cone(Vec3(0), Vec3(0, 1, 0), 0.2f, 0.1f, tex)};
  Mesh m = polygonize(compile(tree, tree.blend(kids)), PolygonizeOptions{.cellSize = 0.05f});
  REQUIRE(m.triangleCount() > 100);
  REQUIRE(m.normals.size() == m.vertexCount());
  REQUIRE(m.uvs.size() == m.vertexCount());

  fs::path dir = fs::temp_directory_path() / ("sprig_export_test_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);

  SECTION("PLY header counts match the mesh") {
    writeMesh(m, dir / "ball.ply");
    std::string bytes = readFile(dir / "ball.ply");
    CHECK(bytes.find("element vertex " + std::to_string(m.vertexCount()) + "\n") != std::string::npos);
    CHECK(bytes.find("element face " + std::to_string(m.triangleCount()) + "\n") != std::string::npos);
    size_t body = bytes.find("end_header\n") + 11;
    CHECK(bytes.size() == body + m.vertexCount() * 32 + m.triangleCount() * 13);
  }
  SECTION("OBJ reads back with the same counts") {
    writeMesh(m, dir / "ball.obj");
    std::istringstream in(readFile(dir / "ball.obj"));
    size_t v = 0, vn = 0, vt = 0, f = 0;
    std::string line;
    while (std::getline(in, line)) {
      if (line.rfind("v ", 0) == 0) ++v;
      else if (line.rfind("vn ", 0) == 0) ++vn;
      else if (line.rfind("vt ", 0) == 0) ++vt;
      else if (line.rfind("f ", 0) == 0) ++f;
    }
    CHECK(v == m.vertexCount());
    CHECK(vn == m.vertexCount());
    CHECK(vt == m.vertexCount());
    CHECK(f == m.triangleCount());
    CHECK(fs::exists(dir / "ball.mtl"));
  }
  SECTION("glb loads through TinyGLTF with the right accessor counts") {
    writeMesh(m, dir / "ball.glb");
    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    std::string err, warn;
    REQUIRE(loader.LoadBinaryFromFile(&model, &err, &warn, (dir / "ball.glb").string()));
    const auto& prim = model.meshes.at(0).primitives.at(0);
    CHECK(model.accessors[prim.attributes.at("POSITION")].count == m.vertexCount());
    CHECK(model.accessors[prim.attributes.at("NORMAL")].count == m.vertexCount());
    CHECK(model.accessors[prim.attributes.at("TEXCOORD_0")].count == m.vertexCount());
    CHECK(model.accessors[prim.indices].count == 3 * m.triangleCount());
  }
  fs::remove_all(dir);
}
