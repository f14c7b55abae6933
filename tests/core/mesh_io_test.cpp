#include <catch2/catch.hpp>

#include <tiny_gltf.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <sstream>

#include "core/atomic_file.h"
#include "core/image.h"
#include "core/mesh_io.h"
#include "tests/core/cube_mesh.h"

using namespace sprig;
namespace fs = std::filesystem;

namespace {

struct TempDir {
  fs::path path;
  TempDir() {
    path = fs::temp_directory_path() / ("sprig_mesh_io_test_" + std::to_string(getpid()));
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
  size_t entries() const { return size_t(std::distance(fs::directory_iterator(path), fs::directory_iterator())); }
};

template <class T>
T readRaw(const std::string& bytes, size_t offset) {
  T v;
  std::memcpy(&v, bytes.data() + offset, sizeof(T));
  return v;
}

/// The glTF binary file read back by TinyGLTF (which must succeed).
tinygltf::Model readGlb(const fs::path& file) {
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  REQUIRE(loader.LoadBinaryFromFile(&model, &err, &warn, file.string()));
  return model;
}

}  // namespace

TEST_CASE("writePly", "[core]") {
  TempDir dir;
  Mesh m = test::cube(true);
  fs::path file = dir.path / "cube.PLY";
  writeMesh(m, file);
  std::string bytes = readFile(file);

  size_t end = bytes.find("end_header\n");
  REQUIRE(end != std::string::npos);
  std::string header = bytes.substr(0, end);
  size_t body = end + std::strlen("end_header\n");
  CHECK(header.rfind("ply\nformat binary_little_endian 1.0\n", 0) == 0);
  CHECK(header.find("element vertex 8\n") != std::string::npos);
  CHECK(header.find("element face 12\n") != std::string::npos);
  CHECK(header.find("property float nx\n") != std::string::npos);
  CHECK(header.find("property float s\n") != std::string::npos);
  CHECK(header.find("property uchar red\n") != std::string::npos);
  CHECK(header.find("property uint material\n") != std::string::npos);

  // x y z nx ny nz s t (4 bytes each) r g b (1 byte each); faces: count, 3 indices, material.
  size_t vertexBytes = 8 * 4 + 3, faceBytes = 1 + 12 + 4;
  REQUIRE(bytes.size() == body + 8 * vertexBytes + 12 * faceBytes);
  for (size_t i = 0; i < 8; ++i) {
    size_t o = body + i * vertexBytes;
    CHECK(readRaw<float>(bytes, o) == m.positions[i].x);
    CHECK(readRaw<float>(bytes, o + 4) == m.positions[i].y);
    CHECK(readRaw<float>(bytes, o + 8) == m.positions[i].z);
    CHECK(readRaw<float>(bytes, o + 12) == m.normals[i].x);
    CHECK(readRaw<float>(bytes, o + 28) == m.uvs[i].y);
    CHECK(uint8_t(bytes[o + 32]) == (m.colors[i].x > 0 ? 255 : 0));
    CHECK(uint8_t(bytes[o + 33]) == 188);  // sRGB(0.5) = 0.7354 -> 188
  }
  for (size_t t = 0; t < 12; ++t) {
    size_t o = body + 8 * vertexBytes + t * faceBytes;
    CHECK(uint8_t(bytes[o]) == 3);
    CHECK(readRaw<uint32_t>(bytes, o + 1) == m.triangles[t].x);
    CHECK(readRaw<uint32_t>(bytes, o + 5) == m.triangles[t].y);
    CHECK(readRaw<uint32_t>(bytes, o + 9) == m.triangles[t].z);
    CHECK(readRaw<uint32_t>(bytes, o + 13) == m.materials[t]);
  }

  SECTION("without optional arrays only positions and faces are written") {
    writePly(test::cube(false), file);
    std::string plain = readFile(file);
    size_t e = plain.find("end_header\n") + std::strlen("end_header\n");
    CHECK(plain.find("nx") == std::string::npos);
    CHECK(plain.size() == e + 8 * 12 + 12 * 13);
  }
  SECTION("same mesh, same bytes") {
    writeMesh(m, dir.path / "again.ply");
    CHECK(readFile(dir.path / "again.ply") == bytes);
  }
}

TEST_CASE("writeObj", "[core]") {
  TempDir dir;
  Mesh m = test::cube(true);
  writeMesh(m, dir.path / "cube.obj");
  REQUIRE(fs::exists(dir.path / "cube.mtl"));
  CHECK(dir.entries() == 2);

  std::istringstream in(readFile(dir.path / "cube.obj"));
  std::vector<Vec3> v, vn;
  std::vector<Vec2> vt;
  std::vector<std::array<int, 9>> faces;
  std::vector<std::string> used;
  std::string line, mtllib;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string tag;
    ls >> tag;
    if (tag == "v") {
      Vec3 p, c;
      ls >> p.x >> p.y >> p.z >> c.x >> c.y >> c.z;
      CHECK(!ls.fail());
      v.push_back(p);
    } else if (tag == "vt") {
      Vec2 t;
      ls >> t.x >> t.y;
      vt.push_back(t);
    } else if (tag == "vn") {
      Vec3 n;
      ls >> n.x >> n.y >> n.z;
      vn.push_back(n);
    } else if (tag == "f") {
      std::array<int, 9> f{};
      char slash;
      for (int k = 0; k < 3; ++k) ls >> f[3 * k] >> slash >> f[3 * k + 1] >> slash >> f[3 * k + 2];
      CHECK(!ls.fail());
      faces.push_back(f);
    } else if (tag == "mtllib") {
      ls >> mtllib;
    } else if (tag == "usemtl") {
      std::string name;
      ls >> name;
      used.push_back(name);
    }
  }
  CHECK(mtllib == "cube.mtl");
  REQUIRE(v.size() == 8);
  REQUIRE(vt.size() == 8);
  REQUIRE(vn.size() == 8);
  REQUIRE(faces.size() == 12);
  for (size_t i = 0; i < 8; ++i) {
    CHECK(v[i] == m.positions[i]);  // shortest round-trip text parses back exactly
    CHECK(vt[i] == m.uvs[i]);
    CHECK(vn[i] == m.normals[i]);
  }
  for (size_t t = 0; t < 12; ++t)
    for (int k = 0; k < 3; ++k) {
      CHECK(faces[t][3 * k] == int(m.triangles[t][k]) + 1);
      CHECK(faces[t][3 * k + 1] == faces[t][3 * k]);
      CHECK(faces[t][3 * k + 2] == faces[t][3 * k]);
    }
  CHECK(used == std::vector<std::string>{"sprig_0", "sprig_1", "sprig_2"});
  std::string mtl = readFile(dir.path / "cube.mtl");
  for (const auto& name : used) CHECK(mtl.find("newmtl " + name + "\n") != std::string::npos);

