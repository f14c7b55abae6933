#include "model/species.h"

#include <algorithm>
#include <cmath>

#include "core/atomic_file.h"
#include "core/paths.h"
#include "core/phases.h"
#include "model/kind_name.h"
#include "model/kinds.h"
#include "model/species_field.h"
#include "model/tree_kind.h"

namespace sprig {

namespace fs = std::filesystem;

namespace {

void readView(MapReader& m, render::ViewSpec& v) {
  v.azimuthDeg = m.number({"azimuth", "Camera direction around the vertical (+Y) axis, in degrees from +Z toward +X."}, v.azimuthDeg, -360.0, 360.0);
  v.elevationDeg = m.number({"elevation", "Camera height above the horizon, in degrees."}, v.elevationDeg, -89.0, 89.0);
  v.fovYDeg = m.number({"fov", "Vertical field of view of the camera, in degrees."}, v.fovYDeg, 1.0, 150.0);
  v.margin = m.number({"margin", "Free fraction of the half-frame left around the framed model."}, v.margin, 0.0, 0.9);
  m.finish();
}

void readLights(MapReader& m, render::RenderSettings& im, DiagnosticList& diags) {
  if (auto s = m.section({"sun", "Direction of the sun light: `azimuth` and `elevation` in degrees, and its `strength`."})) {
    MapReader sun(*s, diags, "render.sun");
    im.sunAzimuthDeg = sun.number({"azimuth", "Sun direction around +Y, in degrees from +Z toward +X."}, im.sunAzimuthDeg, -360.0, 360.0);
    im.sunElevationDeg = sun.number({"elevation", "Sun height above the horizon, in degrees (a low sun, 5 to 20, grazes the surface and shows its relief)."}, im.sunElevationDeg, 1.0, 90.0);
    im.sunStrength = static_cast<float>(sun.number({"strength", "Strength of the sun light."}, im.sunStrength, 0.0, 10.0));
    sun.finish();
  }
  if (auto r = m.section({"rim", "A rim light from behind the model, placed relative to the camera, that outlines silhouettes: `strength`, `azimuth`, `elevation`."})) {
    MapReader rim(*r, diags, "render.rim");
    im.rimStrength = static_cast<float>(rim.number({"strength", "Strength of the rim light (default 1 when `rim` is given; 0 = off)."}, 1.0, 0.0, 10.0));
    im.rimAzimuthDeg = rim.number({"azimuth", "Direction of the rim light around +Y, in degrees from the camera's direction (180 = straight behind the model)."}, im.rimAzimuthDeg, -360.0, 360.0);
    im.rimElevationDeg = rim.number({"elevation", "Height of the rim light above the horizon, in degrees."}, im.rimElevationDeg, 0.0, 90.0);
    rim.finish();
  }
}

void readCamera(MapReader& m, SpeciesRender& r, DiagnosticList& diags) {
  if (auto c = m.section({"camera", "An explicit camera instead of the automatic framing: `position` or `distance`, and `target`."})) {
    MapReader cam(*c, diags, "render.camera");
    CameraSpec spec;
    if (cam.has("position")) spec.position = cam.vec3({"position", "Camera position in world units (excludes `distance`)."}, Vec3(0), -1e6f, 1e6f);
    else cam.allow({"position"});
    if (cam.has("target")) spec.target = cam.vec3({"target", "The point the camera looks at (default: the centre of the framed box)."}, Vec3(0), -1e6f, 1e6f);
    else cam.allow({"target"});
    if (cam.has("distance")) spec.distance = cam.number({"distance", "Camera distance from the target along the view's direction (excludes `position`)."}, 1.0, 1e-6, 1e6);
    else cam.allow({"distance"});
    if (spec.position && spec.distance)
      c->error(diags, "render.camera: give either 'position' or 'distance', not both");
    if (spec.position && spec.target && *spec.position == *spec.target)
      c->error(diags, "render.camera: 'position' and 'target' are the same point (the camera would have no view direction)");
    cam.finish();
    r.camera = spec;
  }
  if (auto c = m.section({"close_up", "A close-up: the camera looks along `view`'s direction at one target and frames it: `point` with `size`, or a tree's `internode` or `junction` by index (excludes `camera`)."})) {
    MapReader close(*c, diags, "render.close_up");
    CloseUpSpec spec;
    spec.loc = c->loc();
    int targets = 0;
    if (close.has("point")) {
      spec.point = close.vec3({"point", "The world point the close-up frames (needs `size`)."}, Vec3(0), -1e6f, 1e6f);
      ++targets;
    } else {
      close.allow({"point"});
    }
    if (close.has("internode")) {
      spec.internode = static_cast<int>(close.integer({"internode", "Trees: frame the final stage's internode of this index (drawing order, 0 = the first `F`)."}, 0, 0, 10000000));
      ++targets;
    } else {
      close.allow({"internode"});
    }
    if (close.has("junction")) {
      spec.junction = static_cast<int>(close.integer({"junction", "Trees: frame the junction where the internode of this index leaves its parent."}, 0, 0, 10000000));
      ++targets;
    } else {
      close.allow({"junction"});
    }
    spec.size = close.number({"size", "World extent the frame's shorter side shows at the target's centre, less the margin (0: frame the part's own box; required with `point`)."}, 0.0, 0.0, 1e6);
    close.finish();
    if (targets != 1)
      c->error(diags, "render.close_up: give exactly one target: 'point', 'internode' or 'junction'");
    else if (spec.point && !(spec.size > 0))
      c->error(diags, "render.close_up: a 'point' needs a 'size' above 0 (the world extent to frame)");
    if (r.camera) c->error(diags, "render.close_up: give either 'camera' or 'close_up', not both");
    r.closeUp = spec;
  }
}

/// `render.inset`: read after every other `render:` key, since the inset's look starts as a
/// copy of the species' (its own camera and light replacing the species').
std::shared_ptr<const InsetSpec> readInset(MapReader& m, const SpeciesRender& parent, DiagnosticList& diags) {
  auto spec = std::make_shared<InsetSpec>();
  spec->fraction = m.number({"fraction", "The inset's width and height as a fraction of the picture's."}, spec->fraction, 0.1, 0.6);
  SpeciesRender& look = spec->look;
  look = parent;
  look.inset.reset();
  look.pair.reset();
  look.camera.reset();
  look.closeUp.reset();
  if (auto v = m.section({"view", "The inset camera's direction: `azimuth`, `elevation`, `fov`, `margin` (default: the picture's)."})) {
    MapReader view(*v, diags, "render.inset.view");
    readView(view, look.view);
  }
  readLights(m, look.image, diags);
  readCamera(m, look, diags);
  look.image.exposure = static_cast<float>(m.number({"exposure", "The inset's exposure in stops (default: the picture's)."}, look.image.exposure, -10.0, 10.0));
  look.image.fillStrength = static_cast<float>(m.number({"fill", "The inset's fill light from the camera (default: the picture's)."}, look.image.fillStrength, 0.0, 10.0));
  look.image.skyStrength = static_cast<float>(m.number({"sky", "The inset's sky light (default: the picture's)."}, look.image.skyStrength, 0.0, 10.0));
  m.finish();
  return spec;
}

void readRender(MapReader& m, SpeciesRender& r, const PathPolicy& policy, DiagnosticList& diags) {
  render::RenderSettings& im = r.image;
  im.width = static_cast<int>(m.integer({"width", "Image width in pixels."}, im.width, 16, 8192));
  im.height = static_cast<int>(m.integer({"height", "Image height in pixels."}, im.height, 16, 8192));
  im.spp = static_cast<int>(m.integer({"samples", "Camera samples per pixel (more: less noise, proportionally slower)."}, im.spp, 1, 1024));
  im.sampler = m.choice({"sampler", "Where the samples go: `zsobol` (Owen-scrambled Sobol' points in Morton order, less noise) or `stratified` (jittered strata, the older baseline)."}, "zsobol", {"zsobol", "stratified"}) == "stratified" ? render::Sampling::Stratified
                                                                                     : render::Sampling::ZSobol;
  im.thinMinPixels = static_cast<float>(m.number({"thin_min_pixels", "Curves and tree cones thinner than this many pixels are drawn this wide, with opacity true width / drawn width, so sub-pixel twigs stay continuous lines (0 = off)."}, im.thinMinPixels, 0.0, 8.0));
  r.dualMesher = m.choice({"mesher", "How polygonized surfaces (mesh-mode renders, `sprig mesh`) are meshed: `tetrahedra` (marching tetrahedra) or `dual` (dual marching cubes, about a third of the triangles)."}, r.dualMesher ? "dual" : "tetrahedra", {"tetrahedra", "dual"}) == "dual";
  r.simplify = m.number({"simplify", "Simplify polygonized surfaces by edge collapses while the geometric error stays below this fraction of the model's extent (0 = off)."}, r.simplify, 0.0, 0.1);
  if (auto w = m.section({"wind", "Wind that sways a tree in animations: `speed` and `direction`."})) {
    MapReader wind(*w, diags, "render.wind");
    r.windSpeed = wind.number({"speed", "Wind speed in m/s (0 = still air): the trunk leans with its square, branches sway and leaves flutter in proportion."}, r.windSpeed, 0.0, 60.0);
    r.windDirectionDeg = wind.number({"direction", "Azimuth the wind blows toward, in degrees around +Y from +Z toward +X."}, r.windDirectionDeg, -360.0, 360.0);
    wind.finish();
  }
  if (auto v = m.section({"view", "Automatic framing of the model: `azimuth`, `elevation`, `fov`, `margin`."})) {
    MapReader view(*v, diags, "render.view");
    readView(view, r.view);
  }
  std::string bg = m.choice({"background", "Behind the model: a sky `gradient`, a flat `color` (`background_color`), or `transparent` (alpha 0 in the PNG)."}, "gradient", {"gradient", "color", "transparent"});
  im.background = bg == "color" ? render::Background::Color
                 : bg == "transparent" ? render::Background::Transparent
                                       : render::Background::Gradient;
  im.backgroundColor = m.color({"background_color", "The background's colour with `background: color`."}, im.backgroundColor);
  im.ground = m.boolean({"ground", "Draw a ground plane under the model."}, im.ground);
  im.groundColor = m.color({"ground_color", "Colour of the ground plane."}, im.groundColor);
  readLights(m, im, diags);
  im.exposure = static_cast<float>(m.number({"exposure", "Exposure in stops: each +1 doubles the image's brightness."}, im.exposure, -10.0, 10.0));
  readCamera(m, r, diags);
  if (auto w = m.section({"wireframe", "Solids: draw the edges of the visible triangles (the tetrahedra's faces on the surface and on a section's cut) as thin lines over the surface: `color`, `width`."})) {
    MapReader wire(*w, diags, "render.wireframe");
    WireframeSpec spec;
    spec.color = wire.color({"color", "Colour of the wireframe's lines."}, spec.color);
    spec.widthPixels = wire.number({"width", "Width of the wireframe's lines in pixels (below `thin_min_pixels` they are drawn that wide, partly transparent)."}, spec.widthPixels, 0.1, 16.0);
    wire.finish();
    r.wireframe = spec;
  }
  if (auto c = m.section({"section", "Solids: a cut-away by the plane normal·x = offset, the side normal·x > offset removed (as `sprig render --section`): `normal`, `offset`."})) {
    MapReader cut(*c, diags, "render.section");
    const Vec3 n = cut.vec3({"normal", "The cutting plane's normal (not zero): the side it points to is removed."}, Vec3(0, 0, 1), -1e6, 1e6);
    const double d = cut.number({"offset", "The plane's offset d in normal·x = d (world units, scaled by the normal's length)."}, 0.0, -1e6, 1e6);
    cut.finish();
    if (n == Vec3(0)) c->error(diags, "render.section: 'normal' is zero (the plane has no side to remove)");
    r.section = Vec4(n, float(d));
  }
  const std::string rest = m.choice({"rest", "Shells: how the picture sets the shell down: `as_built` (apex up, standing as modelled), `aperture_up` or `aperture_down` (lying on the ground as a shell rests on a table: put down with its aperture facing up or down, then rolled to the nearest stable pose). Pictures only: exports keep the model's frame."}, "as_built", {"as_built", "aperture_up", "aperture_down"});
  r.rest = rest == "aperture_up" ? RestPose::ApertureUp : rest == "aperture_down" ? RestPose::ApertureDown : RestPose::None;
  r.pair = m.path({"pair", "Another species file: the picture shows this species and that one (at its final stage) side by side, seen by one camera framing both (this species' camera, light and size; each panel half the width)."}, policy);
  im.fillStrength = static_cast<float>(m.number({"fill", "Strength of an unshadowed fill light from the camera (0 = none)."}, im.fillStrength, 0.0, 10.0));
  im.skyStrength = static_cast<float>(m.number({"sky", "Strength of the sky light."}, im.skyStrength, 0.0, 10.0));
  im.unlitSkySamples = static_cast<int>(m.integer({"unlit_sky_samples", "Sky rays per camera sample where the sun adds nothing (in its shadow or facing away): smooths shadows and cavities lit by the sky alone (0 = one ray, as elsewhere)."}, im.unlitSkySamples, 0, 16));
  im.edgeSamples = static_cast<int>(m.integer({"edge_samples", "Extra camera samples for a pixel whose samples disagree (silhouettes, colour and shadow edges, twigs and spines thinner than a pixel): antialiasing spent where it shows (0 = none)."}, im.edgeSamples, 0, 64));
  im.skyFilter = m.boolean({"sky_filter", "Smooth the sky light's noise with the edge-avoiding filter: never across sharp creases, depth steps or colour edges (false: the raw samples)."}, im.skyFilter);
  im.refineSamples = static_cast<int>(m.integer({"refine_samples", "Extra camera samples for a pixel whose sky light the filter leaves noisy (a shadowed leaf in a crown, a fold with no like neighbour), found by a first pass and the filter's own variance estimate; the filter then runs again (0 = none; needs sky_filter)."}, im.refineSamples, 0, 64));
  if (im.refineSamples > 0 && !im.skyFilter)
    if (auto key = m.keyNode("refine_samples"))
      key->error(diags, "render.refine_samples needs the sky filter: it spends samples where the filter leaves noise (drop it, or set sky_filter: true)");
  r.surface.baseColor = m.color({"color", "Base colour of BlobTree surfaces in `sprig render`."}, r.surface.baseColor);
  r.surface.roughness = static_cast<float>(m.number({"roughness", "Roughness of BlobTree surfaces (0 mirror-like, 1 matte)."}, r.surface.roughness, 0.0, 1.0));
  r.surface.specular = static_cast<float>(m.number({"specular", "Specular reflectance of BlobTree surfaces."}, r.surface.specular, 0.0, 1.0));
  r.surface.metallic = static_cast<float>(m.number({"metallic", "How metallic the surface is (0 dielectric, 1 metal): the diffuse colour fades by 1 − metallic and the highlight takes the base colour's hue."}, r.surface.metallic, 0.0, 1.0));
  r.style.wood.baseColor = m.color({"wood", "Preview colour of internodes (branches and trunk)."}, r.style.wood.baseColor);
  r.style.leaf.baseColor = m.color({"leaf", "Preview colour of polygons and surfaces (leaves)."}, r.style.leaf.baseColor);
  r.style.fruit.baseColor = m.color({"fruit", "Preview colour of spheres (fruits, buds)."}, r.style.fruit.baseColor);
  for (const YNode& c : m.sequence({"palette", "Colours by turtle colour index (the grammar's `'` and `;` modules): entry 0, 1, 2 ..."}))
    if (auto col = c.asColor(diags, "'palette' entry")) r.style.palette.push_back(*col);
  r.style.radiusScale = m.number({"radius_scale", "Preview: multiplies every internode radius."}, r.style.radiusScale, 1e-6, 1e6);
  r.style.organs = m.boolean({"organs", "Preview: draw organs (leaves, flowers, fruits)."}, r.style.organs);
  if (auto s = m.section({"inset", "A detail drawn into the picture's lower right corner: the same stage through the inset's own `close_up` (or `camera`), `view`, `sun`, `rim`, `fill`, `sky` and `exposure`, `fraction` of the picture's width and height (a whole tree with one crotch of it)."})) {
    MapReader inset(*s, diags, "render.inset");
    r.inset = readInset(inset, r, diags);
  }
  m.finish();
}

/// Kinds Sprig names but does not build yet.
const std::vector<std::string> kReservedKinds = {};

Species readSpecies(std::shared_ptr<const YamlFile> yaml, const PathPolicy& policy, DiagnosticList& diags) {
  Species s;
  s.yaml = yaml;
  s.file = yaml->path();
  s.policy = policy;
  YNode root = yaml->rootNode();
  if (root.isNull() || !root.node().IsDefined()) {
    diags.error(SourceLoc{yaml->displayPath(), 1, 1}, "species file is empty");
    return s;
  }
  MapReader top(root, diags, "species file");
  if (!root.isMap()) return s;

  std::vector<std::string> names;
  for (const KindEntry& k : speciesKinds()) names.push_back(k.name);
  names.insert(names.end(), kReservedKinds.begin(), kReservedKinds.end());
  std::string list;
  for (size_t i = 0; i < names.size(); ++i)
    list += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];

