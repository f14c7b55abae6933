#pragma once
/// The `shell:` section of a `kind: shell` species file (organisms/shell.h).
///
/// ```
///   kind: shell
///   shell:
///     preset: murex_cabritii     # optional starting point: none (default) or murex_cabritii
///     lambda: 1.3                # λ, ratio of radii one turn apart (Eq. 1)
///     beta: 22.5                 # β, degrees (Eq. 2)
///     r0: 0.2                    # R₀
///     whorls: 7
///     whorl_angle: 348           # degrees per whorl
///     section_angle: 116         # degrees per section (between varices)
///     surfaces_per_section: 6    # generating surfaces per section: Δθ = 116/6
///     age: 2436                  # θ_end, degrees (default whorls · whorl_angle)
///     stages: [696, 1392, 2436]  # ages of a growth sequence
///     seed: 1
///     generating: murex          # point | murex | {primitives: [...]}
///     varices: {spacing: 116, spines: [[[50, 0.8]], ...], ...}   # or `varices: false`
///     bumps: {sets: 5, size: 0.1, ...}                           # or `bumps: true`
///     axial_spines: {rows: [[0.96, 0.92], ...], ...}
///     opening: {inner_scale: 0.8, depth: 300, ...}
///     textures: {whorl: [0.8, 0.7, 0.6], cords: 12, ...}
///     pigment: {da: 0.01, db: 0.4, ...}                          # reaction-diffusion pattern
/// ```
/// docs/SHELLS.md lists every key with its default. Unknown keys are errors with "did you
/// mean"; every error is reported with file:line:col.

#include <memory>
#include <optional>
#include <vector>

#include "blobtree/compiled.h"
#include "render/scene.h"

#include "app/yaml_reader.h"
#include "organisms/shell.h"
#include "organisms/shell_paint.h"

namespace sprig {

/// A shell species: what to build and how to colour it.
struct ShellSpecies {
  organisms::ShellParams params;
  organisms::ShellTextureOptions textures;
  std::vector<double> stages;  ///< ages (θ_end, degrees) of a growth sequence; empty = automatic
  SourceLoc loc;               ///< position of the `shell:` section (for builder errors)
};

/// Reads a `shell:` section, adding every error to diags. Returns nullopt when the section
/// is not a map.
std::optional<ShellSpecies> readShellSpecies(const YNode& section, DiagnosticList& diags);

/// Parses a whole species text (`kind: shell` with its `shell:` section) as if it were the
/// file displayPath; for tests and tools. Throws InputError with every diagnostic.
ShellSpecies parseShellSpecies(std::string text, const std::string& displayPath);

/// Growth-stage ages for a shell: species.stages when given, else `count` ages evenly
/// spaced in whole whorls ending at the species' age.
std::vector<double> shellGrowthStages(const ShellSpecies& species, int count = 5);

/// A built shell ready to render: the model, its compiled field and its painter.
struct ShellBuild {
  organisms::ShellModel model;
  blobtree::CompiledBlob blob;  ///< compiled model.root (world space, apex up)
  std::shared_ptr<const organisms::ShellPainter> painter;
};

/// Builds and compiles the species' shell at `ageDeg` (θ_end; default the species' age).
/// Throws InputError at the `shell:` section for invalid parameters.
ShellBuild buildShellSpecies(const ShellSpecies& species, std::optional<double> ageDeg = std::nullopt);

/// Adds a built shell to a scene as exact implicit geometry with its part textures. The
/// part textures take texture ids 0-4 (organisms::ShellPart), so the scene must hold no
/// texture yet (throws std::logic_error otherwise). options.cellSize 0 picks
/// organisms::shellCellSize; the default root tolerance becomes
/// organisms::kShellTraceTolerance. Returns the geometry id.
/// With `mesh` (the polygonized shell) the shell goes in as triangles instead (mesh mode).
uint32_t addShellToScene(render::Scene& scene, const ShellBuild& shell, const render::ImplicitOptions& options = {},
                         const blobtree::PolygonizeResult* mesh = nullptr);

}  // namespace sprig