  SECTION("plain mesh: v and f only, one material") {
    writeObj(test::cube(false), dir.path / "plain.obj");
    std::string text = readFile(dir.path / "plain.obj");
    CHECK(text.find("vn ") == std::string::npos);
    CHECK(text.find("\nf 1 3 4\n") != std::string::npos);
    CHECK(text.find("usemtl sprig\n") != std::string::npos);
    CHECK(readFile(dir.path / "plain.mtl").find("newmtl sprig\nKa 0 0 0\nKd 0.8 0.8 0.8\n") != std::string::npos);
  }
}

TEST_CASE("writeGlb", "[core]") {
  TempDir dir;
  Mesh m = test::cube(true);
  fs::path file = dir.path / "cube.glb";
  MeshWriteOptions opt;
  opt.baseColor = Vec3(0.25f, 0.5f, 0.75f);
  writeMesh(m, file, opt);
  std::string bytes = readFile(file);
  REQUIRE(bytes.size() > 20);
  CHECK(bytes.substr(0, 4) == "glTF");
  CHECK(readRaw<uint32_t>(bytes, 4) == 2);
  CHECK(readRaw<uint32_t>(bytes, 8) == bytes.size());

  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  REQUIRE(loader.LoadBinaryFromFile(&model, &err, &warn, file.string()));
  CHECK(err.empty());
  REQUIRE(model.meshes.size() == 1);
  REQUIRE(model.meshes[0].primitives.size() == 1);
  const auto& prim = model.meshes[0].primitives[0];
  CHECK(prim.mode == TINYGLTF_MODE_TRIANGLES);
  for (const char* attr : {"POSITION", "NORMAL", "TEXCOORD_0", "COLOR_0"}) {
    INFO(attr);
    REQUIRE(prim.attributes.count(attr) == 1);
    CHECK(model.accessors[prim.attributes.at(attr)].count == 8);
  }
  const auto& idx = model.accessors[prim.indices];
  CHECK(idx.count == 36);
  CHECK(idx.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT);
  const auto& pos = model.accessors[prim.attributes.at("POSITION")];
  CHECK(pos.minValues == std::vector<double>{0, 0, 0});
  CHECK(pos.maxValues == std::vector<double>{1, 1, 1});

  // The index data reads back exactly.
  const auto& view = model.bufferViews[idx.bufferView];
  const auto& data = model.buffers[view.buffer].data;
  std::vector<uint32_t> indices(36);
  std::memcpy(indices.data(), data.data() + view.byteOffset + idx.byteOffset, 36 * 4);
  for (size_t t = 0; t < 12; ++t)
    for (int k = 0; k < 3; ++k) CHECK(indices[3 * t + k] == m.triangles[t][k]);

  REQUIRE(model.materials.size() == 1);
  CHECK(model.materials[0].pbrMetallicRoughness.baseColorFactor[2] == Approx(0.75));
  CHECK(prim.material == 0);

  SECTION("an empty mesh still writes a valid file") {
    writeGlb(Mesh{}, dir.path / "empty.glb");
    tinygltf::Model empty;
    CHECK(loader.LoadBinaryFromFile(&empty, &err, &warn, (dir.path / "empty.glb").string()));
    CHECK(empty.meshes.empty());
  }
}