  s.name = top.string({"name", "Shown in the gallery and in messages (default: the file's name without `.yaml`)."}, yaml->path().stem().string());
  s.description = top.string({"description", "A sentence or two shown in the gallery."});
  s.kind = "tree";
  if (auto k = top.get({"kind", "What the file describes: `tree`, `shell`, `blob`, `organism` or `solid`."})) {
    s.kindNode = k;
    if (auto text = k->asString(diags, "'kind'")) s.kind = *text;
  } else {
    root.error(diags, "missing required key 'kind' in species file (" + list + ")");
  }
  const KindEntry* kind = findKind(s.kind);
  if (!kind) {
    if (std::find(kReservedKinds.begin(), kReservedKinds.end(), s.kind) != kReservedKinds.end())
      s.kindNode->error(diags, "species kind '" + s.kind + "' is not supported by this version of Sprig");
    else
      s.kindNode->error(diags, "unknown species kind '" + s.kind + "' (" + list + ")" + didYouMean(s.kind, names));
    return s;
  }
  if (auto r = top.section({"render", "Image size, camera, light and colours of renders and previews."})) {
    MapReader render(*r, diags, "render");
    readRender(render, s.render, policy, diags);
    if (auto w = render.keyNode("wind"); w && s.kind != "tree")
      w->error(diags, "'render.wind' sways trees; " + speciesOfKind(s.kind) + " has no wind");
    if (auto w = render.keyNode("wireframe"); w && s.kind != "solid")
      w->error(diags, "'render.wireframe' draws the edges of a solid's tetrahedra; " + speciesOfKind(s.kind) + " has none");
    if (auto c = render.keyNode("rest"); c && s.kind != "shell" && s.render.rest != RestPose::None)
      c->error(diags, "'render.rest' sets a shell down on its side; " + speciesOfKind(s.kind) + " has no aperture to rest by");
    if (auto c = render.keyNode("section"); c && s.kind != "solid")
      c->error(diags, "'render.section' cuts a solid open; " + speciesOfKind(s.kind) + " has no inside to show");
    if (s.render.closeUp && s.kind != "tree" && (s.render.closeUp->internode >= 0 || s.render.closeUp->junction >= 0))
      if (auto c = render.keyNode("close_up"))
        c->error(diags, "'render.close_up' names an internode or a junction of a tree; " + speciesOfKind(s.kind) +
                            " has none (frame a 'point' with a 'size')");
  }
  for (const YNode& st : top.sequence({"stages", "Growth stages shown in the gallery's growth strip and by `--stage`: derivation steps of a tree, ages of a shell."}))
    if (auto v = st.asInteger(diags, "'stages' entry", 0, 100000)) s.stages.push_back(static_cast<int>(*v));
  s.spec = kind->read(top, s, diags);
  top.finish();
  return s;
}

}  // namespace

