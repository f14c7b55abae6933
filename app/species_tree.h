#pragma once
/// Reader of a tree species' `tree:` section into organisms::TreeOptions.
///
/// Every key is the snake_case name of a TreeOptions field (docs/TREES.md lists them with
/// their defaults); unknown keys are errors with "did you mean", wrong types and ranges
/// are reported at their file:line:col. Errors are collected into the caller's list.
/// ```
///   tree:
///     junctions: pcm            # smooth | pcm
///     delta_a: 1.75             # Eq. 4
///     delta_a_multi: 2.75       # Eq. 8
///     tips: taper               # taper | hemisphere
///     prune: {orders: [1], below_height: 2.0, probability: 1, cut_fraction: 0.4}
///     scars: {internodes: [12], stub_length: 1.5, negative_radius: 0.8}
///     bends: {angle: 15, order_scale: 0.8, randomness: 0.3}
///     bark: {texture: 1, u_scale: 1, v_scale: 2}
///     leaves: {enabled: true, scale: 1}
/// ```

#include "app/species.h"
#include "app/yaml_reader.h"
#include "blobtree/compiled.h"
#include "core/diagnostics.h"
#include "core/mesh.h"
#include "organisms/tree_builder.h"
#include "organisms/tree_options.h"
#include "render/scene.h"

namespace sprig {

/// Reads the `tree:` map `section` into options (starting from `defaults`), adding
/// every problem to diags. A null/empty section gives the defaults.
organisms::TreeOptions readTreeOptions(const YNode& section, DiagnosticList& diags,
                                       const organisms::TreeOptions& defaults = {});

/// Parses text holding one `tree:` map (the section itself, not the whole species file)
/// as if it were the file displayPath. Throws InputError with every diagnostic (tests).
organisms::TreeOptions parseTreeOptions(std::string text, const std::string& displayPath);

/// A tree species built into geometry: the BlobTree (and its compiled form) for the wood,
/// a Mesh for the leaves.
struct TreeModel {
  organisms::TreeOptions options;
  organisms::TreeBlob blob;
  blobtree::CompiledBlob compiled;
  Mesh leaves;
};

/// Reads species.treeSection (defaults when absent) and builds the tree of `skeleton`.
/// Throws InputError for a bad `tree:` section or an empty skeleton.
TreeModel buildTreeModel(const Species& species, const lsystem::Skeleton& skeleton);

/// Adds a tree to a scene for an exact render: registers the bark texture
/// (textures::BarkTexture, id options.bark.texture must be the scene's next texture id,
/// which holds for a fresh scene and the default id 0), a wood material with look.style.wood,
/// the wood as implicit geometry and the leaves as a mesh with look.style.leaf (vertex
/// colors win when present). Returns the wood's geometry id.
/// With `mesh` (the polygonized wood) the wood goes in as triangles instead (mesh mode).
uint32_t addTreeToScene(render::Scene& scene, const TreeModel& model, const SpeciesRender& look,
                        const render::ImplicitOptions& implicit = {},
                        const blobtree::PolygonizeResult* mesh = nullptr);

}  // namespace sprig