TEST_CASE("writeMesh::failures", "[core]") {
  TempDir dir;
  Mesh m = test::cube(true);
  SECTION("a missing folder throws and leaves nothing") {
    for (const char* name : {"a.ply", "a.obj", "a.glb"}) {
      INFO(name);
      CHECK_THROWS_AS(writeMesh(m, dir.path / "missing" / name), std::runtime_error);
      CHECK(!fs::exists(dir.path / "missing"));
      CHECK(dir.entries() == 0);
    }
  }
  SECTION("an unknown extension throws before writing") {
    CHECK_THROWS_AS(writeMesh(m, dir.path / "a.stl"), std::invalid_argument);
    CHECK(dir.entries() == 0);
  }
  SECTION("an invalid mesh throws and leaves an existing file as it was") {
    writeMesh(m, dir.path / "a.ply");
    std::string before = readFile(dir.path / "a.ply");
    Mesh bad = m;
    bad.triangles.push_back({0, 1, 8});
    CHECK_THROWS_AS(writeMesh(bad, dir.path / "a.ply"), std::invalid_argument);
    bad = m;
    bad.normals.pop_back();
    CHECK_THROWS_AS(writeMesh(bad, dir.path / "a.ply"), std::invalid_argument);
    CHECK(readFile(dir.path / "a.ply") == before);
    CHECK(dir.entries() == 1);
  }
}

namespace {

// Two parts: a textured-looking "wood" cube with vertex colours at half its base colour or
// brighter, and a "leaves" cube moved aside, double-sided, without vertex colours.
std::vector<ExportPart> twoParts() {
  ExportPart wood{"wood", test::cube(true), PartMaterial{"wood", Vec3(0.5f, 0.4f, 0.2f), 0.7f, false}};
  wood.mesh.materials.clear();
  for (size_t i = 0; i < wood.mesh.colors.size(); ++i)
    wood.mesh.colors[i] = i == 7 ? Vec3(0.6f, 0.2f, 0.1f) : Vec3(0.25f, 0.2f, 0.1f);
  ExportPart leaves{"leaves", test::cube(false), PartMaterial{"leaves", Vec3(0.1f, 0.4f, 0.05f), 0.5f, true}};
  for (auto& p : leaves.mesh.positions) p += Vec3(2, 0, 0);
  return {wood, leaves};
}

/// One quad "bark" and a 4 x 2 texture repeating along u: red on the top row, blue below.
ExportPart texturedQuad() {
  ExportPart quad;
  quad.name = "bark";
  quad.mesh.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
  quad.mesh.uvs = {Vec2(0.2f, 0), Vec2(0.6f, 0), Vec2(0.6f, 1), Vec2(0.2f, 1)};  // u spans < 0.5: no seam
  quad.mesh.colors.assign(4, Vec3(0.9f, 0.1f, 0.1f));  // brighter than the base colour: no COLOR_0, nothing clamped
  quad.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  auto tex = std::make_shared<PartTexture>();
  tex->image = Image(4, 2, Vec4(0, 0, 1, 1));
  for (int x = 0; x < 4; ++x) tex->image.set(x, 0, Vec4(1, 0, 0, 1));
  tex->seams.repeatU = true;
  quad.material = PartMaterial{"bark", Vec3(0.3f, 0.2f, 0.1f), 0.8f, false, tex};
  return quad;
}

}  // namespace