SourceLoc Species::loc() const { return kindNode ? kindNode->loc() : SourceLoc{file.string(), 1, 1}; }

render::RenderSettings SpeciesRender::settings(int imageWidth, int imageHeight) const {
  render::RenderSettings rs = image;
  rs.width = imageWidth;
  rs.height = imageHeight;
  return rs;
}

Species loadSpecies(const fs::path& path, const PathPolicy& given) {
  const Phase phase("read");
  const std::string ext = lowerExtension(path);
  PathPolicy policy = given;
  if (policy.root.empty()) policy.root = defaultLibraryRoot(path);
  SpeciesBuildScope builds;  // the species it references are built once each, kMaxSpeciesBuilds at most
  std::error_code ec;
  if (fs::is_directory(path, ec)) return speciesFromCpfgObject(path, policy);  // model/tree_kind.h
  if (ext == ".lsys" || ext == ".l") return speciesFromGrammarFile(path);
  if (ext != ".yaml" && ext != ".yml")
    throw InputError(SourceLoc{path.string(), 0, 0},
                     "unknown input extension '" + path.extension().string() +
                         "' (expected a species file .yaml/.yml, a grammar .lsys or .l, or a vlab object folder)");
  DiagnosticList diags;
  auto yaml = YamlFile::load(path, diags);
  if (!yaml) diags.throwIfErrors();
  Species s = readSpecies(yaml, policy, diags);
  diags.throwIfErrors();
  return s;
}

