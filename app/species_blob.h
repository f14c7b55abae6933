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
/// ```
/// Primitives: point, segment, cone (with `delta_a`, the δA offset of tree paper Eq. 4),
/// torus, halfspace, box, and the generator spiral_points (point primitives on a
/// logarithmic helico-spiral, murex paper Eq. 1-3). Operators: blend, ricci, union,
/// intersect, difference, controlled, pcm, negative, translate, scale, rotate, bend,
/// twist, taper. docs/readme/blob.md lists every key.
///
/// Every mistake is reported as `file:line:col: error: ...` (unknown kinds and keys with
/// "did you mean", wrong types, ranges, missing keys, invalid geometry from the builder);
/// all errors of a file are collected and thrown together as one InputError.

#include <filesystem>
#include <optional>
#include <string>

#include "app/yaml_reader.h"
#include "blobtree/blobtree.h"
#include "core/diagnostics.h"

namespace sprig {

/// A BlobTree read from a species file.
struct BlobSpecies {
  std::string name;           ///< `name:` (default: the file's stem)
  blobtree::BlobTree tree;    ///< the node pool
  blobtree::NodeId root = 0;  ///< the node the `blob:` key describes
  float cellSize = 0.0f;      ///< `mesh: {cell: ...}`; 0 = polygonizer's automatic size
};

/// Reads the blob keys (`kernel`, `blob`, `mesh`) of a `kind: blob` species from its
/// top-level map; the caller reads `kind`, `name` and the other shared keys and calls
/// top.finish(). Errors are added to diags; returns nullopt when the tree could not be
/// built.
std::optional<BlobSpecies> readBlobSpecies(MapReader& top, DiagnosticList& diags);

/// Reads one blob node (a map with one kind key) into tree, adding errors to diags.
/// Returns nullopt when the node (or a node below it) is invalid.
std::optional<blobtree::NodeId> readBlobNode(const YNode& node, blobtree::BlobTree& tree, DiagnosticList& diags);

/// Loads a whole `kind: blob` species file (keys: kind, name, description, kernel, blob,
/// mesh). Throws InputError with every diagnostic of the file.
BlobSpecies loadBlobSpecies(const std::filesystem::path& path);

/// Parses species text as if it were the file displayPath (tests). Throws as loadBlobSpecies.
BlobSpecies parseBlobSpecies(std::string text, const std::string& displayPath);

}  // namespace sprig