TEST_CASE("writeParts", "[core]") {
  TempDir dir;
  const std::vector<ExportPart> parts = twoParts();
  SECTION("glb: one named node, mesh and material per part; COLOR_0 relative to the base colour") {
    const fs::path file = dir.path / "parts.glb";
    writeParts(parts, file);
    const tinygltf::Model model = readGlb(file);
    REQUIRE(model.nodes.size() == 2);
    CHECK(model.nodes[0].name == "wood");
    CHECK(model.nodes[1].name == "leaves");
    REQUIRE(model.meshes.size() == 2);
    REQUIRE(model.materials.size() == 2);
    const auto& wood = model.materials[size_t(model.meshes[size_t(model.nodes[0].mesh)].primitives[0].material)];
    const auto& leaves = model.materials[size_t(model.meshes[size_t(model.nodes[1].mesh)].primitives[0].material)];
    CHECK(wood.name == "wood");
    CHECK(wood.pbrMetallicRoughness.baseColorFactor == std::vector<double>{0.5f, 0.4f, 0.2f, 1.0});
    CHECK_FALSE(wood.doubleSided);
    CHECK(leaves.pbrMetallicRoughness.baseColorFactor == std::vector<double>{0.1f, 0.4f, 0.05f, 1.0});
    CHECK(leaves.doubleSided);
    const auto& wp = model.meshes[size_t(model.nodes[0].mesh)].primitives[0];
    const auto& lp = model.meshes[size_t(model.nodes[1].mesh)].primitives[0];
    CHECK(lp.attributes.count("COLOR_0") == 0);
    REQUIRE(wp.attributes.count("COLOR_0") == 1);
    const auto& acc = model.accessors[size_t(wp.attributes.at("COLOR_0"))];
    const auto& view = model.bufferViews[size_t(acc.bufferView)];
    std::vector<Vec3> rel(8);
    std::memcpy(rel.data(), model.buffers[0].data.data() + view.byteOffset + acc.byteOffset, 8 * sizeof(Vec3));
    CHECK(rel[0].x == Approx(0.5));  // 0.25 / 0.5
    CHECK(rel[0].y == Approx(0.5));
    CHECK(rel[0].z == Approx(0.5));
    CHECK(rel[7].x == 1.0f);  // 0.6 / 0.5 clamped
    CHECK(rel[7].y == Approx(0.5));
    CHECK(clampedColorChannels(parts[0]) == 1);
    CHECK(clampedColorChannels(parts[1]) == 0);
    // The leaves' positions are the moved cube's.
    const auto& pos = model.accessors[size_t(lp.attributes.at("POSITION"))];
    CHECK(pos.minValues == std::vector<double>{2, 0, 0});
  }
  SECTION("obj: one object and material per part, indices continue across parts") {
    const fs::path file = dir.path / "parts.obj";
    writeParts(parts, file);
    const std::string obj = readFile(file), mtl = readFile(dir.path / "parts.mtl");
    CHECK(obj.find("mtllib parts.mtl\n") != std::string::npos);
    CHECK(obj.find("o wood\n") < obj.find("usemtl wood\n"));
    CHECK(obj.find("usemtl wood\n") < obj.find("o leaves\n"));
    CHECK(obj.find("o leaves\n") < obj.find("usemtl leaves\n"));
    // The leaves' first triangle (0 2 3 of the cube) follows the wood's 8 vertices.
    CHECK(obj.find("usemtl leaves\nf 9 11 12\n") != std::string::npos);
    CHECK(mtl.find("newmtl wood\nKa 0 0 0\nKd 0.5 0.4 0.2\n") != std::string::npos);
    CHECK(mtl.find("newmtl leaves\nKa 0 0 0\nKd 0.1 0.4 0.05\n") != std::string::npos);
  }
  SECTION("ply: a colour at every vertex, the part index per face, the parts named in the header") {
    const fs::path file = dir.path / "parts.ply";
    writeParts(parts, file);
    const std::string bytes = readFile(file);
    CHECK(bytes.find("comment part 0 wood\ncomment part 1 leaves\n") != std::string::npos);
    CHECK(bytes.find("element vertex 16\n") != std::string::npos);
    CHECK(bytes.find("property uchar red\n") != std::string::npos);
    CHECK(bytes.find("property uint material\n") != std::string::npos);
    // Vertex 8 (the first of the leaves) carries the leaves' base colour, sRGB-encoded. The
    // wood has normals and the leaves none, so the merged mesh keeps positions and colours
    // only: 15 bytes a vertex.
    const size_t body = bytes.find("end_header\n") + 11;
    const size_t v8 = body + 8 * 15 + 12;
    CHECK(uint8_t(bytes[v8]) == 89);       // linearToSrgb(0.1) * 255 = 89.04
    CHECK(uint8_t(bytes[v8 + 1]) == 170);  // linearToSrgb(0.4) * 255 = 169.6
    CHECK(uint8_t(bytes[v8 + 2]) == 63);   // linearToSrgb(0.05) * 255 = 63.2
    // The last face's material is the leaves' index, 1.
    CHECK(readRaw<uint32_t>(bytes, bytes.size() - 4) == 1);
  }
  SECTION("two parts of one name are refused, nothing written") {
    std::vector<ExportPart> same = parts;
    same[1].name = "wood";
    CHECK_THROWS_AS(writeParts(same, dir.path / "same.glb"), std::invalid_argument);
    CHECK(dir.entries() == 0);
  }
}

