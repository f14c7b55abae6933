#pragma once
/// Mesh export: binary PLY, Wavefront OBJ (+MTL) and glTF 2.0 binary (.glb).
///
/// Every writer builds the whole file in memory, writes it to a temporary next to the
/// destination (core/atomic_file.h) and renames it into place, so a reader never sees a
/// half-written mesh and a failed write leaves nothing behind. Output bytes depend only on
/// the mesh and the options (floats are printed in their shortest round-trip form), so the
/// same mesh gives the same file.
///
/// Optional per-vertex arrays (normals, uvs, colors) are written when they have one entry
/// per vertex; colors are linear RGB in the Mesh and are written sRGB-encoded as 8-bit in
/// PLY, as linear floats in glTF (COLOR_0, as the specification asks) and as sRGB floats
/// after the position in OBJ (the common `v x y z r g b` extension).

#include <atomic>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/mesh.h"
#include "core/mesh_corners.h"
#include "core/types.h"

namespace sprig {

/// Mesh file formats Sprig writes.
enum class MeshFormat { Ply, Obj, Glb };

/// Options shared by the mesh writers.
struct MeshWriteOptions {
  /// Name of the material in OBJ/MTL and glTF (OBJ uses `<name>_<id>` when the mesh has
  /// per-triangle material ids).
  std::string materialName = "sprig";
  /// Diffuse/base colour of the material, linear RGB in [0,1].
  Vec3 baseColor{0.8f, 0.8f, 0.8f};
  /// glTF roughness factor in [0,1].
  float roughness = 0.6f;
};

/// The format for a path's extension (.ply, .obj, .glb; case-insensitive).
/// Throws std::invalid_argument naming the path for any other extension.
MeshFormat meshFormatFor(const std::filesystem::path& path);

/// Writes mesh to path in the format its extension names (see meshFormatFor), atomically.
/// Throws std::invalid_argument for an unknown extension or an invalid mesh (an index out
/// of range, an optional array of the wrong length) and std::runtime_error when the file
/// cannot be written (the destination is then left untouched).
void writeMesh(const Mesh& mesh, const std::filesystem::path& path, const MeshWriteOptions& options = {});

/// Binary little-endian PLY: x y z [nx ny nz] [s t] [red green blue] per vertex,
/// `vertex_indices` (uchar count, uint indices) per face, and `material` (uint) per face
/// when the mesh has material ids. Throws as writeMesh.
void writePly(const Mesh& mesh, const std::filesystem::path& path);
/// writePly with extra header lines (each `comment ...\n`) after Sprig's own comment.
void writePly(const Mesh& mesh, const std::filesystem::path& path, const std::string& comments);

/// OBJ with `mtllib`, plus the MTL file beside it (same stem, `.mtl`); both are written
/// atomically, the MTL first. Indices are 1-based; faces are `v/vt/vn` as available.
/// Throws as writeMesh.
void writeObj(const Mesh& mesh, const std::filesystem::path& path, const MeshWriteOptions& options = {});

/// An image computed on first use: an export's atlas of the full-resolution mesh is baked
/// only when a file that holds that mesh is written (levels of detail bake their own
/// atlases, docs/MESHES.md "Levels of detail"). The bake must be deterministic, so the
/// bytes do not depend on when (or on which thread) it runs.
class DeferredImage {
 public:
  explicit DeferredImage(std::function<Image()> bake) : bake_(std::move(bake)) {}
  /// The image: baked on the first call (once, thread-safe; the bake's closure is then
  /// released), the same afterwards. A bake that throws is tried again on the next call.
  const Image& get();
  /// Whether the image has been baked.
  bool baked() const { return baked_.load(); }

