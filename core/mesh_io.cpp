#include "core/mesh_io.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "core/atomic_file.h"
#include "core/image.h"
#include "core/mesh_corners.h"
#include "core/parallel.h"
#include "core/paths.h"
#include "core/srgb.h"

namespace sprig {

namespace fs = std::filesystem;

const Image& DeferredImage::get() {
  std::call_once(once_, [this] {
    image_ = bake_();
    bake_ = nullptr;  // the bake's captures (a mesh, a model) are no longer needed
    baked_ = true;
  });
  return image_;
}

bool normalMapOwnsUvs(const PartMaterial& m) { return m.normalTexture && m.texture && !m.texture->isAtlas(); }

namespace {

// Throws std::invalid_argument when an index or an optional array does not fit the mesh.
void validate(const Mesh& mesh) {
  size_t n = mesh.positions.size();
  auto check = [&](size_t size, const char* what) {
    if (size != 0 && size != n)
      throw std::invalid_argument(std::string("mesh has ") + std::to_string(size) + " " + what + " for " +
                                  std::to_string(n) + " vertices");
  };
  check(mesh.normals.size(), "normals");
  check(mesh.uvs.size(), "uvs");
  check(mesh.colors.size(), "colors");
  if (!mesh.materials.empty() && mesh.materials.size() != mesh.triangles.size())
    throw std::invalid_argument("mesh has " + std::to_string(mesh.materials.size()) + " material ids for " +
                                std::to_string(mesh.triangles.size()) + " triangles");
  for (const auto& t : mesh.triangles)
    if (t.x >= n || t.y >= n || t.z >= n)
      throw std::invalid_argument("mesh triangle index out of range (" + std::to_string(n) + " vertices)");
}

uint8_t toByte(float c) { return static_cast<uint8_t>(std::lround(linearToSrgb(c) * 255.0f)); }

// Appends little-endian raw bytes of a trivially copyable value (x86-64 is little-endian).
template <class T>
void putRaw(std::string& out, const T& v) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &v, sizeof(T));
  out.append(bytes, sizeof(T));
}

// Appends a float in its shortest round-trip decimal form.
void putFloat(std::string& out, float v) {
  char buf[32];
  auto res = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, res.ptr);
}

void putUint(std::string& out, uint64_t v) {
  char buf[24];
  auto res = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, res.ptr);
}

// The OBJ vertex lines of mesh: `v` (with sRGB colours when it has colours), then `vt` and
// `vn` when it has uvs and normals.
void appendObjVertices(std::string& out, const Mesh& mesh) {
  const bool hasN = !mesh.normals.empty(), hasUv = !mesh.uvs.empty(), hasC = !mesh.colors.empty();
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const Vec3& p = mesh.positions[i];
    out += "v ";
    putFloat(out, p.x), out += ' ', putFloat(out, p.y), out += ' ', putFloat(out, p.z);
    if (hasC) {
      out += ' ';
      putFloat(out, linearToSrgb(mesh.colors[i].x)), out += ' ';
      putFloat(out, linearToSrgb(mesh.colors[i].y)), out += ' ';
      putFloat(out, linearToSrgb(mesh.colors[i].z));
    }
    out += '\n';
  }
  if (hasUv)
    for (const auto& uv : mesh.uvs) out += "vt ", putFloat(out, uv.x), out += ' ', putFloat(out, uv.y), out += '\n';
  if (hasN)
    for (const auto& nm : mesh.normals) {
      out += "vn ";
      putFloat(out, nm.x), out += ' ', putFloat(out, nm.y), out += ' ', putFloat(out, nm.z);
      out += '\n';
    }
}

void writeAtomic(const fs::path& path, const std::string& bytes) {
  TempPath tmp(path);
  {
    std::ofstream f(tmp.path(), std::ios::binary | std::ios::trunc);
    if (!f) throw std::runtime_error("cannot write '" + path.string() + "': cannot create a file in its folder");
    f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    f.flush();
    if (!f) throw std::runtime_error("cannot write '" + path.string() + "': write failed");
  }
  tmp.commit();
}

// Materials used by the mesh, in first-use order of sorted ids (deterministic).
std::vector<uint32_t> materialIds(const Mesh& mesh) {
  std::vector<uint32_t> ids(mesh.materials.begin(), mesh.materials.end());
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}

// A distinct, muted colour for material id i (golden-ratio hue walk), mixed with base.
Vec3 materialColor(const Vec3& base, uint32_t id) {
  if (id == 0) return base;
  float h = std::fmod(0.61803398875f * float(id), 1.0f) * 6.0f;
  float x = 1.0f - std::fabs(std::fmod(h, 2.0f) - 1.0f);
  Vec3 rgb = h < 1 ? Vec3(1, x, 0) : h < 2 ? Vec3(x, 1, 0) : h < 3 ? Vec3(0, 1, x)
           : h < 4 ? Vec3(0, x, 1) : h < 5 ? Vec3(x, 0, 1) : Vec3(1, 0, x);
  return 0.5f * base + 0.5f * rgb;
}

/// Appends one attribute or index array to data (4-byte aligned) as its own buffer view
/// and accessor of model; returns the accessor's index.
int addGltfAccessor(tinygltf::Model& model, std::vector<unsigned char>& data, const void* bytes, size_t byteLength,
                    size_t count, int type, int componentType, int target) {
  while (data.size() % 4) data.push_back(0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = data.size();
  view.byteLength = byteLength;
  view.target = target;
  auto* b = static_cast<const unsigned char*>(bytes);
  data.insert(data.end(), b, b + byteLength);
  model.bufferViews.push_back(view);
  tinygltf::Accessor acc;
  acc.bufferView = int(model.bufferViews.size() - 1);
  acc.byteOffset = 0;
  acc.componentType = componentType;
  acc.count = count;
  acc.type = type;
  model.accessors.push_back(acc);
  return int(model.accessors.size() - 1);
}

}  // namespace

MeshFormat meshFormatFor(const fs::path& path) {
  std::string ext = lowerExtension(path);
  if (ext == ".ply") return MeshFormat::Ply;
  if (ext == ".obj") return MeshFormat::Obj;
  if (ext == ".glb") return MeshFormat::Glb;
  throw std::invalid_argument("cannot tell the mesh format of '" + path.string() +
                              "': use the extension .ply, .obj or .glb");
}

void writeMesh(const Mesh& mesh, const fs::path& path, const MeshWriteOptions& options) {
  switch (meshFormatFor(path)) {
    case MeshFormat::Ply: writePly(mesh, path); break;
    case MeshFormat::Obj: writeObj(mesh, path, options); break;
    case MeshFormat::Glb: writeGlb(mesh, path, options); break;
  }
}