TEST_CASE("writeParts::texture: glb and obj", "[core]") {
  TempDir dir;
  const ExportPart quad = texturedQuad();
  CHECK(clampedColorChannels(quad) == 0);
  SECTION("glb: an embedded PNG as baseColorTexture, factor 1, the base colour in extras, no COLOR_0") {
    const fs::path file = dir.path / "t.glb";
    const auto reports = writeParts({quad}, file);
    REQUIRE(reports.size() == 1);
    CHECK(reports[0].textureWidth == 4);
    CHECK(reports[0].textureHeight == 2);
    const tinygltf::Model model = readGlb(file);
    REQUIRE(model.materials.size() == 1);
    const auto& pbr = model.materials[0].pbrMetallicRoughness;
    CHECK(pbr.baseColorFactor == std::vector<double>{1, 1, 1, 1});
    REQUIRE(pbr.baseColorTexture.index == 0);
    REQUIRE(model.textures.size() == 1);
    REQUIRE(model.images.size() == 1);
    const auto& image = model.images[size_t(model.textures[0].source)];
    CHECK(image.mimeType == "image/png");
    CHECK(image.bufferView >= 0);
    // TinyGLTF decodes the PNG (stb_image): 4 x 2, 8-bit sRGB red over blue.
    REQUIRE(image.width == 4);
    REQUIRE(image.height == 2);
    CHECK(int(image.image[0]) == 255);
    CHECK(int(image.image[size_t(image.component) * 4 + 2]) == 255);
    CHECK(int(image.image[size_t(image.component) * 4 + 0]) == 0);
    const auto& sampler = model.samplers[size_t(model.textures[0].sampler)];
    CHECK(sampler.wrapS == TINYGLTF_TEXTURE_WRAP_REPEAT);
    CHECK(sampler.wrapT == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE);
    const auto& extras = model.materials[0].extras.Get("sprigBaseColor");
    REQUIRE(extras.IsArray());
    CHECK(extras.Get(0).GetNumberAsDouble() == Approx(0.3));
    const auto& prim = model.meshes[0].primitives[0];
    CHECK(prim.attributes.count("COLOR_0") == 0);
    CHECK(prim.attributes.count("TEXCOORD_0") == 1);
    CHECK(dir.entries() == 1);  // the PNG went into the file, no temporary left beside it
  }
  SECTION("obj: the PNG beside it, map_Kd and Kd 1 in the MTL") {
    const fs::path file = dir.path / "t.obj";
    writeParts({quad}, file);
    CHECK(fs::exists(dir.path / "t_bark.png"));
    const std::string mtl = readFile(dir.path / "t.mtl");
    CHECK(mtl.find("newmtl bark\nKa 0 0 0\nKd 1 1 1\n") != std::string::npos);
    CHECK(mtl.find("map_Kd t_bark.png\n") != std::string::npos);
    CHECK(readFile(file).find("f 1/1 2/2 3/3\n") != std::string::npos);
    CHECK(dir.entries() == 3);
  }
}

