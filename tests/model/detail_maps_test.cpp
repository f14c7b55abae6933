#include <catch2/catch.hpp>

#include <tiny_gltf.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "core/atomic_file.h"
#include "core/mesh_corners.h"
#include "core/mesh_io.h"
#include "core/parallel.h"
#include "model/detail_maps.h"
#include "model/lod.h"
#include "model/mesh_parts.h"
#include "tests/model/read_glb.h"

using namespace sprig;
namespace fs = std::filesystem;

namespace {

// The full surface: z = kAmp·sin(2π·kWaves·x) over the unit square (ridges along y).
constexpr float kAmp = 0.02f, kWaves = 2.0f;

Vec3 ridgeNormal(float x) {
  const float slope = kAmp * 2.0f * float(kPi) * kWaves * std::cos(2.0f * float(kPi) * kWaves * x);
  return glm::normalize(Vec3(-slope, 0.0f, 1.0f));
}

// An n x n grid of the unit square (two triangles a cell, counter-clockwise seen from +z),
// at height z(x) with its analytic normals and a colour that varies with x.
Mesh grid(int n, float amplitude, float lo = 0.0f, float hi = 1.0f) {
  Mesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const float x = lo + (hi - lo) * float(i) / float(n), y = lo + (hi - lo) * float(j) / float(n);
      m.positions.emplace_back(x, y, amplitude * std::sin(2.0f * float(kPi) * kWaves * x));
      m.normals.push_back(amplitude > 0 ? ridgeNormal(x) : Vec3(0, 0, 1));
      m.colors.emplace_back(x, 0.5f, 0.2f);
    }
  auto at = [n](int i, int j) { return uint32_t(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      m.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      m.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return m;
}

// The image texel (x, y from the top row) of texel (i, j) of triangle t's patch, and the
// barycentric point of its centre (bakeAtlas's layout); false when the centre lies outside
// the triangle (a gutter texel).
bool patchTexel(const AtlasLayout& l, size_t t, int i, int j, int& x, int& y, Vec3& bary) {
  const double leg = double(l.cell - 3);
  const double l1 = (i + 0.5 - 1.5) / leg, l2 = (j + 0.5 - 1.5) / leg;
  x = int(t % size_t(l.columns)) * l.cell + i;
  y = l.height() - 1 - (int(t / size_t(l.columns)) * l.cell + j);
  bary = Vec3(float(1 - l1 - l2), float(l1), float(l2));
  return l1 >= 0 && l2 >= 0 && l1 + l2 <= 1;
}

// grid(n, amplitude) coloured by an image over its own uvs, uv = (x, y): no vertex colours.
Mesh texturedGrid(int n, float amplitude) {
  Mesh m = grid(n, amplitude);
  m.colors.clear();
  for (const Vec3& p : m.positions) m.uvs.emplace_back(p.x, p.y);
  return m;
}

// The float values of accessor `index` of a glb (tightly packed floats).
const float* accessorFloats(const tinygltf::Model& m, int index) {
  const tinygltf::Accessor& a = m.accessors[size_t(index)];
  const tinygltf::BufferView& v = m.bufferViews[size_t(a.bufferView)];
  return reinterpret_cast<const float*>(m.buffers[0].data.data() + v.byteOffset + a.byteOffset);
}

struct TempDir {
  fs::path path = fs::temp_directory_path() / ("sprig_detail_maps_test_" + std::to_string(getpid()));
  TempDir() {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
};

}  // namespace

TEST_CASE("bakeDetailMaps", "[model][lod]") {
  // 32 flat triangles inside the full surface's square: the ridges simplified away (and no
  // ray along the full mesh's open border, where a hit may be missed).
  const Mesh low = grid(4, 0.0f, 0.05f, 0.95f);
  const AtlasLayout layout = atlasLayout(low.triangles.size());
  REQUIRE(layout.cell == kAtlasMaxCell);

  SECTION("a sine ridge decodes to its analytic normal") {
    const DetailSurface full(grid(256, kAmp), Vec3(0.5f));
    const DetailMaps maps = bakeDetailMaps(low, Vec3(0.5f), full, 0.05f, true);
    REQUIRE(maps.normal);
    REQUIRE(maps.color);
    // Stored 8-bit as the glb holds them: 3 bytes a texel, no float image.
    CHECK(maps.normal->image8.encoding == ImageEncoding::Data);
    CHECK(maps.color->image8.encoding == ImageEncoding::TextureMap);
    CHECK(maps.normal->image8.values.size() == size_t(layout.width()) * size_t(layout.height()) * 3);
    CHECK(maps.normal->image.pixels.empty());
    CHECK(maps.color->image.pixels.empty());
    CHECK(maps.texels == low.triangles.size() * 105);  // the texels inside a 16-texel patch's triangle
    CHECK(maps.hits == maps.texels);  // every texel lies above or below the ridge
    size_t checked = 0;
    double worstDeg = 0, worstColor = 0;
    for (size_t t = 0; t < low.triangles.size(); ++t)
      for (int j = 0; j < layout.cell; ++j)
        for (int i = 0; i < layout.cell; ++i) {
          int x = 0, y = 0;
          Vec3 b;
          if (!patchTexel(layout, t, i, j, x, y, b)) continue;
          const glm::uvec3& tri = low.triangles[t];
          const Vec3 P[3] = {low.positions[tri.x], low.positions[tri.y], low.positions[tri.z]};
          const Vec3 p = b.x * P[0] + b.y * P[1] + b.z * P[2];
          // The texel's frame: the writer's tangent (the atlas maps corner 1 along +s, corner
          // 2 along +t), bitangent cross(N, T)·w, N the flat low normal.
          const Vec2 uv[3] = {Vec2(0.0f), Vec2(1.0f, 0.0f), Vec2(0.0f, 1.0f)};
          const glm::vec4 T = cornerTangent(P, uv, Vec3(0, 0, 1));
          REQUIRE(std::abs(T.w) == 1.0f);
          const Vec3 N(0, 0, 1), Tx(T), B = glm::cross(N, Tx) * T.w;
          // +x of the map along increasing s (corner 1), +y up the image (corner 2).
          REQUIRE(glm::dot(Tx, glm::normalize(P[1] - P[0])) == Approx(1.0f));
          REQUIRE(glm::dot(B, P[2] - P[0]) > 0.0f);
          const Vec3 enc = Vec3(maps.normal->image8.at(x, y)) * 2.0f - Vec3(1.0f);  // glTF's decoding
          const Vec3 object = glm::normalize(enc.x * Tx + enc.y * B + enc.z * N);
          const double deg = std::acos(std::min(1.0f, glm::dot(object, ridgeNormal(p.x)))) * 180.0 / kPi;
          worstDeg = std::max(worstDeg, deg);
          worstColor = std::max(worstColor, double(std::abs(maps.color->image8.at(x, y).r - p.x)));
          ++checked;
        }
    INFO("worst angle " << worstDeg << " degrees, worst colour " << worstColor);
    CHECK(checked > 32 * 60);
    // 8-bit quantization (1/127 per component: about 0.5 degrees) and the full mesh's
    // interpolated normals (256 cells across 2 waves: about 0.1 degrees); the ridge tilts
    // the normal by up to 14 degrees.
    CHECK(worstDeg < 1.0);
    // The full mesh's colours at the hit, x there, in 8-bit sRGB (half a step is at most
    // 0.0045 in linear values below 1).
    CHECK(worstColor < 1e-3 + 0.0045);
  }

  SECTION("a flat full mesh gives (128, 128, 255) everywhere; a miss is flat too") {
    const DetailSurface flat(grid(64, 0.0f), Vec3(0.5f));
    const DetailMaps maps = bakeDetailMaps(low, Vec3(0.5f), flat, 0.05f, false);
    REQUIRE(maps.normal);
    CHECK(!maps.color);
    const Vec3 expected(128.0f / 255.0f, 128.0f / 255.0f, 1.0f);
    CHECK(encodeTangentNormal(Vec3(0, 0, 1)) == expected);
    for (size_t t = 0; t < low.triangles.size(); ++t)
      for (int j = 0; j < layout.cell; ++j)
        for (int i = 0; i < layout.cell; ++i) {
          int x = 0, y = 0;
          Vec3 b;
          patchTexel(layout, t, i, j, x, y, b);
          REQUIRE(Vec3(maps.normal->image8.at(x, y)) == expected);
        }
    // Out of reach: the full surface 1 above the low one, the rays reach 0.5.
    Mesh above = grid(8, 0.0f);
    for (Vec3& p : above.positions) p.z += 1.0f;
    const DetailMaps missed = bakeDetailMaps(low, Vec3(0.5f), DetailSurface(above, Vec3(0.5f)), 0.5f, true);
    CHECK(missed.hits == 0);
    CHECK(Vec3(missed.normal->image8.at(0, layout.height() - 1)) == expected);
    int x = 0, y = 0;
    Vec3 b;
    patchTexel(layout, 0, 1, 1, x, y, b);  // corner 0 of triangle 0: the low mesh's own colour
    // The byte the float image's PNG held at that texel.
    const Image8& colors = missed.color->image8;
    CHECK(int(colors.values[(size_t(y) * size_t(colors.width) + size_t(x)) * 3]) ==
          int(textureMapByte(low.colors[low.triangles[0].x].r)));
  }
}

TEST_CASE("buildLodChain detail maps in .glb", "[model][lod]") {
  ExportPart ridge{"ridge", grid(48, kAmp), PartMaterial{"ridge", Vec3(0.4f, 0.3f, 0.2f), 0.7f, false}};
  REQUIRE(atlasVertexColors(ridge) > 0);
  LodMapReport report;
  const std::vector<LodLevel> levels = buildLodChain({ridge}, 2000, nullptr, &report);
  REQUIRE(levels.size() >= 2);
  CHECK(report.maps == levels.size());  // LOD0 was simplified too
  CHECK(report.hits > report.texels * 9 / 10);
  for (const LodLevel& level : levels) {
    REQUIRE(level.parts[0].material.normalTexture);
    CHECK(level.parts[0].material.texture->isAtlas());
  }
  TempDir dir;
  auto write = [&](int threads) {
    ThreadLimit limit(threads);
    const std::vector<LodLevel> again = buildLodChain({ridge}, 2000);
    const fs::path file = dir.path / ("ridge_" + std::to_string(threads) + ".glb");
    writeLevels(again, file);
    return file;
  };
  const fs::path one = write(1), two = write(2);
  CHECK(readFile(one) == readFile(two));
  CHECK(readFile(one.parent_path() / "ridge_1_lod1.glb") == readFile(two.parent_path() / "ridge_2_lod1.glb"));

  const tinygltf::Model m = test::readGlb(one);
  size_t primitives = 0;
  for (const tinygltf::Mesh& mesh : m.meshes)
    for (const tinygltf::Primitive& p : mesh.primitives) {
      ++primitives;
      REQUIRE(p.attributes.count("TANGENT"));
      REQUIRE(p.attributes.count("NORMAL"));
      const tinygltf::Material& mat = m.materials[size_t(p.material)];
      CHECK(mat.normalTexture.index >= 0);
      CHECK(mat.pbrMetallicRoughness.baseColorTexture.index >= 0);
      const tinygltf::Accessor& a = m.accessors[size_t(p.attributes.at("TANGENT"))];
      REQUIRE(a.type == TINYGLTF_TYPE_VEC4);
      REQUIRE(a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT);
      const tinygltf::Accessor& na = m.accessors[size_t(p.attributes.at("NORMAL"))];
      const tinygltf::BufferView& v = m.bufferViews[size_t(a.bufferView)];
      const tinygltf::BufferView& nv = m.bufferViews[size_t(na.bufferView)];
      const auto* t = reinterpret_cast<const float*>(m.buffers[0].data.data() + v.byteOffset + a.byteOffset);
      const auto* n = reinterpret_cast<const float*>(m.buffers[0].data.data() + nv.byteOffset + na.byteOffset);
      for (size_t i = 0; i < a.count; ++i) {
        const Vec3 tx(t[4 * i], t[4 * i + 1], t[4 * i + 2]), nx(n[3 * i], n[3 * i + 1], n[3 * i + 2]);
        REQUIRE(glm::length(tx) == Approx(1.0f).margin(1e-5));
        REQUIRE(std::abs(t[4 * i + 3]) == 1.0f);
        REQUIRE(std::abs(glm::dot(tx, nx)) < 1e-4f);  // perpendicular to the vertex normal
      }
    }
  CHECK(primitives == levels.size());
  CHECK(m.images.size() == 2 * levels.size());  // a colour atlas and a normal map per level
}

TEST_CASE("buildLodChain gives a part's own image a normal map with coordinates of its own", "[model][lod]") {
  // A 64 x 64 image over the ridged square's own uvs (u, v) = (x, y), as single-bark wood,
  // a whorl without growth lines and cpfg's textures have.
  auto own = std::make_shared<PartTexture>();
  own->image = Image(64, 64, Vec4(0.3f, 0.5f, 0.2f, 1.0f));
  ExportPart ridge{"ridge", texturedGrid(48, kAmp), PartMaterial{"ridge", Vec3(0.4f, 0.3f, 0.2f), 0.7f, false, own}};
  LodMapReport report;
  Vec3 moved(0.0f);
  const std::vector<LodLevel> levels = buildLodChain({ridge}, 2000, &moved, &report);
  REQUIRE(levels.size() >= 2);
  CHECK(report.maps == levels.size());  // every level simplified, every level a normal map
  CHECK(report.hits > report.texels * 9 / 10);
  for (const LodLevel& level : levels) {
    const ExportPart& low = level.parts[0];
    CHECK(low.material.texture == own);  // the image itself, over the level's own uvs
    REQUIRE(low.material.normalTexture);
    REQUIRE(low.material.normalTexture->isAtlas());
    CHECK(low.material.normalTexture->atlas.index.size() == low.mesh.triangles.size() * 3);
  }
  TempDir dir;
  writeLevels(levels, dir.path / "own.glb");
  SECTION("glb: the image through TEXCOORD_0, the normal map through TEXCOORD_1, tangents of the normal map's") {
    const tinygltf::Model m = test::readGlb(dir.path / "own.glb");
    size_t primitives = 0;
    for (const tinygltf::Mesh& mesh : m.meshes)
      for (const tinygltf::Primitive& p : mesh.primitives) {
        ++primitives;
        const tinygltf::Material& mat = m.materials[size_t(p.material)];
        CHECK(mat.pbrMetallicRoughness.baseColorTexture.texCoord == 0);
        CHECK(mat.normalTexture.texCoord == 1);
        REQUIRE(p.attributes.count("TEXCOORD_0"));
        REQUIRE(p.attributes.count("TEXCOORD_1"));
        REQUIRE(p.attributes.count("TANGENT"));
        const size_t n = m.accessors[size_t(p.attributes.at("POSITION"))].count;
        const float* pos = accessorFloats(m, p.attributes.at("POSITION"));
        const float* uv0 = accessorFloats(m, p.attributes.at("TEXCOORD_0"));
        const float* uv1 = accessorFloats(m, p.attributes.at("TEXCOORD_1"));
        const float* nrm = accessorFloats(m, p.attributes.at("NORMAL"));
        const float* tan = accessorFloats(m, p.attributes.at("TANGENT"));
        // The image's uv is the square's (x, y) where the vertex was (glTF's t from the top).
        for (size_t i = 0; i < n; ++i) {
          REQUIRE(uv0[2 * i] == Approx(pos[3 * i] - moved.x).margin(1e-5));
          REQUIRE(uv0[2 * i + 1] == Approx(1.0f - (pos[3 * i + 1] - moved.y)).margin(1e-5));
          REQUIRE(uv1[2 * i] >= 0.0f);
          REQUIRE(uv1[2 * i] <= 1.0f);
        }
        // Each corner's tangent follows the normal map's coordinates (TEXCOORD_1), not the image's.
        const tinygltf::Accessor& ia = m.accessors[size_t(p.indices)];
        const tinygltf::BufferView& iv = m.bufferViews[size_t(ia.bufferView)];
        const auto* idx = reinterpret_cast<const uint32_t*>(m.buffers[0].data.data() + iv.byteOffset + ia.byteOffset);
        for (size_t t = 0; t < ia.count / 3; ++t) {
          Vec3 P[3];
          Vec2 uv[3];
          for (int k = 0; k < 3; ++k) {
            const uint32_t v = idx[3 * t + size_t(k)];
            P[k] = Vec3(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]);
            uv[k] = Vec2(uv1[2 * v], 1.0f - uv1[2 * v + 1]);
          }
          for (int k = 0; k < 3; ++k) {
            const uint32_t v = idx[3 * t + size_t(k)];
            const glm::vec4 expected = cornerTangent(P, uv, Vec3(nrm[3 * v], nrm[3 * v + 1], nrm[3 * v + 2]));
            REQUIRE(glm::dot(Vec3(expected), Vec3(tan[4 * v], tan[4 * v + 1], tan[4 * v + 2])) == Approx(1.0f).margin(1e-4));
            REQUIRE(tan[4 * v + 3] == expected.w);
          }
        }
      }
    CHECK(primitives == levels.size());
    // The image once (shared by the levels), a normal map per level.
    CHECK(m.images.size() == 1 + levels.size());
  }
  SECTION("a normal map of its own whose corners do not fit the triangles is refused, nothing written") {
    ExportPart bad = levels[0].parts[0];
    auto normal = std::make_shared<PartTexture>(*bad.material.normalTexture);
    normal->atlas.index.pop_back();
    bad.material.normalTexture = normal;
    CHECK_THROWS_AS(writeParts({bad}, dir.path / "bad.glb"), std::invalid_argument);
    CHECK(!fs::exists(dir.path / "bad.glb"));
  }
  SECTION("OBJ gives a corner one uv: the image is written, the normal map is not") {
    writeLevels(levels, dir.path / "own.obj");
    const std::string mtl = readFile(dir.path / "own.mtl");
    CHECK(mtl.find("map_Kd") != std::string::npos);
    CHECK(mtl.find("norm") == std::string::npos);
    CHECK(!fs::exists(dir.path / "own_ridge_normal.png"));
    for (const fs::path& f : partFiles(levels[0].parts, dir.path / "own.obj")) CHECK(fs::exists(f));
  }
}

TEST_CASE("writeParts normal map in OBJ", "[model][lod]") {
  ExportPart ridge{"ridge", grid(48, kAmp), PartMaterial{"ridge", Vec3(0.4f, 0.3f, 0.2f), 0.7f, false}};
  REQUIRE(atlasVertexColors(ridge) > 0);
  const std::vector<LodLevel> levels = buildLodChain({ridge}, 2000);
  REQUIRE(levels.size() >= 2);
  TempDir dir;
  writeLevels(levels, dir.path / "r.obj");
  const std::string mtl = readFile(dir.path / "r.mtl");
  CHECK(mtl.find("norm -clamp on r_ridge_normal.png") != std::string::npos);
  CHECK(fs::exists(dir.path / "r_ridge_normal.png"));
  CHECK(fs::exists(dir.path / "r_lod1_ridge_normal.png"));
  const std::vector<fs::path> files = partFiles(levels[1].parts, dir.path / "r_lod1.obj");
  CHECK(std::find(files.begin(), files.end(), dir.path / "r_lod1_ridge_normal.png") != files.end());
}

// Not run in CI: writes a bumpy square (ridges along both axes) as its full mesh and as a
// flat two-level chain with detail maps into $SPRIG_LOOK_DIR, to render the two side by side
// in a viewer (docs/MESHES.md "Levels of detail": the normal map's orientation looked at).
TEST_CASE("detail maps to look at", "[.][look]") {
  const char* dir = std::getenv("SPRIG_LOOK_DIR");
  REQUIRE(dir);
  Mesh full = grid(160, 0.0f);
  for (size_t v = 0; v < full.positions.size(); ++v) {
    Vec3& p = full.positions[v];
    const float a = 0.03f, wx = 2.0f * float(kPi) * 3.0f, wy = 2.0f * float(kPi) * 2.0f;
    p.z = a * std::sin(wx * p.x) + a * std::sin(wy * p.y);
    full.normals[v] = glm::normalize(Vec3(-a * wx * std::cos(wx * p.x), -a * wy * std::cos(wy * p.y), 1.0f));
    full.colors[v] = Vec3(0.6f);
  }
  ExportPart part{"bumps", full, PartMaterial{"bumps", Vec3(0.6f), 0.7f, false}};
  writeParts({part}, fs::path(dir) / "bumps_full.glb");
  const std::vector<LodLevel> levels = buildLodChain({part}, 1000);
  writeLevels(levels, fs::path(dir) / "bumps.glb");
}