void writePly(const Mesh& mesh, const fs::path& path) { writePly(mesh, path, std::string()); }

void writePly(const Mesh& mesh, const fs::path& path, const std::string& comments) {
  validate(mesh);
  size_t n = mesh.positions.size();
  bool hasN = !mesh.normals.empty(), hasUv = !mesh.uvs.empty(), hasC = !mesh.colors.empty();
  bool hasM = !mesh.materials.empty();

  std::string out = "ply\nformat binary_little_endian 1.0\ncomment written by Sprig\n" + comments;
  out += "element vertex " + std::to_string(n) + "\n";
  out += "property float x\nproperty float y\nproperty float z\n";
  if (hasN) out += "property float nx\nproperty float ny\nproperty float nz\n";
  if (hasUv) out += "property float s\nproperty float t\n";
  if (hasC) out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  out += "element face " + std::to_string(mesh.triangles.size()) + "\n";
  out += "property list uchar uint vertex_indices\n";
  if (hasM) out += "property uint material\n";
  out += "end_header\n";

  size_t vertexBytes = 12 + (hasN ? 12 : 0) + (hasUv ? 8 : 0) + (hasC ? 3 : 0);
  out.reserve(out.size() + n * vertexBytes + mesh.triangles.size() * (13 + (hasM ? 4 : 0)));
  for (size_t i = 0; i < n; ++i) {
    const Vec3& p = mesh.positions[i];
    putRaw(out, p.x), putRaw(out, p.y), putRaw(out, p.z);
    if (hasN) putRaw(out, mesh.normals[i].x), putRaw(out, mesh.normals[i].y), putRaw(out, mesh.normals[i].z);
    if (hasUv) putRaw(out, mesh.uvs[i].x), putRaw(out, mesh.uvs[i].y);
    if (hasC) {
      out.push_back(char(toByte(mesh.colors[i].x)));
      out.push_back(char(toByte(mesh.colors[i].y)));
      out.push_back(char(toByte(mesh.colors[i].z)));
    }
  }
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    out.push_back(char(3));
    putRaw(out, mesh.triangles[t].x), putRaw(out, mesh.triangles[t].y), putRaw(out, mesh.triangles[t].z);
    if (hasM) putRaw(out, mesh.materials[t]);
  }
  writeAtomic(path, out);
}

void writeObj(const Mesh& mesh, const fs::path& path, const MeshWriteOptions& options) {
  validate(mesh);
  bool hasN = !mesh.normals.empty(), hasUv = !mesh.uvs.empty(), hasC = !mesh.colors.empty();
  bool hasM = !mesh.materials.empty();
  fs::path mtlPath = path;
  mtlPath.replace_extension(".mtl");
  std::vector<uint32_t> ids = hasM ? materialIds(mesh) : std::vector<uint32_t>{};
  auto nameOf = [&](uint32_t id) {
    return hasM ? options.materialName + "_" + std::to_string(id) : options.materialName;
  };

  // The MTL: one entry, or one per material id.
  std::string mtl = "# written by Sprig\n";
  auto putMaterial = [&](const std::string& name, const Vec3& c) {
    mtl += "newmtl " + name + "\nKa 0 0 0\nKd ";
    putFloat(mtl, c.x), mtl += ' ', putFloat(mtl, c.y), mtl += ' ', putFloat(mtl, c.z);
    mtl += "\nKs 0.04 0.04 0.04\nNs 32\nd 1\nillum 2\n\n";
  };
  if (hasM)
    for (uint32_t id : ids) putMaterial(nameOf(id), materialColor(options.baseColor, id));
  else
    putMaterial(nameOf(0), options.baseColor);

  std::string out = "# written by Sprig\nmtllib " + mtlPath.filename().string() + "\n";
  out.reserve(mesh.positions.size() * (hasC ? 90 : 40) * (1 + hasN + hasUv) + mesh.triangles.size() * 40);
  appendObjVertices(out, mesh);
  if (!hasM) out += "usemtl " + nameOf(0) + "\n";
  uint32_t current = ~0u;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (hasM && mesh.materials[t] != current) {
      current = mesh.materials[t];
      out += "usemtl " + nameOf(current) + "\n";
    }
    out += 'f';
    for (int k = 0; k < 3; ++k) {
      uint64_t idx = uint64_t(mesh.triangles[t][k]) + 1;
      out += ' ';
      putUint(out, idx);
      if (hasUv || hasN) {
        out += '/';
        if (hasUv) putUint(out, idx);
        if (hasN) out += '/', putUint(out, idx);
      }
    }
    out += '\n';
  }
  writeAtomic(mtlPath, mtl);
  writeAtomic(path, out);
}