Species parseSpecies(std::string text, const std::string& displayPath, const PathPolicy& policy) {
  SpeciesBuildScope builds;
  DiagnosticList diags;
  auto yaml = YamlFile::parse(std::move(text), displayPath, diags);
  if (!yaml) diags.throwIfErrors();
  Species s = readSpecies(yaml, policy, diags);
  diags.throwIfErrors();
  return s;
}

namespace {

void collectStrings(const YAML::Node& n, std::vector<std::string>& out, int depth) {
  if (depth > 64 || out.size() > 10000) return;
  if (n.IsScalar()) {
    out.push_back(n.Scalar());
  } else if (n.IsSequence()) {
    for (const auto& c : n) collectStrings(c, out, depth + 1);
  } else if (n.IsMap()) {
    for (const auto& kv : n) collectStrings(kv.second, out, depth + 1);
  }
}

void addInputFiles(const fs::path& path, std::vector<fs::path>& out, int depth) {
  if (std::find(out.begin(), out.end(), path) != out.end()) return;
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(path, ec))
      if (e.is_regular_file()) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    out.insert(out.end(), files.begin(), files.end());
    return;
  }
  out.push_back(path);
  const std::string ext = lowerExtension(path);
  if (ext == ".l") {
    fs::path view = path;
    view.replace_extension(".v");
    out.push_back(view);  // watched even while missing: creating it changes the plant
    return;
  }
  if ((ext != ".yaml" && ext != ".yml") || depth > 8) return;
  std::vector<std::string> strings;
  try {
    collectStrings(YAML::LoadFile(path.string()), strings, 0);
  } catch (const std::exception&) {
    return;  // the reader reports it; the file itself is watched
  }
  for (const std::string& s : strings) {
    if (s.empty() || s.size() > 1024 || s.find('\n') != std::string::npos) continue;
    const fs::path p = (path.parent_path() / s).lexically_normal();
    if (fs::is_regular_file(p, ec)) addInputFiles(p, out, depth + 1);
  }
}

}  // namespace

std::vector<fs::path> speciesInputFiles(const fs::path& path) {
  std::vector<fs::path> out;
  addInputFiles(path, out, 0);
  return out;
}

std::vector<fs::path> listSpeciesFiles(const fs::path& folder) {
  std::vector<fs::path> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(folder, ec)) {
    if (!e.is_regular_file()) continue;
    std::string ext = lowerExtension(e.path());
    if (ext == ".yaml" || ext == ".yml") out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace sprig
