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

#include "app/yaml_reader.h"
#include "core/diagnostics.h"
#include "organisms/tree_options.h"

namespace sprig {

/// Reads the `tree:` map `section` into options (starting from `defaults`), adding
/// every problem to diags. A null/empty section gives the defaults.
organisms::TreeOptions readTreeOptions(const YNode& section, DiagnosticList& diags,
                                       const organisms::TreeOptions& defaults = {});

/// Parses text holding one `tree:` map (the section itself, not the whole species file)
/// as if it were the file displayPath. Throws InputError with every diagnostic (tests).
organisms::TreeOptions parseTreeOptions(std::string text, const std::string& displayPath);

}  // namespace sprig