TEST_CASE("writeParts::texture: clamping, missing uvs and cut-outs", "[core]") {
  TempDir dir;
  const ExportPart quad = texturedQuad();
  CHECK(clampedColorChannels(quad) == 0);
  SECTION("obj: -clamp on where the glTF sampler clamps both axes, not where one repeats") {
    ExportPart clamped = quad;
    auto clampedTex = std::make_shared<PartTexture>(*quad.material.texture);
    clampedTex->seams.repeatU = false;  // both axes clamp, as an atlas's and cpfg leaves' do
    clamped.material.texture = clampedTex;
    clamped.material.alphaCutoff = 0.1f;
    writeParts({clamped}, dir.path / "k.obj");
    CHECK(readFile(dir.path / "k.mtl").find("map_Kd -clamp on k_bark.png\nmap_d -clamp on k_bark.png\n") != std::string::npos);
    writeParts({clamped}, dir.path / "k.glb");
    const tinygltf::Model model = readGlb(dir.path / "k.glb");
    CHECK(model.samplers[0].wrapS == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE);
    CHECK(model.samplers[0].wrapT == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE);
    writeParts({quad}, dir.path / "r.obj");  // s repeats: MTL cannot clamp t alone
    CHECK(readFile(dir.path / "r.mtl").find("-clamp") == std::string::npos);
  }
  SECTION("a texture without uvs is refused, nothing written") {
    ExportPart bad = quad;
    bad.mesh.uvs.clear();
    CHECK_THROWS_AS(writeParts({bad}, dir.path / "bad.obj"), std::invalid_argument);
    CHECK(dir.entries() == 0);
  }
  SECTION("a cut-out: alpha kept (RGBA PNG), glTF MASK with its cutoff, MTL map_d, the sampler's filters") {
    ExportPart cut = quad;
    auto cutTex = std::make_shared<PartTexture>(*quad.material.texture);
    cutTex->image.set(1, 0, Vec4(1, 0, 0, 0));  // one transparent texel
    cutTex->magFilter = PartTexture::Filter::Nearest;
    cutTex->minFilter = PartTexture::Filter::Linear;
    cut.material.texture = cutTex;
    cut.material.alphaCutoff = 0.1f;
    const fs::path glb = dir.path / "c.glb";
    writeParts({cut}, glb);
    const tinygltf::Model model = readGlb(glb);
    CHECK(model.materials[0].alphaMode == "MASK");
    CHECK(model.materials[0].alphaCutoff == Approx(0.1));
    const auto& image = model.images[0];
    REQUIRE(image.component == 4);
    CHECK(int(image.image[3]) == 255);
    CHECK(int(image.image[4 + 3]) == 0);
    CHECK(model.samplers[0].magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST);
    CHECK(model.samplers[0].minFilter == TINYGLTF_TEXTURE_FILTER_LINEAR);
    const fs::path obj = dir.path / "c.obj";
    writeParts({cut}, obj);
    CHECK(readFile(dir.path / "c.mtl").find("map_Kd c_bark.png\nmap_d c_bark.png\n") != std::string::npos);
    const Image png = readImage(dir.path / "c_bark.png");
    CHECK(png.at(0, 0).a == 1.0f);
    CHECK(png.at(1, 0).a == 0.0f);
    // Opaque parts keep the default: OPAQUE, an RGB PNG (no map_d).
    writeParts({quad}, dir.path / "o.glb");
    const tinygltf::Model opaque = readGlb(dir.path / "o.glb");
    CHECK(opaque.materials[0].alphaMode == "OPAQUE");
    writeParts({quad}, dir.path / "o.obj");
    CHECK(readFile(dir.path / "o.mtl").find("map_d") == std::string::npos);
    CHECK(readImageInfo(dir.path / "o_bark.png").channels == 3);
  }
}

