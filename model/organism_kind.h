#pragma once
/// `kind: organism` species: multi-scale procedural detail on a Catmull-Clark surface
/// (Velho, Perlin, Ying, Biermann 2002; organisms/multires.h, organisms/detail.h).
///
/// ```
///   kind: organism
///   organism:
///     base: {cube_sphere: {radius: 1, quads: 2}}   # or torus, cylinder, plane, revolution,
///                                                   # mesh: {file, faces}, species: {file, faces}
///     capture: {file: meshes/head.off}              # optional: analysed into `captured` detail
///     levels: 6                                     # Catmull-Clark levels (1..8)
///     detail:                                       # shape A: procedures, summed
///       - rock: {amplitude: 0.1, frequency: 2, levels: [1, 6], seed: 1}
///       - berry: {radius: 0.2, levels: [1, 3], seeds: {spacing: 0.35}}
///       - tentacle: {length: 0.05, angle_deg: 0, spin_deg: 90, levels: [1, 4], seeds: {control_vertices: true}}
///     blend:                                        # optional shape B, blended per level (§6)
///       detail: [ ... ]
///       alpha: {plane: {normal: [1, 2, 0], offset: 0, width: 0.6, transition: sharp}}
///       color: [0.5, 0.2, 0.1]                      # surface colour where alpha = 1
///     modify:                                       # local detail modification (§5.2)
///       - {center: [0, 1, 0], radius: 0.4, gains: [1, 1, 0, 2]}
///     shader: {planet: {relief: 0.05, sea_level: 0}} # post-blend shader of the scalar (§6.3)
///     frames: 24                                    # animation frames over time 0..1
/// ```
/// docs/ORGANISMS.md lists every key with its default. Every mistake is reported as
/// `file:line:col: error: ...` (unknown keys with "did you mean", ranges, a level range
/// outside the levels, a profile expression that does not parse).

#include <memory>
#include <optional>
#include <vector>

#include "model/kinds.h"
#include "model/yaml_reader.h"
#include "organisms/multires.h"
#include "organisms/subdivision.h"
#include "lsystem/expression.h"

namespace sprig {

/// The planet shader's colour bands, by height.
struct PlanetBands {
  Vec3 ocean{0.02f, 0.08f, 0.25f}, lowland{0.12f, 0.32f, 0.08f}, highland{0.35f, 0.28f, 0.18f}, ice{0.9f, 0.92f, 0.95f};
};

/// The post-blend planet shader (§6.3): the scalar channel h becomes a height above a sea
/// level, coloured by bands; the blend alpha mixes toward the second planet's own bands
/// when given, else tints the colours toward `tint`.
struct PlanetShader {
  float relief = 0.05f;     ///< world units of displacement per unit of h
  float seaLevel = 0.0f;    ///< h below this is ocean (flat at the sea level)
  float mountain = 0.05f;   ///< h above this is mountain
  float snow = 0.09f;       ///< h above this is snow
  PlanetBands bands;        ///< where alpha = 0 (and without a blend)
  std::optional<PlanetBands> second;  ///< where alpha = 1 (the second planet), if given
  Vec3 tint{0.55f, 0.2f, 0.35f};  ///< without `second`: colour shift where alpha = 1
  float tintStrength = 0.5f;
};

/// The planet shader's colour of scalar h and blend alpha a.
Vec3 planetColor(const PlanetShader& s, float h, float a);

/// The keys of an organism species (`organism:`), read and checked.
class OrganismSpec : public KindSpec {
 public:
  organisms::ControlMesh base;
  int levels = 5;
  organisms::DetailSet detail;
  organisms::DetailSet blendDetail;
  std::shared_ptr<const organisms::AlphaField> alpha;
  std::optional<Vec3> blendColor;
  /// The blend's own surface where alpha is 1 (roughness, specular, metallic; each optional,
  /// the render's where absent), mixed in by alpha like blendColor.
  std::optional<float> blendRoughness, blendSpecular, blendMetallic;
  std::vector<organisms::Modification> modifications;
  std::optional<PlanetShader> planet;
  std::shared_ptr<const organisms::DetailProcedure> captured;  ///< `capture:` analysed, or null
  size_t captureMisses = 0;  ///< finest vertices whose rays missed the captured mesh
  int frames = 1;        ///< animation stages over time 0..1 (1 = a still organism)
  bool animated = false; ///< some procedure, the alpha or the shader depends on time
  SourceLoc loc;

  std::string checkSummary(const Species& species) const override;
  std::unique_ptr<KindModel> makeModel(const Species& species, const ModelOptions& options) const override;
};

/// Reads the `organism:` section of a species file (required), adding every error to diags.
std::shared_ptr<const KindSpec> readOrganismSpec(MapReader& top, Species& species, DiagnosticList& diags);

/// The synthesized organism at one time: its limit mesh (no colours yet) and the finest
/// level's blend alpha and scalar (empty when unused).
struct OrganismSurface {
  Mesh mesh;
  std::vector<float> alpha, scalar;
};

/// Synthesizes the organism at time t (0..1) on subdivision (the refinement of spec.base to
/// spec.levels; kept by callers that synthesize many times); the planet shader's relief is applied.
OrganismSurface buildOrganismSurface(const OrganismSpec& spec, const organisms::Subdivision& subdivision, double time);

/// Faces of the finest level of spec's base refined to its levels.
size_t finestFaceCount(const organisms::ControlMesh& base, int levels);

/// Per-vertex colours of a surface: baseColor, blended toward the blend colour by alpha, or
/// the planet shader's colours.
std::vector<Vec3> organismColors(const OrganismSpec& spec, const OrganismSurface& surface, const Vec3& baseColor);

/// Per-vertex (roughness, specular, metallic) of a surface: the render's `surface` values,
/// blended toward the blend's own by alpha; empty when the blend sets none of them (the
/// material's apply everywhere).
std::vector<Vec3> organismSurfaces(const OrganismSpec& spec, const OrganismSurface& surface, const Vec3& renderSurface);

/// The organism at time t (0..1) as a triangle mesh with limit normals and per-vertex
/// colours (the material's base colour where nothing colours it).
Mesh buildOrganismMesh(const OrganismSpec& spec, double time, const Vec3& baseColor);

}  // namespace sprig
