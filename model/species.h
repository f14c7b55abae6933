#pragma once
/// Species files (`species/*.yaml`) and bare grammars, read completely when loaded.
///
/// A species file names its kind and holds everything needed to grow and show one organism;
/// docs/MANUAL.md ("Species files") lists every key with its default. The keys every kind shares
/// (name, description, kind, render, stages) are read here; the kind's own keys are read by
/// the kind (model/kinds.h) into its typed value, Species::spec, in the same pass, so one
/// load reports every error of every section, each at its `file:line:col`.
///
/// A bare `.lsys` file is a tree species with default settings whose grammar is that file.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "lsystem/cpfg_texture.h"
#include "model/yaml_reader.h"
#include "render/camera.h"
#include "render/geometry.h"
#include "render/renderer.h"

namespace sprig {

class KindSpec;

/// An explicit camera (`render.camera:`); unset parts come from the automatic framing.
struct CameraSpec {
  std::optional<Vec3> position;    ///< `position: [x, y, z]`, the eye
  std::optional<Vec3> target;      ///< `target: [x, y, z]` (default: the center of the framed box)
  std::optional<double> distance;  ///< `distance`: eye at view.azimuth/elevation this far from target
};

/// A close-up (`render.close_up:`): the camera looks along `render.view`'s direction at one
/// target and frames it (with the view's margin) instead of the whole model. The target is
/// a world point with a size, or a part the kind can locate (trees: an internode or the
/// junction at an internode's base, by index in drawing order). Exactly one of point,
/// internode and junction is set.
struct CloseUpSpec {
  std::optional<Vec3> point;  ///< `point: [x, y, z]`: a world point (needs `size`)
  int internode = -1;         ///< `internode: i` (trees): the box of the final stage's i-th internode, radius included
  int junction = -1;          ///< `junction: i` (trees): where internode i leaves its parent, 4 of their radii across
  double size = 0;            ///< `size`: world extent across the frame's shorter side at the target's centre (0: frame the part's box)
  SourceLoc loc;              ///< the `close_up:` map, for targets found missing when the model is built
};

/// How a skeleton preview is sized and coloured (`render:` keys `wood`, `leaf`, `fruit`,
/// `palette`, `radius_scale`, `organs`).
struct SkeletonStyle {
  double radiusScale = 1.0;          ///< multiplies every internode radius
  double minRadiusFraction = 0.002;  ///< radius floor as a fraction of the skeleton's bounds diagonal
  render::Material wood{Vec3(0.30f, 0.20f, 0.12f), 0.7f, 0.03f};   ///< internodes
  render::Material leaf{Vec3(0.16f, 0.38f, 0.08f), 0.5f, 0.06f};   ///< polygons and named surfaces
  render::Material fruit{Vec3(0.55f, 0.08f, 0.06f), 0.35f, 0.08f};  ///< spheres
  /// Base colors by turtle color index (`'`); an organ whose index has an entry uses it.
  std::vector<Vec3> palette;
  bool organs = true;  ///< draw organs (polygons, spheres, named surfaces)
  /// A cpfg grammar's view file textures (`texture:` lines), which its textured surfaces
  /// (Organ::texture) wear; null for none.
  std::shared_ptr<const std::vector<lsystem::CpfgTexture>> cpfgTextures;
  /// A cpfg view file's background scene (`background scene:`), already in the plant's
  /// coordinates, each triangle in its material's diffuse colour; null for none.
  std::shared_ptr<const render::MeshPart> cpfgBackground;
  /// A cpfg grammar's view file `font:` (an X11 font name), the font of its `@L` labels;
  /// empty: cpfg's default (model/cpfg_labels.h).
  std::string cpfgFont;
};

/// Solids: `render.wireframe: {color, width}`: the edges of the visible triangles (the
/// tetrahedra's faces on the surface and on a section's cut) drawn as thin lines.
struct WireframeSpec {
  Vec3 color{0.02f};         ///< `color`: linear RGB of the lines
  double widthPixels = 1.0;  ///< `width`: line width in pixels at each end's depth
};

/// Shells: how a picture sets the shell down (`render.rest`).
enum class RestPose {
  None,          ///< `as_built`: as modelled (apex up, standing on its lowest point)
  ApertureUp,    ///< `aperture_up`: lying on the ground, put down aperture up, rolled to the nearest stable pose
  ApertureDown,  ///< `aperture_down`: the same, put down aperture down
};

struct InsetSpec;

/// How a species is shown (`render:`): the renderer's settings for its image, camera,
/// preview style and surface material.
struct SpeciesRender {
  /// `width`, `height`, `samples`, `background`, `background_color`, `ground`,
  /// `ground_color`, `sun: {azimuth, elevation}`, `exposure`, `fill`, `sky`.
  render::RenderSettings image;
  render::ViewSpec view;               ///< `view: {azimuth, elevation, fov, margin}`
  SkeletonStyle style;                 ///< skeleton previews
  std::optional<CameraSpec> camera;    ///< `camera: {position, target, distance}`
  std::optional<CloseUpSpec> closeUp;  ///< `close_up: {point, internode, junction, size}` (excludes `camera`)
  /// `pair: other.yaml`: the species' picture (`sprig render`, the gallery's final stage) is
  /// two panels side by side, this species and the other at its final stage, seen by one
  /// camera (renderPair, model/model.h). Resolved against the species file's folder.
  std::optional<std::filesystem::path> pair;
  /// `inset:`: a detail drawn into the picture's lower right corner (renderPicture,
  /// model/model.h): the same stage seen by the inset's own close-up, camera and light.
  std::shared_ptr<const InsetSpec> inset;
  /// Shells: `rest:` the pose pictures show the shell in (model/shell_kind.h); exports,
  /// `sprig mesh` and the model's measures keep the model's own frame.
  RestPose rest = RestPose::None;
  render::Material surface{Vec3(0.72f, 0.60f, 0.48f), 0.45f, 0.05f};  ///< `color`, `roughness`, `specular`, `metallic`: blob surfaces
  /// Solids: a cut-away by the plane n·x = d (xyz = n, w = d); the side n·x > d is removed
  /// (`sprig render --section`).
  std::optional<Vec4> section;
  /// Solids: `wireframe: {color, width}` (model/solid_kind.h wireframeCurves); unset: none.
  std::optional<WireframeSpec> wireframe;
  /// Trees: `wind: {speed, direction}`, the wind the gallery's animation sways the tree in
  /// (m/s, 0 = none; azimuth degrees it blows toward). `sprig animate` uses --wind instead.
  double windSpeed = 0;
  double windDirectionDeg = 0;
  /// `mesher: tetrahedra | dual`: how polygonized surfaces (mesh-mode renders, `sprig mesh`)
  /// are meshed: marching tetrahedra (the reference; a vertex on every crossing grid edge) or
  /// dual marching cubes (a third of the triangles); both closed and 2-manifold.
  bool dualMesher = false;
  /// `simplify`: polygonized surfaces (mesh-mode renders, `sprig mesh`) are simplified by
  /// edge collapses while the geometric error stays below this fraction of the surface's
  /// extent (organisms::simplifyToError, meshoptimizer); 0 (the default) keeps every triangle.
  double simplify = 0;
  /// Set by renderModel (never read from the file): the camera's pixel, so a mesh-mode build
  /// polygonizes at the cell the image needs (render::pixelCellSize); unset (`sprig mesh`,
  /// exports) polygonizes at the model's own cell.
  std::optional<render::PixelScale> pixels;
  /// Set by `sprig mesh` (never read from the file): with levels of detail and no --cell,
  /// the triangles a tree's polygonized wood needs (kLodCellMargin times LOD0's budget,
  /// model/lod.h); the wood is then polygonized at the coarser cell that gives about that
  /// many (lodCellSize, model/mesh_parts.h), never finer than its own automatic cell.
  /// 0: the automatic cell.
  size_t meshTriangles = 0;