TEST_CASE("writeParts stores textures at kTexturePngLevel, 8-bit images as they are", "[core]") {
  TempDir dir;
  // One triangle with an atlas of 8 x 4 texels: an 8-bit colour image and an 8-bit normal map.
  ExportPart tri;
  tri.name = "leaf";
  tri.mesh.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  tri.mesh.normals.assign(3, Vec3(0, 0, 1));
  tri.mesh.triangles = {{0, 1, 2}};
  auto color = std::make_shared<PartTexture>(), normal = std::make_shared<PartTexture>();
  color->image8 = Image8(8, 4, 3, ImageEncoding::TextureMap);
  normal->image8 = Image8(8, 4, 3, ImageEncoding::Data);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x) {
      color->image8.set(x, y, Vec3(float(x) / 7.0f, float(y) / 3.0f, 0.25f));
      normal->image8.set(x, y, Vec3(0.5f, float(x) / 7.0f, 1.0f));
    }
  for (auto* tex : {color.get(), normal.get()}) {
    tex->atlas.values = {Vec2(0.1f, 0.1f), Vec2(0.9f, 0.1f), Vec2(0.1f, 0.9f)};
    tex->atlas.index = {0, 1, 2};
  }
  tri.material = PartMaterial{"leaf", Vec3(0.3f), 0.8f, false, color};
  tri.material.normalTexture = normal;
  const fs::path file = dir.path / "t.glb";
  const auto reports = writeParts({tri}, file);
  REQUIRE(reports.size() == 1);
  CHECK(reports[0].textureWidth == 8);
  const tinygltf::Model model = readGlb(file);
  REQUIRE(model.images.size() == 2);
  for (size_t i = 0; i < 2; ++i) {
    const Image8& written = i == 0 ? color->image8 : normal->image8;
    const tinygltf::BufferView& v = model.bufferViews[size_t(model.images[i].bufferView)];
    const std::string png(model.buffers[0].data.begin() + long(v.byteOffset),
                          model.buffers[0].data.begin() + long(v.byteOffset + v.byteLength));
    // zlib's header in the IDAT chunk: FLEVEL 1, the class of levels 2 to 5 (RFC 1950;
    // OpenImageIO's default, 6, is class 2).
    static_assert(kTexturePngLevel == 4, "the FLEVEL below is level 4's");
    const size_t idat = png.find("IDAT");
    REQUIRE(idat != std::string::npos);
    CHECK(((uint8_t(png[idat + 5]) >> 6) & 3) == 1);
    // The decoded PNG (stb_image's bytes, RGBA) is the image written, byte for byte.
    const tinygltf::Image& im = model.images[i];
    REQUIRE(im.width == 8);
    REQUIRE(im.height == 4);
    std::vector<uint8_t> rgb;
    for (size_t p = 0; p < 32; ++p)
      for (size_t c = 0; c < 3; ++c) rgb.push_back(im.image[p * size_t(im.component) + c]);
    CHECK(rgb == written.values);
  }
  SECTION("an 8-bit image in another encoding than its file's is refused") {
    auto wrong = std::make_shared<PartTexture>(*normal);
    wrong->image8.encoding = ImageEncoding::TextureMap;
    ExportPart bad = tri;
    bad.material.normalTexture = wrong;
    CHECK_THROWS_AS(writeParts({bad}, dir.path / "bad.glb"), std::invalid_argument);
    CHECK_FALSE(fs::exists(dir.path / "bad.glb"));
  }
  SECTION("OBJ: the same bytes beside it") {
    writeParts({tri}, dir.path / "t.obj");
    const Image back = readImage(dir.path / "t_leaf.png");
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 8; ++x) CHECK(back.at(x, y) == color->image8.at(x, y));
  }
}
