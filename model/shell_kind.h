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
#include "model/kinds.h"
#include "render/geometry.h"

#include "model/yaml_reader.h"
#include "organisms/shell.h"
#include "organisms/shell_paint.h"

namespace sprig {

/// The keys of a shell species (`shell:`), read and checked.
class ShellSpec : public KindSpec {
 public:
  organisms::ShellParams params;
  organisms::ShellTextureOptions textures;
  std::vector<double> stages;  ///< ages (θ_end, degrees) of a growth sequence; empty = automatic
  SourceLoc loc;               ///< position of the `shell:` section (for builder errors)

  std::string checkSummary(const Species& species) const override;
  std::unique_ptr<KindModel> makeModel(const Species& species, const ModelOptions& options) const override;
};

/// Reads the `shell:` section of a species file (required), adding every error to diags.
std::shared_ptr<const KindSpec> readShellSpec(MapReader& top, Species& species, DiagnosticList& diags);

/// Reads a `shell:` section; nullopt when it is not a map (the error is in diags).
std::optional<ShellSpec> readShellSection(const YNode& section, DiagnosticList& diags);

/// Ages of the growth strip: the species' stages, else up to count ages evenly spaced from
/// the start to the final age (ages younger than one generating-surface step dropped).
std::vector<double> shellGrowthStages(const ShellSpec& species, int count = 5);

/// A shell built at one age.
struct ShellBuild {
  organisms::ShellModel model;
  std::shared_ptr<const blobtree::CompiledBlob> blob;  ///< compiled model.root (world space, apex up)
  std::shared_ptr<const organisms::ShellPainter> painter;
  bool rested = false;  ///< built in a resting pose (render.rest): the picture's ground touches its lowest point
};

/// Builds species at ageDeg (default: its age), turned by pose after the model's own frame
/// (organisms::ShellParams::pose; identity: the model itself). Throws InputError for
/// invalid parameters.
ShellBuild buildShell(const ShellSpec& species, std::optional<double> ageDeg = std::nullopt,
                      const glm::dmat4& pose = glm::dmat4(1.0));

/// Cells across the diagonal of the coarse surface shellRestingPose rolls the shell on.
inline constexpr float kRestPoseCells = 120.0f;

/// The pose of `render.rest` for a shell built in its own frame: the rigid turn (about the
/// centre of its box) that lays it on a horizontal ground as it comes to rest when put down
/// with its aperture (the spiral's tangent at the lip) facing up (apertureUp) or down, then
/// rolled downhill to the nearest stable pose (organisms::restingUp on a polygonized surface
/// of kRestPoseCells cells across, its centre of mass the enclosed volume's); the shell's
/// axis from apex to canal is then turned towards +x. The picture's ground then rests under
/// its lowest point (model/model.h restingFrame). restedBox, when given, receives the box of
/// the rested coarse surface, a cell wider each way (the frame of the pictures).
glm::dmat4 shellRestingPose(const ShellBuild& shell, bool apertureUp, Box3* restedBox = nullptr);

/// The shell as geometry: exact (mesh null) or the polygonized mesh, with the painter's
/// part textures as its texture table (ids = organisms::ShellPart).
render::Geometry shellGeometry(const ShellBuild& shell, std::shared_ptr<const blobtree::PolygonizeResult> mesh = nullptr);

}  // namespace sprig