void writeGlb(const Mesh& mesh, const fs::path& path, const MeshWriteOptions& options) {
  validate(mesh);
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "Sprig";

  tinygltf::Material mat;
  mat.name = options.materialName;
  mat.pbrMetallicRoughness.baseColorFactor = {options.baseColor.x, options.baseColor.y, options.baseColor.z, 1.0};
  mat.pbrMetallicRoughness.metallicFactor = 0.0;
  mat.pbrMetallicRoughness.roughnessFactor = options.roughness;
  model.materials.push_back(mat);

  tinygltf::Scene scene;
  scene.name = "Sprig";
  if (!mesh.triangles.empty()) {
    tinygltf::Buffer buffer;
    std::vector<unsigned char>& data = buffer.data;
    auto addAccessor = [&](const void* bytes, size_t byteLength, size_t count, int type, int componentType, int target) {
      return addGltfAccessor(model, data, bytes, byteLength, count, type, componentType, target);
    };
    size_t n = mesh.positions.size();
    tinygltf::Primitive prim;
    prim.mode = TINYGLTF_MODE_TRIANGLES;
    prim.material = 0;
    int pos = addAccessor(mesh.positions.data(), n * sizeof(Vec3), n, TINYGLTF_TYPE_VEC3,
                          TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
    Box3 box = mesh.bounds();
    model.accessors[pos].minValues = {box.lo.x, box.lo.y, box.lo.z};
    model.accessors[pos].maxValues = {box.hi.x, box.hi.y, box.hi.z};
    prim.attributes["POSITION"] = pos;
    if (!mesh.normals.empty())
      prim.attributes["NORMAL"] = addAccessor(mesh.normals.data(), n * sizeof(Vec3), n, TINYGLTF_TYPE_VEC3,
                                              TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
    if (!mesh.uvs.empty()) {
      std::vector<Vec2> flipped(mesh.uvs.size());
      for (size_t i = 0; i < n; ++i) flipped[i] = {mesh.uvs[i].x, 1.0f - mesh.uvs[i].y};
      prim.attributes["TEXCOORD_0"] = addAccessor(flipped.data(), n * sizeof(Vec2), n, TINYGLTF_TYPE_VEC2,
                                                  TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
    }
    if (!mesh.colors.empty())
      prim.attributes["COLOR_0"] = addAccessor(mesh.colors.data(), n * sizeof(Vec3), n, TINYGLTF_TYPE_VEC3,
                                               TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
    prim.indices = addAccessor(mesh.triangles.data(), mesh.triangles.size() * sizeof(glm::uvec3),
                               mesh.triangles.size() * 3, TINYGLTF_TYPE_SCALAR,
                               TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    model.buffers.push_back(std::move(buffer));

    tinygltf::Mesh gm;
    gm.name = "Sprig mesh";
    gm.primitives.push_back(prim);
    model.meshes.push_back(gm);
    tinygltf::Node node;
    node.mesh = 0;
    model.nodes.push_back(node);
    scene.nodes.push_back(0);
  }
  model.scenes.push_back(scene);
  model.defaultScene = 0;

  std::ostringstream stream;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&model, stream, false, true))
    throw std::runtime_error("cannot write '" + path.string() + "': glTF serialization failed");
  writeAtomic(path, stream.str());
}

}  // namespace sprig

namespace sprig {

namespace {

// A name safe for OBJ/MTL statements (whitespace becomes '_').
std::string objName(const std::string& name) {
  std::string out = name.empty() ? std::string("part") : name;
  for (char& c : out)
    if (c == ' ' || c == '\t' || c == '\n' || c == '\r') c = '_';
  return out;
}

// The colour glTF's COLOR_0 carries for colour c of a part with base colour b: c / b per
// channel, clamped to [0,1]; a channel of b that is 0 gives 1 (the product is 0 anyway).
Vec3 relativeColor(const Vec3& c, const Vec3& b, size_t* clamped = nullptr) {
  Vec3 out;
  for (int k = 0; k < 3; ++k) {
    float r = b[k] > 0 ? c[k] / b[k] : 1.0f;
    if (r > 1.0f + 1e-6f && clamped) ++*clamped;
    out[k] = std::clamp(r, 0.0f, 1.0f);
  }
  return out;
}

// True when the part has vertex colours that differ from its base colour.
bool hasOwnColors(const ExportPart& part) {
  const Mesh& m = part.mesh;
  if (m.colors.size() != m.positions.size() || m.colors.empty()) return false;
  for (const Vec3& c : m.colors)
    if (glm::any(glm::greaterThan(glm::abs(c - part.material.baseColor), Vec3(1e-6f)))) return true;
  return false;
}

// Whether the OBJ writer writes a part's normal map: OBJ gives a corner one uv, so a normal
// map with coordinates of its own (normalMapOwnsUvs) is left out.
bool objNormalMap(const PartMaterial& m) { return m.normalTexture && !normalMapOwnsUvs(m); }

// The corner normals and uvs a part is written with (glTF, OBJ), and what they did.
struct PartCorners {
  CornerTable<Vec3> normals;
  CornerTable<Vec2> uvs;
  PartWriteReport report;
};

PartCorners partCorners(const ExportPart& part) {
  PartCorners c;
  const Mesh& mesh = part.mesh;
  const size_t n = mesh.positions.size();
  c.report.name = part.name;
  if (mesh.normals.size() == n) {
    CreaseNormals cn = splitCreaseNormals(mesh);
    c.report.creaseVertices = cn.splitVertices;
    c.normals = std::move(cn.normals);
  }
  const PartTexture* tex = part.material.texture.get();
  if (tex && tex->isAtlas()) {
    c.uvs = tex->atlas;
    c.report.atlasCell = tex->atlasCell;
    c.report.textureWidth = tex->width(), c.report.textureHeight = tex->height();
  } else if (mesh.uvs.size() == n) {
    c.uvs = cornerUvs(mesh, tex ? tex->seams : UvSeamOptions{});
    c.report.seamCorners = c.uvs.values.size() - n;
    if (tex) c.report.textureWidth = tex->width(), c.report.textureHeight = tex->height();
  }
  return c;
}

// The PNG bytes of a texture image written with encoding (TextureMap: 8-bit sRGB RGB;
// Picture: RGBA; Data: 8-bit values as they are), through a temporary
// file beside `near` (core/image.h owns image files; the temporary is removed when this
// returns).
// How a part's base colour texture is stored: RGBA when it cuts out, else sRGB RGB.
ImageEncoding baseColorEncoding(const PartMaterial& material) {
  return material.alphaCutoff >= 0.0f ? ImageEncoding::Picture : ImageEncoding::TextureMap;
}

// Writes tex's image (8-bit as it is, or the float image in encoding) to png at
// kTexturePngLevel.
void writeTexture(const PartTexture& tex, const fs::path& png, ImageEncoding encoding) {
  ImageWriteOptions options;
  options.pngLevel = kTexturePngLevel;
  if (!tex.image8.empty())
    writeImage(tex.image8, png, options);
  else
    writeImage(tex.pixels(), png, encoding, options);
}

std::string encodePng(const PartTexture& tex, const fs::path& near, ImageEncoding encoding) {
  fs::path dest = near;
  dest.replace_extension(".png");
  TempPath temp(dest);
  writeTexture(tex, temp.path(), encoding);
  return readFile(temp.path());
}

// The key of a texture's image in a PngReuse scope: the image (its address, its values'
// address and size) and the encoding.
using PngKey = std::tuple<const void*, const void*, size_t, int>;
PngKey pngKey(const PartTexture& tex, ImageEncoding encoding) {
  if (!tex.image8.empty()) return PngKey(&tex.image8, tex.image8.values.data(), tex.image8.values.size(), int(encoding));
  const Image& image = tex.pixels();
  return PngKey(&image, image.pixels.data(), image.pixels.size(), int(encoding));
}

}  // namespace

// The bytes of the images encoded in a PngReuse scope, by pngKey.
struct PngReuse::Cache {
  std::map<PngKey, std::string> png;
};

namespace {

thread_local PngReuse* innermostPngReuse = nullptr;

}  // namespace

PngReuse::PngReuse() : cache_(std::make_unique<Cache>()), outer_(innermostPngReuse) { innermostPngReuse = this; }
PngReuse::~PngReuse() { innermostPngReuse = outer_; }
size_t PngReuse::encoded() const { return cache_->png.size(); }
PngReuse* PngReuse::innermost() { return innermostPngReuse; }

void PngReuse::encodeAhead(const std::vector<const ExportPart*>& parts, const fs::path& near) {
  struct Todo {
    PngKey key;
    const PartTexture* tex;
    ImageEncoding encoding;
  };
  std::vector<Todo> todo;
  auto want = [&](const PartTexture& tex, ImageEncoding encoding) {
    const PngKey key = pngKey(tex, encoding);
    if (cache_->png.count(key)) return;
    for (const Todo& t : todo)
      if (t.key == key) return;
    todo.push_back({key, &tex, encoding});
  };
  for (const ExportPart* p : parts) {
    if (p->mesh.triangles.empty()) continue;
    if (p->material.texture) want(*p->material.texture, baseColorEncoding(p->material));
    if (p->material.normalTexture) want(*p->material.normalTexture, ImageEncoding::Data);
  }
  // The largest images first: two threads finish together when the last ones are small.
  std::stable_sort(todo.begin(), todo.end(), [](const Todo& a, const Todo& b) {
    return size_t(a.tex->width()) * size_t(a.tex->height()) > size_t(b.tex->width()) * size_t(b.tex->height());
  });
  std::vector<std::string> bytes(todo.size());
  parallelFor(0, todo.size(), [&](size_t i) { bytes[i] = encodePng(*todo[i].tex, near, todo[i].encoding); });
  for (size_t i = 0; i < todo.size(); ++i) cache_->png.emplace(todo[i].key, std::move(bytes[i]));
}
const std::string& PngReuse::once(const PartTexture& tex, int encoding, const std::function<std::string()>& encode) {
  const PngKey key = pngKey(tex, ImageEncoding(encoding));
  auto it = cache_->png.find(key);
  if (it == cache_->png.end()) it = cache_->png.emplace(key, encode()).first;
  return it->second;
}

namespace {

// encodePng's bytes, made once per image and encoding within a PngReuse scope (the
// scope's own, not a copy); outside a scope made into own.
const std::string& pngBytes(const PartTexture& tex, const fs::path& near, ImageEncoding encoding, std::string& own) {
  PngReuse* scope = PngReuse::innermost();
  if (!scope) return own = encodePng(tex, near, encoding);
  return scope->once(tex, int(encoding), [&] { return encodePng(tex, near, encoding); });
}

// One tangent per vertex of an unwelded mesh whose vertices each belong to one corner (an
// atlas gives every corner its own uv): cornerTangent of that corner; a vertex no triangle
// uses gets a unit vector perpendicular to its normal.
std::vector<glm::vec4> vertexTangents(const Mesh& mesh) {
  std::vector<glm::vec4> out(mesh.positions.size());
  const Vec3 none[3] = {Vec3(0.0f), Vec3(0.0f), Vec3(0.0f)};
  const Vec2 noUv[3] = {Vec2(0.0f), Vec2(0.0f), Vec2(0.0f)};
  for (size_t v = 0; v < out.size(); ++v) out[v] = cornerTangent(none, noUv, mesh.normals[v]);
  for (const glm::uvec3& tri : mesh.triangles) {
    const Vec3 p[3] = {mesh.positions[tri.x], mesh.positions[tri.y], mesh.positions[tri.z]};
    const Vec2 uv[3] = {mesh.uvs[tri.x], mesh.uvs[tri.y], mesh.uvs[tri.z]};
    for (int k = 0; k < 3; ++k) out[tri[k]] = cornerTangent(p, uv, mesh.normals[tri[k]]);
  }
  return out;
}

// The value of table at each vertex of mesh, a mesh whose vertices are each one corner
// (unweld by an atlas): vertex triangles[t][k] takes corner k of triangle t's value.
std::vector<Vec2> cornerValues(const Mesh& mesh, const CornerTable<Vec2>& table) {
  std::vector<Vec2> out(mesh.positions.size(), Vec2(0.0f));
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    for (size_t k = 0; k < 3; ++k) out[mesh.triangles[t][int(k)]] = table.values[table.index[t * 3 + k]];
  return out;
}

// A part's vertex attributes and morph targets fit its mesh.
void checkExtras(const ExportPart& p) {
  const size_t n = p.mesh.positions.size();
  for (const VertexAttribute& a : p.attributes)
    if (a.name.empty() || a.name[0] != '_' || a.values.size() != n)
      throw std::invalid_argument("exported part '" + p.name + "' has a vertex attribute '" + a.name +
                                  "' that does not start with '_' or has not one value per vertex");
  if (!p.morph) return;
  const PartMorph& m = *p.morph;
  bool ok = !m.targets.empty() && m.names.size() == m.targets.size() && m.weights.size() == m.targets.size() &&
            m.times.size() >= 2 && !m.animation.empty();
  for (size_t k = 0; ok && k < m.targets.size(); ++k) ok = m.targets[k].size() == n && m.weights[k].size() == m.times.size();
  for (size_t f = 1; ok && f < m.times.size(); ++f) ok = m.times[f] > m.times[f - 1];
  if (!ok) throw std::invalid_argument("exported part '" + p.name + "' has morph targets or weights that do not fit its mesh");
}

// tex's image (8-bit or float) holds its pixels, an 8-bit one in encoding, the writers' for it.
void checkTextureImage(const ExportPart& p, const PartTexture& tex, ImageEncoding encoding) {
  if (!tex.image8.empty()) {
    const Image8& im = tex.image8;
    if (im.width <= 0 || im.height <= 0 || im.channels != (encoding == ImageEncoding::Picture ? 4 : 3) ||
        im.values.size() != size_t(im.width) * size_t(im.height) * size_t(im.channels))
      throw std::invalid_argument("exported part '" + p.name + "' has an empty or malformed 8-bit texture image");
    if (im.encoding != encoding)
      throw std::invalid_argument("exported part '" + p.name + "' has an 8-bit texture image in another encoding than its file's");
    return;
  }
  const Image& im = tex.pixels();
  if (im.width <= 0 || im.height <= 0 || im.pixels.size() != size_t(im.width) * size_t(im.height) * 4)
    throw std::invalid_argument("exported part '" + p.name + "' has an empty or malformed texture image");
}

// An atlas's corners fit p's triangles and lie in the image.
void checkAtlasCorners(const ExportPart& p, const CornerTable<Vec2>& a) {
  if (a.index.size() != p.mesh.triangles.size() * 3)
    throw std::invalid_argument("exported part '" + p.name + "' has an atlas whose corners do not match its triangles");
  for (uint32_t i : a.index)
    if (i >= a.values.size()) throw std::invalid_argument("exported part '" + p.name + "' has an atlas index out of range");
  for (const Vec2& uv : a.values)
    if (!(uv.x >= 0 && uv.x <= 1 && uv.y >= 0 && uv.y <= 1))
      throw std::invalid_argument("exported part '" + p.name + "' has an atlas coordinate outside [0,1]");
}

void checkParts(const std::vector<ExportPart>& parts) {
  std::vector<std::string> names;
  for (const ExportPart& p : parts) {
    validate(p.mesh);
    names.push_back(p.name);
    checkExtras(p);
    if (const PartTexture* tex = p.material.texture.get()) {
      if (tex->isAtlas()) {
        checkAtlasCorners(p, tex->atlas);
      } else if (p.mesh.uvs.size() != p.mesh.positions.size()) {
        throw std::invalid_argument("exported part '" + p.name + "' has a texture but no texture coordinates");
      }
      checkTextureImage(p, *tex, baseColorEncoding(p.material));
    }
    if (const PartTexture* nt = p.material.normalTexture.get()) {
      const PartTexture* tex = p.material.texture.get();
      checkTextureImage(p, *nt, ImageEncoding::Data);
      const bool shared = tex && tex->isAtlas() && nt->width() == tex->width() && nt->height() == tex->height();
      if (normalMapOwnsUvs(p.material) && nt->isAtlas())
        checkAtlasCorners(p, nt->atlas);
      else if (!shared)
        throw std::invalid_argument("exported part '" + p.name + "' has a normal map without an atlas of its size");
    }
  }
  std::sort(names.begin(), names.end());
  auto dup = std::adjacent_find(names.begin(), names.end());
  if (dup != names.end()) throw std::invalid_argument("two exported parts are named '" + *dup + "'");
}

// A glTF binary built part by part: images shared between parts (levels of detail) stored once.
class GlbBuilder {
 public:
  explicit GlbBuilder(const fs::path& path) : path_(path) {
    model_.asset.version = "2.0";
    model_.asset.generator = "Sprig";
    scene_.name = "Sprig";
  }

  /// Adds part as a node named nodeName (and its mesh and material); returns the node's index.
  int addPart(const ExportPart& part, const std::string& nodeName, PartWriteReport* report);
  /// Puts node in the scene.
  void addToScene(int node) { scene_.nodes.push_back(node); }
  tinygltf::Node& node(int i) { return model_.nodes[size_t(i)]; }
  int addEmptyNode(const tinygltf::Node& n) {
    model_.nodes.push_back(n);
    return int(model_.nodes.size() - 1);
  }
  void useExtension(const std::string& name) { model_.extensionsUsed.push_back(name); }
  /// Writes the file atomically.
  void write();

 private:
  int addAccessor(const void* bytes, size_t byteLength, size_t count, int type, int componentType, int target) {
    return addGltfAccessor(model_, data_, bytes, byteLength, count, type, componentType, target);
  }
  int addTexture(const PartTexture* tex, const std::string& name, ImageEncoding encoding);
  int addMaterial(const ExportPart& part);
  /// Adds uvs (Mesh::uvs' convention, t = 0 at the bottom) as the primitive's attribute
  /// `name`, with t flipped to glTF's (0 at the top).
  void addTexCoords(tinygltf::Primitive& prim, const std::string& name, const std::vector<Vec2>& uvs) {
    std::vector<Vec2> flipped(uvs.size());
    for (size_t i = 0; i < uvs.size(); ++i) flipped[i] = {uvs[i].x, 1.0f - uvs[i].y};
    prim.attributes[name] = addAccessor(flipped.data(), uvs.size() * sizeof(Vec2), uvs.size(), TINYGLTF_TYPE_VEC2,
                                        TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
  }
  void addExtras(const ExportPart& part, const std::vector<uint32_t>& origin, tinygltf::Primitive& prim, tinygltf::Mesh& gm);
  void addAnimations();
  /// A morph target's displacements: a plain accessor, or sparse (no buffer view; the
  /// moved vertices' indices and displacements) when fewer than 3/4 of the vertices move.
  int addTarget(const std::vector<Vec3>& values);

  std::vector<std::pair<int, const PartMorph*>> animated_;  ///< nodes with morph animations

  fs::path path_;
  tinygltf::Model model_;
  tinygltf::Scene scene_;
  std::vector<unsigned char> data_;
  std::map<const PartTexture*, int> textures_;
};

int GlbBuilder::addTexture(const PartTexture* tex, const std::string& name, ImageEncoding encoding) {
  if (auto it = textures_.find(tex); it != textures_.end()) return it->second;
  std::string own;
  const std::string& png = pngBytes(*tex, path_, encoding, own);
  while (data_.size() % 4) data_.push_back(0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = data_.size();
  view.byteLength = png.size();
  data_.insert(data_.end(), png.begin(), png.end());
  model_.bufferViews.push_back(view);
  tinygltf::Image image;
  image.name = name;
  image.mimeType = "image/png";
  image.bufferView = int(model_.bufferViews.size() - 1);
  model_.images.push_back(image);
  tinygltf::Sampler sampler;
  sampler.magFilter =
      tex->magFilter == PartTexture::Filter::Nearest ? TINYGLTF_TEXTURE_FILTER_NEAREST : TINYGLTF_TEXTURE_FILTER_LINEAR;
  sampler.minFilter = tex->minFilter == PartTexture::Filter::Nearest  ? TINYGLTF_TEXTURE_FILTER_NEAREST
                      : tex->minFilter == PartTexture::Filter::Linear ? TINYGLTF_TEXTURE_FILTER_LINEAR
                      : tex->isAtlas()                                ? TINYGLTF_TEXTURE_FILTER_LINEAR
                                                                      : TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
  sampler.wrapS = tex->seams.repeatU ? TINYGLTF_TEXTURE_WRAP_REPEAT : TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
  sampler.wrapT = tex->seams.repeatV ? TINYGLTF_TEXTURE_WRAP_REPEAT : TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
  model_.samplers.push_back(sampler);
  tinygltf::Texture texture;
  texture.name = name;
  texture.sampler = int(model_.samplers.size() - 1);
  texture.source = int(model_.images.size() - 1);
  model_.textures.push_back(texture);
  return textures_[tex] = int(model_.textures.size() - 1);
}

int GlbBuilder::addMaterial(const ExportPart& part) {
  tinygltf::Material mat;
  mat.name = part.material.name;
  const Vec3& c = part.material.baseColor;
  mat.pbrMetallicRoughness.baseColorFactor = {c.x, c.y, c.z, 1.0};
  if (part.material.texture) {
    // The image holds absolute colours: factor 1, the species' colour kept in extras.
    mat.pbrMetallicRoughness.baseColorFactor = {1.0, 1.0, 1.0, 1.0};
    tinygltf::Value::Array rgb{tinygltf::Value(double(c.x)), tinygltf::Value(double(c.y)), tinygltf::Value(double(c.z))};
    tinygltf::Value::Object extras;
    extras["sprigBaseColor"] = tinygltf::Value(rgb);
    mat.extras = tinygltf::Value(extras);
    if (part.material.alphaCutoff >= 0.0f) {
      mat.alphaMode = "MASK";
      mat.alphaCutoff = part.material.alphaCutoff;
    }
    mat.pbrMetallicRoughness.baseColorTexture.index =
        addTexture(part.material.texture.get(), part.name, baseColorEncoding(part.material));
  }
  if (part.material.normalTexture) {
    mat.normalTexture.index = addTexture(part.material.normalTexture.get(), part.name + "_normal", ImageEncoding::Data);
    if (normalMapOwnsUvs(part.material)) mat.normalTexture.texCoord = 1;
  }
  mat.pbrMetallicRoughness.metallicFactor = part.material.metallic;
  mat.pbrMetallicRoughness.roughnessFactor = part.material.roughness;
  mat.doubleSided = part.material.doubleSided;
  model_.materials.push_back(mat);
  return int(model_.materials.size() - 1);
}

int GlbBuilder::addPart(const ExportPart& part, const std::string& nodeName, PartWriteReport* report) {
  PartCorners corners = partCorners(part);
  if (report) *report = corners.report;
  std::vector<uint32_t> origin;
  // A normal map with coordinates of its own (an atlas: one vertex per corner) is welded by
  // them, and each corner's image uv goes beside them.
  const bool second = normalMapOwnsUvs(part.material) && !corners.uvs.index.empty();
  const Mesh mesh = unweld(part.mesh, corners.normals, second ? part.material.normalTexture->atlas : corners.uvs, &origin);
  const size_t n = mesh.positions.size();
  tinygltf::Primitive prim;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  prim.material = addMaterial(part);
  const int pos = addAccessor(mesh.positions.data(), n * sizeof(Vec3), n, TINYGLTF_TYPE_VEC3, TINYGLTF_COMPONENT_TYPE_FLOAT,
                              TINYGLTF_TARGET_ARRAY_BUFFER);
  const Box3 box = mesh.bounds();
  model_.accessors[size_t(pos)].minValues = {box.lo.x, box.lo.y, box.lo.z};
  model_.accessors[size_t(pos)].maxValues = {box.hi.x, box.hi.y, box.hi.z};
  prim.attributes["POSITION"] = pos;
  if (!mesh.normals.empty())
    prim.attributes["NORMAL"] = addAccessor(mesh.normals.data(), n * sizeof(Vec3), n, TINYGLTF_TYPE_VEC3,
                                            TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
  if (second) {
    addTexCoords(prim, "TEXCOORD_0", cornerValues(mesh, corners.uvs));
    addTexCoords(prim, "TEXCOORD_1", mesh.uvs);
  } else if (!mesh.uvs.empty()) {
    addTexCoords(prim, "TEXCOORD_0", mesh.uvs);
  }
  if (part.material.normalTexture && !mesh.normals.empty()) {
    const std::vector<glm::vec4> tangents = vertexTangents(mesh);
    prim.attributes["TANGENT"] = addAccessor(tangents.data(), n * sizeof(glm::vec4), n, TINYGLTF_TYPE_VEC4,
                                             TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
  }
  if (!part.material.texture && hasOwnColors(part)) {
    std::vector<Vec3> rel(n);
    for (size_t i = 0; i < n; ++i) rel[i] = relativeColor(mesh.colors[i], part.material.baseColor);
    prim.attributes["COLOR_0"] = addAccessor(rel.data(), n * sizeof(Vec3), n, TINYGLTF_TYPE_VEC3,
                                             TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
  }
  prim.indices = addAccessor(mesh.triangles.data(), mesh.triangles.size() * sizeof(glm::uvec3), mesh.triangles.size() * 3,
                             TINYGLTF_TYPE_SCALAR, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  tinygltf::Mesh gm;
  gm.name = nodeName;
  addExtras(part, origin, prim, gm);
  gm.primitives.push_back(prim);
  model_.meshes.push_back(gm);
  tinygltf::Node node;
  node.name = nodeName;
  node.mesh = int(model_.meshes.size() - 1);
  model_.nodes.push_back(node);
  const int index = int(model_.nodes.size() - 1);
  if (part.morph) animated_.emplace_back(index, part.morph.get());
  return index;
}

void GlbBuilder::addExtras(const ExportPart& part, const std::vector<uint32_t>& origin, tinygltf::Primitive& prim,
                           tinygltf::Mesh& gm) {
  const size_t n = origin.size();
  for (const VertexAttribute& a : part.attributes) {
    std::vector<glm::vec4> values(n);
    for (size_t i = 0; i < n; ++i) values[i] = a.values[origin[i]];
    prim.attributes[a.name] = addAccessor(values.data(), n * sizeof(glm::vec4), n, TINYGLTF_TYPE_VEC4,
                                          TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
  }
  if (!part.morph) return;
  tinygltf::Value::Array names;
  for (size_t k = 0; k < part.morph->targets.size(); ++k) {
    const std::vector<Vec3>& target = part.morph->targets[k];
    std::vector<Vec3> values(n);
    Box3 box;
    for (size_t i = 0; i < n; ++i) box.extend(values[i] = target[origin[i]]);
    const int acc = addTarget(values);
    model_.accessors[size_t(acc)].minValues = {box.lo.x, box.lo.y, box.lo.z};
    model_.accessors[size_t(acc)].maxValues = {box.hi.x, box.hi.y, box.hi.z};
    prim.targets.push_back({{"POSITION", acc}});
    gm.weights.push_back(0.0);
    names.push_back(tinygltf::Value(part.morph->names[k]));
  }
  gm.extras = tinygltf::Value(tinygltf::Value::Object{{"targetNames", tinygltf::Value(names)}});
}

int GlbBuilder::addTarget(const std::vector<Vec3>& values) {
  std::vector<uint32_t> moved;
  for (size_t i = 0; i < values.size(); ++i)
    if (values[i] != Vec3(0.0f)) moved.push_back(uint32_t(i));
  if (moved.empty() || moved.size() * 16 >= values.size() * 12)  // sparse: 4 bytes of index and 12 of value
    return addAccessor(values.data(), values.size() * sizeof(Vec3), values.size(), TINYGLTF_TYPE_VEC3,
                       TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
  // Sparse without a buffer view: zeros, and the moved vertices' displacements.
  std::vector<Vec3> moves(moved.size());
  for (size_t k = 0; k < moved.size(); ++k) moves[k] = values[moved[k]];
  const int indices = addAccessor(moved.data(), moved.size() * 4, moved.size(), TINYGLTF_TYPE_SCALAR,
                                  TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, 0);
  const int disp = addAccessor(moves.data(), moves.size() * sizeof(Vec3), moves.size(), TINYGLTF_TYPE_VEC3,
                               TINYGLTF_COMPONENT_TYPE_FLOAT, 0);
  tinygltf::Accessor acc;
  acc.bufferView = -1;
  acc.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  acc.count = values.size();
  acc.type = TINYGLTF_TYPE_VEC3;
  acc.sparse.isSparse = true;
  acc.sparse.count = int(moved.size());
  acc.sparse.indices.bufferView = model_.accessors[size_t(indices)].bufferView;
  acc.sparse.indices.byteOffset = 0;
  acc.sparse.indices.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
  acc.sparse.values.bufferView = model_.accessors[size_t(disp)].bufferView;
  acc.sparse.values.byteOffset = 0;
  // The two helper accessors are only a way to store the views: replace the last by the target.
  model_.accessors.resize(model_.accessors.size() - 2);
  model_.accessors.push_back(acc);
  return int(model_.accessors.size() - 1);
}

void GlbBuilder::addAnimations() {
  std::map<std::string, tinygltf::Animation> byName;
  std::map<std::pair<std::string, std::vector<float>>, int> inputs;  // time accessors shared by equal keyframes
  for (const auto& [node, m] : animated_) {
    tinygltf::Animation& anim = byName[m->animation];
    anim.name = m->animation;
    auto [it, fresh] = inputs.try_emplace(std::make_pair(m->animation, m->times), -1);
    if (fresh) {
      it->second = addAccessor(m->times.data(), m->times.size() * sizeof(float), m->times.size(), TINYGLTF_TYPE_SCALAR,
                               TINYGLTF_COMPONENT_TYPE_FLOAT, 0);
      model_.accessors[size_t(it->second)].minValues = {double(m->times.front())};
      model_.accessors[size_t(it->second)].maxValues = {double(m->times.back())};
    }
    // Output: every target's weight at keyframe 0, then at keyframe 1, ...
    std::vector<float> out;
    out.reserve(m->times.size() * m->weights.size());
    for (size_t f = 0; f < m->times.size(); ++f)
      for (const std::vector<float>& w : m->weights) out.push_back(w[f]);
    tinygltf::AnimationSampler sampler;
    sampler.input = it->second;
    sampler.interpolation = "LINEAR";
    sampler.output = addAccessor(out.data(), out.size() * sizeof(float), out.size(), TINYGLTF_TYPE_SCALAR,
                                 TINYGLTF_COMPONENT_TYPE_FLOAT, 0);
    anim.samplers.push_back(sampler);
    tinygltf::AnimationChannel channel;
    channel.sampler = int(anim.samplers.size() - 1);
    channel.target_node = node;
    channel.target_path = "weights";
    anim.channels.push_back(channel);
  }
  for (auto& [name, anim] : byName) model_.animations.push_back(std::move(anim));
}

void GlbBuilder::write() {
  addAnimations();
  if (!data_.empty()) {
    tinygltf::Buffer buffer;
    buffer.data = std::move(data_);
    model_.buffers.push_back(std::move(buffer));
  }
  model_.scenes.push_back(scene_);
  model_.defaultScene = 0;
  std::ostringstream stream;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&model_, stream, false, true))
    throw std::runtime_error("cannot write '" + path_.string() + "': glTF serialization failed");
  writeAtomic(path_, stream.str());
}

std::vector<PartWriteReport> writePartsGlb(const std::vector<ExportPart>& parts, const fs::path& path) {
  std::vector<PartWriteReport> reports;
  GlbBuilder glb(path);
  for (const ExportPart& part : parts) {
    if (part.mesh.triangles.empty()) continue;
    reports.emplace_back();
    glb.addToScene(glb.addPart(part, part.name, &reports.back()));
  }
  glb.write();
  return reports;
}

// The image file of part's normal map beside an OBJ at path.
fs::path normalMapPath(const fs::path& path, const ExportPart& part) {
  fs::path png = path;
  return png.replace_filename(path.stem().string() + "_" + objName(part.name) + "_normal.png");
}

std::vector<PartWriteReport> writePartsObj(const std::vector<ExportPart>& parts, const fs::path& path) {
  std::vector<PartWriteReport> reports;
  fs::path mtlPath = path;
  mtlPath.replace_extension(".mtl");
  std::string mtl = "# written by Sprig\n";
  std::string out = "# written by Sprig\nmtllib " + mtlPath.filename().string() + "\n";
  struct ImageFile {
    fs::path png;
    const PartTexture* texture;
    ImageEncoding encoding;
  };
  std::vector<ImageFile> images;
  uint64_t base = 0, uvBase = 0, nBase = 0;
  for (const ExportPart& part : parts) {
    if (part.mesh.triangles.empty()) continue;
    PartCorners corners = partCorners(part);
    reports.push_back(corners.report);
    // v lines from the welded positions; vt and vn from the corner tables.
    Mesh lines;
    lines.positions = part.mesh.positions;
    lines.colors = part.mesh.colors;
    lines.uvs = corners.uvs.values;
    lines.normals = corners.normals.values;
    const Mesh& mesh = part.mesh;
    const std::string matName = objName(part.material.name);
    const PartTexture* tex = part.material.texture.get();
    const Vec3 c = tex ? Vec3(1.0f) : part.material.baseColor;
    mtl += "newmtl " + matName + "\nKa 0 0 0\nKd ";
    putFloat(mtl, c.x), mtl += ' ', putFloat(mtl, c.y), mtl += ' ', putFloat(mtl, c.z);
    mtl += "\nKs 0.04 0.04 0.04\nNs 32\nd 1\nillum 2\n";
    if (tex) {
      fs::path png = path;
      png.replace_filename(path.stem().string() + "_" + objName(part.name) + ".png");
      const bool cutOut = part.material.alphaCutoff >= 0.0f;
      images.push_back({png, tex, cutOut ? ImageEncoding::Picture : ImageEncoding::TextureMap});
      // MTL's -clamp covers both axes at once: said where glTF's sampler clamps both (an
      // atlas, cpfg's leaves); an image that repeats in one axis only is left repeating.
      const std::string map = (!tex->seams.repeatU && !tex->seams.repeatV ? "-clamp on " : "") + png.filename().string();
      mtl += "map_Kd " + map + "\n";
      if (cutOut) mtl += "map_d " + map + "\n";
    }
    if (const PartTexture* normal = objNormalMap(part.material) ? part.material.normalTexture.get() : nullptr) {
      // `norm`: the normal map of the MTL's PBR extension (tinyobjloader, three.js); not
      // map_Bump, which many readers take for a height map.
      const fs::path png = normalMapPath(path, part);
      images.push_back({png, normal, ImageEncoding::Data});
      mtl += "norm -clamp on " + png.filename().string() + "\n";
    }
    mtl += "\n";
    const bool hasN = !lines.normals.empty(), hasUv = !lines.uvs.empty();
    out += "o " + objName(part.name) + "\n";
    appendObjVertices(out, lines);
    out += "usemtl " + matName + "\n";
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      out += 'f';
      for (int k = 0; k < 3; ++k) {
        out += ' ';
        putUint(out, base + uint64_t(mesh.triangles[t][k]) + 1);
        if (hasUv || hasN) {
          out += '/';
          if (hasUv) putUint(out, uvBase + uint64_t(corners.uvs.index[t * 3 + size_t(k)]) + 1);
          if (hasN) out += '/', putUint(out, nBase + uint64_t(corners.normals.index[t * 3 + size_t(k)]) + 1);
        }
      }
      out += '\n';
    }
    base += mesh.positions.size();
    uvBase += lines.uvs.size();
    nBase += lines.normals.size();
  }
  // Images first, then the MTL naming them, then the OBJ; a failure removes the images.
  std::vector<fs::path> written;
  try {
    for (const ImageFile& f : images) {
      writeTexture(*f.texture, f.png, f.encoding);
      written.push_back(f.png);
    }
    writeAtomic(mtlPath, mtl);
    writeAtomic(path, out);
  } catch (...) {
    std::error_code ec;
    for (const fs::path& p : written) fs::remove(p, ec);
    throw;
  }
  return reports;
}

void writePartsPly(const std::vector<ExportPart>& parts, const fs::path& path) {
  Mesh all;
  std::string comments;
  uint32_t index = 0;
  for (const ExportPart& part : parts) {
    if (part.mesh.triangles.empty()) continue;
    Mesh m = part.mesh;
    if (m.colors.size() != m.positions.size()) m.colors.assign(m.positions.size(), part.material.baseColor);
    m.uvs.clear();
    m.materials.assign(m.triangles.size(), index);
    comments += "comment part " + std::to_string(index) + " " + objName(part.name) + "\n";
    all.append(m);
    ++index;
  }
  writePly(all, path, comments);
}

}  // namespace

size_t clampedColorChannels(const ExportPart& part) {
  size_t clamped = 0;
  if (!part.material.texture && hasOwnColors(part))
    for (const Vec3& c : part.mesh.colors) relativeColor(c, part.material.baseColor, &clamped);
  return clamped;
}

std::vector<PartWriteReport> writeParts(const std::vector<ExportPart>& parts, const fs::path& path) {
  const MeshFormat format = meshFormatFor(path);
  checkParts(parts);
  switch (format) {
    case MeshFormat::Ply: {
      writePartsPly(parts, path);
      std::vector<PartWriteReport> reports;
      for (const ExportPart& p : parts)
        if (!p.mesh.triangles.empty()) reports.push_back(PartWriteReport{p.name, 0, 0, 0, 0});
      return reports;
    }
    case MeshFormat::Obj: return writePartsObj(parts, path);
    case MeshFormat::Glb: return writePartsGlb(parts, path);
  }
  return {};
}

std::vector<PartWriteReport> writePartLevels(const std::vector<LodLevel>& levels, const fs::path& path) {
  if (meshFormatFor(path) != MeshFormat::Glb)
    throw std::invalid_argument("levels of detail in one file are glTF (.glb): '" + path.string() + "' is not");
  if (levels.empty()) throw std::invalid_argument("writePartLevels: no level to write");
  if (levels.size() == 1) return writeParts(levels[0].parts, path);
  const std::vector<ExportPart>& top = levels[0].parts;
  for (const LodLevel& level : levels) {
    checkParts(level.parts);
    bool same = level.parts.size() == top.size();
    for (size_t i = 0; same && i < top.size(); ++i) same = level.parts[i].name == top[i].name;
    if (!same) throw std::invalid_argument("writePartLevels: the levels of detail do not have the same parts");
  }
  std::vector<PartWriteReport> reports;
  GlbBuilder glb(path);
  for (size_t i = 0; i < top.size(); ++i) {
    if (top[i].mesh.triangles.empty()) continue;
    reports.emplace_back();
    const int node = glb.addPart(top[i], top[i].name, &reports.back());
    glb.addToScene(node);
    tinygltf::Value::Array ids, coverage{tinygltf::Value(levels[0].screenCoverage)};
    for (size_t k = 1; k < levels.size(); ++k) {
      const ExportPart& p = levels[k].parts[i];
      const std::string name = p.name + "_lod" + std::to_string(k);
      int id = -1;
      if (p.mesh.triangles.empty()) {  // a part gone at this level: a node without a mesh
        tinygltf::Node empty;
        empty.name = name;
        id = glb.addEmptyNode(empty);
      } else {
        id = glb.addPart(p, name, nullptr);
      }
      ids.push_back(tinygltf::Value(id));
      coverage.push_back(tinygltf::Value(levels[k].screenCoverage));
    }
    tinygltf::Value::Object lod{{"ids", tinygltf::Value(ids)}};
    glb.node(node).extensions["MSFT_lod"] = tinygltf::Value(lod);
    tinygltf::Value::Object extras{{"MSFT_screencoverage", tinygltf::Value(coverage)}};
    glb.node(node).extras = tinygltf::Value(extras);
  }
  glb.useExtension("MSFT_lod");
  glb.write();
  return reports;
}

fs::path lodPath(const fs::path& path, size_t k) {
  fs::path out = path;
  out.replace_filename(path.stem().string() + "_lod" + std::to_string(k) + path.extension().string());
  return out;
}

std::vector<fs::path> partFiles(const std::vector<ExportPart>& parts, const fs::path& path) {
  std::vector<fs::path> files{path};
  if (meshFormatFor(path) != MeshFormat::Obj) return files;
  fs::path mtl = path;
  files.push_back(mtl.replace_extension(".mtl"));
  for (const ExportPart& part : parts)
    if (!part.mesh.triangles.empty() && part.material.texture) {
      fs::path png = path;
      files.push_back(png.replace_filename(path.stem().string() + "_" + objName(part.name) + ".png"));
      if (objNormalMap(part.material)) files.push_back(normalMapPath(path, part));
    }
  return files;
}

}  // namespace sprig