  /// Renderer settings for an image of width x height.
  render::RenderSettings settings(int imageWidth, int imageHeight) const;
};

/// `render.inset`: a detail of the model drawn into the lower right corner of its picture
/// (whole + detail in one still: a whole tree and one crotch of it). The inset is `fraction`
/// of the picture's width and height and is rendered with `look`: the species' own `render:`
/// settings with the inset's `view`, `close_up` or `camera`, `sun`, `rim`, `fill`, `sky` and
/// `exposure` in their place.
struct InsetSpec {
  double fraction = 0.4;  ///< `fraction`: the inset's width and height over the picture's
  SpeciesRender look;     ///< how the inset is rendered (no inset or pair of its own)
};

/// One species, read and checked.
struct Species {
  std::string kind;         ///< `kind` ("tree", "shell", "blob")
  std::string name;         ///< `name` (default: the file's stem)
  std::string description;  ///< `description`
  std::filesystem::path file;  ///< the species (or grammar) file as given
  bool bareGrammar = false;    ///< true when file is a grammar (`.lsys`, `.l`, a vlab object folder), not a species file
  /// Notes and warnings from reading it (cpfg defaults used, view file keys ignored), for
  /// the commands to print.
  std::vector<Diagnostic> notes;
  std::vector<int> stages;     ///< `stages`: steps of a tree's growth strip (empty = automatic)
  SpeciesRender render;        ///< `render:`
  std::shared_ptr<const KindSpec> spec;  ///< the kind's own keys, typed (model/kinds.h)

  /// The parsed YAML (null for bare grammars), for positions in the file.
  std::shared_ptr<const YamlFile> yaml;
  std::optional<YNode> kindNode;  ///< the `kind:` value, for errors about the kind
  PathPolicy policy;              ///< the policy it was loaded with

  /// Where errors about the species as a whole point: its `kind:` value, else its first line.
  SourceLoc loc() const;
};

/// Reads a species file or a bare grammar (chosen by extension: .yaml/.yml, .lsys, cpfg's
/// .l, or a vlab object folder).
/// Referenced files must satisfy policy. Throws InputError with every diagnostic.
Species loadSpecies(const std::filesystem::path& path, const PathPolicy& policy = {});

/// Reads species text as if it were the file displayPath (tests). Throws as loadSpecies.
Species parseSpecies(std::string text, const std::string& displayPath, const PathPolicy& policy = {});

/// The files a species is read from, for watching them (`--watch`): the file itself (every
/// file of a vlab object folder; a cpfg `.l` file's view file `NAME.v`), and for a species
/// file every string value naming an existing file beside it (grammar, meshes, textures,
/// images), followed into referenced species files. Never throws: an unreadable or
/// malformed file is listed alone, so its repair is seen.
std::vector<std::filesystem::path> speciesInputFiles(const std::filesystem::path& path);

/// The species files of a folder (`*.yaml`, `*.yml`), sorted by name.
std::vector<std::filesystem::path> listSpeciesFiles(const std::filesystem::path& folder);

}  // namespace sprig