 private:
  std::once_flag once_;
  std::function<Image()> bake_;
  Image image_;
  std::atomic<bool> baked_{false};
};

/// The zlib level of the PNGs the mesh writers store textures in (glb images, OBJ's
/// `STEM_PART.png`; PNG filter none, as before). On the Murex's 3792 x 3792 atlas and
/// normal map, level 6 (OpenImageIO's default, which the writers used before) took about
/// three times as long as level 4 for files 5 % smaller; level 1 saves a little more time
/// for files a fifth larger than level 6's. Every level decodes to the same pixels
/// (docs/PERFORMANCE.md "The Murex's glb in 30 s").
inline constexpr int kTexturePngLevel = 4;

/// A part's texture baked into an image: the colour at texture coordinate (s, t) of the
/// part's Mesh::uvs (origin at the image's bottom-left, as OBJ's vt) is the image's colour
/// there, absolute (not relative to the base colour). The writers store it as an 8-bit sRGB
/// PNG: embedded in glb, beside the OBJ.
struct PartTexture {
  /// Linear RGB, top row = t of 1. Alpha is ignored unless the part's material has an
  /// alphaCutoff: then the writers keep it (8-bit sRGB RGBA PNG).
  Image image;
  /// When set, the image is this deferred bake's (image stays empty): read it through
  /// pixels(). Copies of the texture share it, so it is baked at most once.
  std::shared_ptr<DeferredImage> deferred;
  /// When not empty, the texture's image as the PNG stores it (image stays empty and
  /// deferred null): the levels' atlases and normal maps (model/detail_maps.h) are baked
  /// straight into 8-bit values, 3 bytes a texel where image takes 16. Its encoding must be
  /// the writers' for the texture (TextureMap for an opaque base colour, Picture for a
  /// cut-out, Data for a normal map).
  Image8 image8;
  /// The texture's float image: `image`, or the deferred one (baked now if it was not yet);
  /// empty for an 8-bit texture (image8).
  const Image& pixels() const { return deferred ? deferred->get() : image; }
  /// The image's width and height, whichever form it has (a deferred image is baked now).
  int width() const { return image8.empty() ? pixels().width : image8.width; }
  int height() const { return image8.empty() ? pixels().height : image8.height; }
  UvSeamOptions seams;    ///< which axes repeat (glTF sampler REPEAT, else CLAMP_TO_EDGE) and the seam rules
  /// An atlas: when not empty, the texture coordinates of every triangle's corners (3 per
  /// triangle of the part's mesh, values in [0,1]), used instead of the mesh's uvs (which
  /// the mesh then need not have) and without seam rules. Each triangle owns a patch of
  /// the image, so the glTF sampler has no mipmaps (a smaller level would mix patches) and
  /// clamps at the edges.
  CornerTable<Vec2> atlas;
  int atlasCell = 0;  ///< texels per side of a triangle's patch in an atlas (reports)
  /// glTF sampler filters. Default: magFilter LINEAR, minFilter LINEAR_MIPMAP_LINEAR
  /// (atlases LINEAR); Nearest and Linear set the filter to that, without mipmaps.
  enum class Filter { Default, Nearest, Linear };
  Filter magFilter = Filter::Default;
  Filter minFilter = Filter::Default;
  bool isAtlas() const { return !atlas.index.empty(); }
};

struct PartMaterial;
/// Whether a part's normal map has texture coordinates of its own: an atlas beside a base
/// colour image over the mesh's own uvs (PartMaterial::normalTexture: glTF TEXCOORD_1; the
/// OBJ writer leaves such a normal map out).
bool normalMapOwnsUvs(const PartMaterial& material);

/// The material of an exported part.
struct PartMaterial {
  std::string name = "sprig";  ///< material name in glTF and MTL (letters, digits, '_' in OBJ)
  Vec3 baseColor{0.8f};        ///< linear RGB in [0,1]: glTF baseColorFactor and MTL Kd, both as these linear numbers
  float roughness = 0.6f;      ///< glTF roughnessFactor in [0,1]
  bool doubleSided = false;    ///< glTF doubleSided (leaves: both faces are seen)
  /// The part's colours as an image (the part's mesh must then have uvs, or the texture an
  /// atlas), or null. A
  /// textured material has baseColorFactor and Kd 1 (the image holds absolute colours; both
  /// formats multiply the factor in), keeps baseColor in glTF's material extras as
  /// `sprigBaseColor`, and has no COLOR_0 (it would multiply again).
  std::shared_ptr<const PartTexture> texture;
  /// Cut-out: when >= 0 (with a texture), the texture's alpha is kept and texels whose alpha
  /// is below this are not drawn: glTF alphaMode MASK with this alphaCutoff, MTL map_d
  /// naming the texture image. Negative: opaque.
  float alphaCutoff = -1.0f;
  /// A tangent-space normal map, or null: either in texture's atlas layout (texture an
  /// atlas of the same image size; the corners of texture's atlas address it), or, beside a
  /// texture over the mesh's own uvs (not an atlas), an atlas of its own (its `atlas`
  /// corners address it: a second set of texture coordinates). Its image holds encoded
  /// normals ((n + 1)/2 per channel, x along the tangent, y up the image, z along the vertex
  /// normal), written without an sRGB curve. glTF: the material's normalTexture (texCoord 1
  /// and a TEXCOORD_1 attribute for an atlas of its own) and a TANGENT attribute
  /// (cornerTangent of each corner in the normal map's coordinates: unit, w = ±1); OBJ: `norm
  /// STEM_PART_normal.png` in the MTL for a shared atlas (OBJ gives a corner one uv: a normal
  /// map with coordinates of its own is not written); PLY: nothing.
  std::shared_ptr<const PartTexture> normalTexture;
  float metallic = 0.0f;       ///< glTF metallicFactor in [0,1] (MTL has no portable form)
};

/// An application-specific per-vertex attribute of a glTF export (e.g. a tree's `_WIND`,
/// model/wind_export.h): VEC4 floats, one per vertex of the part's mesh. The name starts
/// with '_' (glTF 2.0 §3.7.2.1); other formats do not write it.
struct VertexAttribute {
  std::string name;
  std::vector<glm::vec4> values;
};

/// Morph targets of a part and the looping animation of their weights (glTF only; a tree's
/// wind sway, model/wind_export.h). Each target is a displacement per vertex of the part's
/// mesh; weights[k][f] is target k's weight at times[f]. The writer stores the targets
/// with their names (mesh extras `targetNames`, the names Blender's shape keys and three.js'
/// morphTargetDictionary take), default weights 0, and gathers the animations of every part
/// with the same `animation` name into one glTF animation: one sampler (LINEAR) per node,
/// its channel driving the node's `weights`.
struct PartMorph {
  std::vector<std::string> names;
  std::vector<std::vector<Vec3>> targets;
  std::string animation;
  std::vector<float> times;
  std::vector<std::vector<float>> weights;
};

/// One named part of an exported model (wood, leaves, whorl, a solid's material, ...).
/// Vertex colours, when the mesh has them, are the part's colours at its vertices; the
/// writers keep them relative to the material's base colour (see writeParts).
struct ExportPart {
  std::string name;  ///< node name in glTF, object name in OBJ
  Mesh mesh;
  PartMaterial material;
  /// Many small separate pieces (leaves): levels of detail (model/lod.h) keep a share of
  /// the pieces, grown to keep their area, instead of simplifying each piece.
  bool scattered = false;
  /// Application-specific vertex attributes (glTF only), each one value per vertex.
  std::vector<VertexAttribute> attributes;
  /// Morph targets and their animation (glTF only), or null.
  std::shared_ptr<const PartMorph> morph;
};

/// One level of detail of a model (model/lod.h buildLodChain makes them): the parts, with
/// the same names in the same order at every level, and the MSFT_screencoverage threshold
/// (the fraction of the screen's area below which the next level is drawn; 0: never culled).
struct LodLevel {
  std::vector<ExportPart> parts;
  size_t triangles = 0;
  double screenCoverage = 0;
};

/// Writes parts to path in the format its extension names, atomically, each part kept
/// apart: glTF (.glb) one node, mesh and material per part, named after the part;
/// COLOR_0, when the part's mesh has colours, is each colour divided by the material's
/// base colour per channel (glTF multiplies them) and clamped to [0,1]. OBJ one object
/// (`o`) and one material (`usemtl`) per part, its MTL with the base colours, vertex
/// colours after the positions as in writeObj. PLY one mesh with a colour at every vertex
/// (a part without vertex colours gets its base colour) and the part's index as each
/// face's `material`; the header names the parts in comments (`comment part 0 wood`).
/// Parts without triangles are skipped. Throws as writeMesh, and std::invalid_argument
/// when two parts share a name.
///
/// Normals: glTF and OBJ split them at creases (splitCreaseNormals: faces around a vertex
/// more than 90° apart), glTF by duplicating the vertex, OBJ by its own `vn` index; PLY
/// keeps one normal per vertex. Textures (PartMaterial::texture): glTF embeds the PNG as a
/// bufferView image referenced by baseColorTexture (seams duplicated as for creases);
/// OBJ writes `STEM_PART.png` beside the OBJ (each file atomically, the images first,
/// then the MTL with `map_Kd`, then the OBJ; a failure removes the images it wrote) and
/// per-corner `vt` indices; PLY keeps its per-vertex colours and names the images nowhere.
/// Returns what was done per part.
struct PartWriteReport {
  std::string name;
  size_t creaseVertices = 0;  ///< vertices given more than one normal (glTF, OBJ)
  size_t seamCorners = 0;     ///< uv values added at texture seams (glTF, OBJ)
  int textureWidth = 0, textureHeight = 0;  ///< the texture image's size, 0 without one
  int atlasCell = 0;  ///< texels per side of each triangle's patch when the texture is an atlas, else 0
};
std::vector<PartWriteReport> writeParts(const std::vector<ExportPart>& parts, const std::filesystem::path& path);

/// Writes a model's levels of detail to one .glb, atomically: levels[0]'s parts as
/// writeParts writes them (the scene's nodes, named after the parts), every further level's
/// part as a node outside the scene named `PART_lodK` (its material keeps the part's name;
/// an image shared between levels is stored once), and each LOD0 node carries the
/// extension MSFT_lod (`ids`: its part's nodes of levels 1, 2, ...; listed in
/// extensionsUsed, not extensionsRequired) and `extras.MSFT_screencoverage` (one threshold
/// per level). A reader without the extension shows LOD0. One level writes what writeParts
/// writes. Returns the reports of LOD0's parts. Throws as writeParts, and
/// std::invalid_argument for a path that is not .glb or levels whose part names differ.
std::vector<PartWriteReport> writePartLevels(const std::vector<LodLevel>& levels, const std::filesystem::path& path);

/// While an object of this class lives, the glTF writers on its thread encode each texture
/// image once: the PNG bytes made for one file are reused, byte for byte, by every later
/// file that holds the same image (writeLevels: `OUT_lodK.glb` and `OUT.glb` share their
/// images). The images written meanwhile must stay alive and unchanged. Scopes nest (the
/// innermost holds the bytes).
class PngReuse {
 public:
  PngReuse();
  ~PngReuse();
  PngReuse(const PngReuse&) = delete;
  PngReuse& operator=(const PngReuse&) = delete;
  /// PNG images encoded in this scope so far (reuses not counted).
  size_t encoded() const;
  /// Encodes now, two or more at a time (core/parallel.h), every texture image the glTF
  /// writers will write for parts (each image and encoding once; those this scope holds
  /// already are skipped), so that the writers that follow only reuse the bytes. near: a
  /// path beside which the temporary files go (the output's).
  void encodeAhead(const std::vector<const ExportPart*>& parts, const std::filesystem::path& near);
  /// The innermost scope alive on this thread, or null.
  static PngReuse* innermost();
  /// encode()'s bytes for tex's image in encoding (an ImageEncoding), made at the first
  /// call for that image and encoding in this scope and reused after.
  const std::string& once(const PartTexture& tex, int encoding, const std::function<std::string()>& encode);

 private:
  struct Cache;
  std::unique_ptr<Cache> cache_;
  PngReuse* outer_ = nullptr;
};

/// The path of level k's own file beside path: `STEM_lodK.EXT`.
std::filesystem::path lodPath(const std::filesystem::path& path, size_t k);

/// Every file writeParts(parts, path) writes: path, and for OBJ its MTL and the images of
/// its textured parts (`STEM_PART.png`).
std::vector<std::filesystem::path> partFiles(const std::vector<ExportPart>& parts, const std::filesystem::path& path);

/// How many colour channels writeParts clamps in glTF's COLOR_0 (a vertex brighter than its
/// part's base colour in a channel); 0 means the glTF shows every vertex colour exactly
/// (always for a textured part, which has no COLOR_0).
size_t clampedColorChannels(const ExportPart& part);

/// glTF 2.0 binary through TinyGLTF: one mesh, one primitive (triangles), POSITION
/// (with min/max), NORMAL, TEXCOORD_0 (v flipped to glTF's top-left origin), COLOR_0,
/// uint32 indices, one metallic-roughness material. Throws as writeMesh.
void writeGlb(const Mesh& mesh, const std::filesystem::path& path, const MeshWriteOptions& options = {});

}  // namespace sprig
