#pragma once
/// `kind: blob` species: a BlobTree written out directly in YAML (the seeds' "procedural
/// interface" to the BlobTree: murex paper §2.2, tree paper §2).
///
/// A blob node is a map with exactly one key, the node's kind, whose value holds its
/// parameters; operators nest further nodes:
/// ```
///   kind: blob
///   kernel: wyvill                 # or soft
///   blob:
///     ricci:
///       n: 4
///       children:
///         - point: {center: [-0.6, 0, 0], radius: 1}
///         - segment: {a: [0.6, -1, 0], b: [0.6, 1, 0], radius: 0.5}
///   mesh: {cell: 0.02}             # optional default polygonization cell size
///   textures:                      # optional, texture ids 0, 1, ... in list order
///     - image: ../textures/maps/bark.png
///     - stripes: {frequency: 6, spiral: true}
/// ```
/// A primitive picks a texture with `texture: {id: N, u_scale, v_scale, ...}`; colors blend
/// by field weight across blends (tree paper §3.7). Primitives without `texture:` keep the
/// render surface color.
/// Primitives: point, segment, cone (with `delta_a`, the δA offset of tree paper Eq. 4),
/// torus, halfspace, box, and the generator spiral_points (point primitives on a
/// logarithmic helico-spiral, murex paper Eq. 1-3). Operators: blend, ricci, union,
/// intersect, difference, controlled, pcm, negative, translate, scale, rotate, bend,
/// twist, taper. docs/BLOBTREE.md ("`kind: blob` species") lists every key.
///
/// Every mistake is reported as `file:line:col: error: ...` (unknown kinds and keys with
/// "did you mean", wrong types, ranges, missing keys, invalid geometry from the builder);
/// all errors of a file are collected and thrown together as one InputError.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "model/kinds.h"
#include "model/yaml_reader.h"
#include "blobtree/blobtree.h"
#include "core/diagnostics.h"
#include "textures/bark_look.h"
#include "textures/registry.h"

namespace sprig {

/// A BlobTree read from a species file.
struct BlobSpecies {
  std::string name;           ///< `name:` (default: the file's stem)
  blobtree::BlobTree tree;    ///< the node pool
  blobtree::NodeId root = 0;  ///< the node the `blob:` key describes
  float cellSize = 0.0f;      ///< `mesh: {cell: ...}`; 0 = polygonizer's automatic size
  /// `textures:` in id order (null when the file has none): the primitives' texture ids.
  std::shared_ptr<const textures::TextureRegistry> textures;
  /// The branch bark ridge keys of the bark texture that sets them (`ridge_darkening`,
  /// `ridge_lines`, `ridge_relief`, `ridge_arc*`; at most one texture may): they shade the
  /// whole surface, its `pcm` seams and arcs over its branches (blobRidgeArcs). nullopt: none.
  std::optional<textures::BarkLook> ridge;
};

/// Texture id of primitives that name no texture: no texture is registered under it, so
/// the renderer shows the material's base color there (and blends it with neighbours).
inline constexpr uint16_t kNoTexture = 65535;

/// Reads a `textures:` list: each entry a map with one key naming its kind, `image: PATH`
/// (relative to the species file, checked with policy; opened through OpenImageIO now, so
/// a missing or unreadable file is an error at the path: "cannot read texture ..."),
/// `color: [r, g, b]`, or a procedural texture with its options (`noise`, `bark`,
/// `stripes`, `spots`, `leaf`). A bark texture reads the bark keys of tree species
/// (readBarkLook) plus `tile_v` and `seed`; when ridge is given, the first bark texture that
/// sets a branch bark ridge key stores its look there (a second one is an error). Errors go
/// to diags; returns the registry (entries with errors are left out, so check diags before
/// using it).
std::shared_ptr<const textures::TextureRegistry> readBlobTextures(const YNode& list, const PathPolicy& policy,
                                                                  DiagnosticList& diags,
                                                                  std::optional<textures::BarkLook>* ridge = nullptr);

/// The branches of a blob, as the branch bark ridge arcs need them: a segment or cone whose
/// start a lies on another's axis. Where a segment or cone passes through a (not at its
/// ends), it is the parent; where cones meet end to start, the one that ends at a is the
/// basal part, the starting one that best continues its direction the leader (the parent),
/// and every other one starting at a a branch; with no basal part there is no parent.
/// Primitives under bend, twist and taper warps, cutters (the second and later children
/// of difference and intersect) and negative fields are not branches; transforms apply
/// (radii scaled by the cube root of the determinant). Cost: O(n²) in the segments and cones.
std::vector<textures::RidgeArc> blobRidgeArcs(const blobtree::BlobTree& tree, blobtree::NodeId root);

/// Reads the blob keys (`kernel`, `blob`, `mesh`, `textures`) of a `kind: blob` species
/// from its top-level map; the caller reads `kind`, `name` and the other shared keys and
/// calls top.finish(). Texture files are resolved with policy and opened here. Errors are
/// added to diags; returns nullopt when the tree could not be built.
std::optional<BlobSpecies> readBlobSpecies(MapReader& top, DiagnosticList& diags, const PathPolicy& policy = {});

/// Reads one blob node (a map with one kind key) into tree, adding errors to diags.
/// textureCount >= 0 checks every `texture: {id}` against that many textures (-1: any id).
/// Returns nullopt when the node (or a node below it) is invalid.
std::optional<blobtree::NodeId> readBlobNode(const YNode& node, blobtree::BlobTree& tree, DiagnosticList& diags,
                                             int textureCount = -1);

/// Loads a whole `kind: blob` species file (keys: kind, name, description, kernel, blob,
/// mesh, textures; `render` and `stages` are passed over, loadSpecies checks them).
/// Throws InputError with every diagnostic of the file.
BlobSpecies loadBlobSpecies(const std::filesystem::path& path, const PathPolicy& policy = {});


/// The keys of a blob species (`blob`, `kernel`, `mesh`, `textures`), read and checked.
class BlobSpec : public KindSpec {
 public:
  BlobSpecies blob;

  std::string checkSummary(const Species& species) const override;
  std::unique_ptr<KindModel> makeModel(const Species& species, const ModelOptions& options) const override;
};

/// Reads the blob keys of a species file (the `blob:` tree is required), opening its
/// texture images, and adds every error to diags.
std::shared_ptr<const KindSpec> readBlobSpec(MapReader& top, Species& species, DiagnosticList& diags);

}  // namespace sprig
