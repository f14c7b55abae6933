#include "app/species.h"

#include <algorithm>
#include <cmath>

#include "core/atomic_file.h"
#include "core/paths.h"

namespace sprig {

namespace fs = std::filesystem;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

void readView(MapReader& m, render::ViewSpec& v) {
  v.azimuthDeg = m.number("azimuth", v.azimuthDeg, -360.0, 360.0);
  v.elevationDeg = m.number("elevation", v.elevationDeg, -89.0, 89.0);
  v.fovYDeg = m.number("fov", v.fovYDeg, 1.0, 150.0);
  v.margin = m.number("margin", v.margin, 0.0, 0.9);
  m.finish();
}

void readRender(MapReader& m, SpeciesRender& r, DiagnosticList& diags) {
  r.width = static_cast<int>(m.integer("width", r.width, 16, 8192));
  r.height = static_cast<int>(m.integer("height", r.height, 16, 8192));
  r.samples = static_cast<int>(m.integer("samples", r.samples, 1, 1024));
  if (auto v = m.section("view")) {
    MapReader view(*v, diags, "render.view");
    readView(view, r.view);
  }
  std::string bg = m.choice("background", "gradient", {"gradient", "color", "transparent"});
  r.background = bg == "color" ? render::Background::Color
                 : bg == "transparent" ? render::Background::Transparent
                                       : render::Background::Gradient;
  r.backgroundColor = m.color("background_color", r.backgroundColor);
  r.ground = m.boolean("ground", r.ground);
  r.groundColor = m.color("ground_color", r.groundColor);
  if (auto s = m.section("sun")) {
    MapReader sun(*s, diags, "render.sun");
    r.sunAzimuthDeg = sun.number("azimuth", r.sunAzimuthDeg, -360.0, 360.0);
    r.sunElevationDeg = sun.number("elevation", r.sunElevationDeg, 1.0, 90.0);
    sun.finish();
  }
  r.exposure = static_cast<float>(m.number("exposure", r.exposure, -10.0, 10.0));
  if (auto c = m.section("camera")) {
    MapReader cam(*c, diags, "render.camera");
    CameraSpec spec;
    if (cam.has("position")) spec.position = cam.vec3("position", Vec3(0), -1e6f, 1e6f);
    else cam.allow({"position"});
    if (cam.has("target")) spec.target = cam.vec3("target", Vec3(0), -1e6f, 1e6f);
    else cam.allow({"target"});
    if (cam.has("distance")) spec.distance = cam.number("distance", 1.0, 1e-6, 1e6);
    else cam.allow({"distance"});
    if (spec.position && spec.distance)
      c->error(diags, "render.camera: give either 'position' or 'distance', not both");
    cam.finish();
    r.camera = spec;
  }
  r.fill = static_cast<float>(m.number("fill", r.fill, 0.0, 10.0));
  r.sky = static_cast<float>(m.number("sky", r.sky, 0.0, 10.0));
  r.surface.baseColor = m.color("color", r.surface.baseColor);
  r.surface.roughness = static_cast<float>(m.number("roughness", r.surface.roughness, 0.0, 1.0));
  r.surface.specular = static_cast<float>(m.number("specular", r.surface.specular, 0.0, 1.0));
  r.style.wood.baseColor = m.color("wood", r.style.wood.baseColor);
  r.style.leaf.baseColor = m.color("leaf", r.style.leaf.baseColor);
  r.style.fruit.baseColor = m.color("fruit", r.style.fruit.baseColor);
  for (const YNode& c : m.sequence("palette"))
    if (auto col = c.asColor(diags, "'palette' entry")) r.style.palette.push_back(*col);
  r.style.radiusScale = m.number("radius_scale", r.style.radiusScale, 1e-6, 1e6);
  r.style.organs = m.boolean("organs", r.style.organs);
  m.finish();
}

void readTurtle(MapReader& m, Species& s) {
  auto& t = s.turtle;
  t.stepLength = m.number("step", t.stepLength, 1e-9, 1e9);
  if (m.has("angle")) {
    t.angleDeg = m.number("angle", t.angleDeg, -360.0, 360.0);
    s.angleSet = true;
  } else {
    m.allow({"angle"});
  }
  t.initialWidth = m.number("width", t.initialWidth, 0.0, 1e9);
  t.widthScale = m.number("width_scale", t.widthScale, 1e-9, 1e9);
  t.widthFactor = m.number("width_factor", t.widthFactor, 1e-6, 1e6);
  t.tropism = DVec3(m.vec3("tropism", Vec3(t.tropism), -1e6, 1e6));
  t.elasticity = m.number("elasticity", t.elasticity, -10.0, 10.0);
  std::string radii = m.choice("radii", "width", {"width", "pipe"});
  t.radii = radii == "pipe" ? lsystem::RadiusModel::Pipe : lsystem::RadiusModel::Width;
  t.pipeExponent = m.number("pipe_exponent", t.pipeExponent, 0.5, 10.0);
  t.tipRadius = m.number("tip_radius", t.tipRadius, 1e-9, 1e9);
  t.taper = m.boolean("taper", t.taper);
  t.surfaceScale = m.number("surface_scale", t.surfaceScale, 1e-9, 1e9);
  t.maxWidthToLength = m.number("max_width_to_length", t.maxWidthToLength, 0.0, 1e6);
  m.finish();
}

/// Reads `grammar:`: inline text (contains a newline) or a path relative to the species file.
void readGrammar(MapReader& top, Species& s, const PathPolicy& policy, DiagnosticList& diags) {
  auto g = top.get("grammar");
  if (!g) {
    top.node().error(diags, "missing required key 'grammar' in species file");
    return;
  }
  auto text = g->asString(diags, "'grammar'");
  if (!text) return;
  if (text->find('\n') != std::string::npos) {
    s.grammarText = *text;
    s.grammarFile = s.yaml->displayPath();
    // A block scalar's content starts on the line after its indicator; find that line's
    // indentation so grammar positions map back into the species file.
    SourceLoc at = g->loc();
    const std::string indicatorLine = s.yaml->sourceLine(at.line);
    const bool block = at.col >= 1 && at.col <= static_cast<int>(indicatorLine.size()) &&
                       (indicatorLine[at.col - 1] == '|' || indicatorLine[at.col - 1] == '>');
    int line = block ? at.line + 1 : at.line;  // quoted multi-line strings map approximately
    const std::string& yamlText = s.yaml->text();
    const int lines = static_cast<int>(std::count(yamlText.begin(), yamlText.end(), '\n')) + 1;
    s.grammarLineOffset = line - 1;
    for (int l = line; l <= lines; ++l) {
      std::string src = s.yaml->sourceLine(l);
      size_t nonSpace = src.find_first_not_of(' ');
      if (nonSpace != std::string::npos) {
        s.grammarColOffset = static_cast<int>(nonSpace);
        break;
      }
    }
    return;
  }
  if (auto p = resolveReference(*g, *text, policy, diags)) {
    try {
      s.grammarText = readFile(*p);
      s.grammarFile = p->string();
    } catch (const std::exception& e) {
      g->error(diags, "cannot read grammar file '" + p->string() + "'");
    }
  }
}

void readDefines(MapReader& top, Species& s, DiagnosticList& diags) {
  auto d = top.section("defines");
  if (!d) return;
  for (auto& [k, v] : d->pairs()) {
    if (!k.isScalar()) continue;
    auto value = v.asNumber(diags, "'defines." + k.scalar() + "'");
    if (value) s.overrides.defines.push_back(lsystem::DefineOverride{k.scalar(), *value, k.loc()});
  }
}

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

  s.name = top.string("name", yaml->path().stem().string());
  s.description = top.string("description");
  std::string kind = "tree";
  if (auto k = top.get("kind")) {
    s.kindNode = k;
    if (auto text = k->asString(diags, "'kind'")) kind = *text;
  } else {
    root.error(diags, "missing required key 'kind' in species file (tree, shell, blob, organism or solid)");
  }
  static const std::vector<std::string> kinds = {"tree", "shell", "blob", "organism", "solid"};
  if (std::find(kinds.begin(), kinds.end(), kind) == kinds.end()) {
    s.kindNode->error(diags, "unknown species kind '" + kind + "' (tree, shell, blob, organism or solid)" +
                                 didYouMean(kind, kinds));
    return s;
  }
  if (kind == "organism" || kind == "solid") {
    s.kindNode->error(diags, "species kind '" + kind + "' is not supported by this version of Sprig");
    return s;
  }
  s.kind = kind == "tree" ? SpeciesKind::Tree : kind == "shell" ? SpeciesKind::Shell : SpeciesKind::Blob;

  if (auto r = top.section("render")) {
    MapReader render(*r, diags, "render");
    readRender(render, s.render, diags);
  }
  for (const YNode& st : top.sequence("stages"))
    if (auto v = st.asInteger(diags, "'stages' entry", 0, 100000)) s.stages.push_back(static_cast<int>(*v));

  switch (s.kind) {
    case SpeciesKind::Tree: {
      readGrammar(top, s, policy, diags);
      readDefines(top, s, diags);
      if (top.has("steps"))
        s.overrides.derivationLength = static_cast<int>(top.integer("steps", 0, 0, 100000));
      else
        top.allow({"steps"});
      if (top.has("seed"))
        s.overrides.seed = static_cast<uint64_t>(top.integer("seed", 0, 0));
      else
        top.allow({"seed"});
      s.maxModules = static_cast<size_t>(top.integer("max_modules", static_cast<int64_t>(s.maxModules), 1,
                                                     int64_t(4'000'000'000)));
      if (auto t = top.section("turtle")) {
        MapReader turtle(*t, diags, "turtle");
        readTurtle(turtle, s);
      }
      s.treeSection = top.section("tree");
      break;
    }
    case SpeciesKind::Shell:
      s.shellSection = top.section("shell");
      if (!s.shellSection && !top.has("shell")) root.error(diags, "missing required key 'shell' in species file");
      break;
    case SpeciesKind::Blob:
      // Read by app/species_blob (readBlobSpecies) where a command needs the BlobTree.
      top.allow({"kernel", "blob", "mesh", "textures"});
      if (!top.has("blob")) root.error(diags, "missing required key 'blob' in species file");
      break;
    default: break;
  }
  top.finish();
  return s;
}

Species speciesFromGrammarFile(const fs::path& path) {
  Species s;
  s.bareGrammar = true;
  s.file = path;
  s.name = path.stem().string();
  try {
    s.grammarText = readFile(path);
  } catch (const std::exception&) {
    throw InputError(SourceLoc{path.string(), 0, 0}, "cannot open file");
  }
  s.grammarFile = path.string();
  // ABOP widths are pixel widths: keep a bare grammar's internodes slender (lsystem/turtle.h).
  s.turtle.maxWidthToLength = 0.12;
  return s;
}

}  // namespace

const char* speciesKindName(SpeciesKind kind) {
  switch (kind) {
    case SpeciesKind::Tree: return "tree";
    case SpeciesKind::Shell: return "shell";
    case SpeciesKind::Blob: return "blob";
    case SpeciesKind::Organism: return "organism";
    case SpeciesKind::Solid: return "solid";
  }
  return "tree";
}

render::RenderSettings SpeciesRender::settings(int imageWidth, int imageHeight) const {
  render::RenderSettings rs;
  rs.width = imageWidth;
  rs.height = imageHeight;
  rs.spp = samples;
  rs.background = background;
  rs.backgroundColor = backgroundColor;
  rs.ground = ground;
  rs.groundColor = groundColor;
  rs.sunAzimuthDeg = sunAzimuthDeg;
  rs.sunElevationDeg = sunElevationDeg;
  rs.exposure = exposure;
  rs.fillStrength = fill;
  rs.skyStrength = sky;
  return rs;
}

Species loadSpecies(const fs::path& path, const PathPolicy& policy) {
  const std::string ext = lowerExtension(path);
  if (ext == ".lsys") return speciesFromGrammarFile(path);
  if (ext != ".yaml" && ext != ".yml")
    throw InputError(SourceLoc{path.string(), 0, 0},
                     "unknown input extension '" + path.extension().string() +
                         "' (expected a species file .yaml/.yml or a grammar .lsys)");
  DiagnosticList diags;
  auto yaml = YamlFile::load(path, diags);
  if (!yaml) diags.throwIfErrors();
  Species s = readSpecies(yaml, policy, diags);
  diags.throwIfErrors();
  return s;
}

Species parseSpecies(std::string text, const std::string& displayPath, const PathPolicy& policy) {
  DiagnosticList diags;
  auto yaml = YamlFile::parse(std::move(text), displayPath, diags);
  if (!yaml) diags.throwIfErrors();
  Species s = readSpecies(yaml, policy, diags);
  diags.throwIfErrors();
  return s;
}

lsystem::Grammar speciesGrammar(const Species& species, const lsystem::GrammarOverrides& extra) {
  if (species.kind != SpeciesKind::Tree) {
    SourceLoc at = species.kindNode ? species.kindNode->loc() : SourceLoc{species.file.string(), 0, 0};
    throw InputError(at, std::string("a ") + speciesKindName(species.kind) +
                             " species has no grammar (this command needs a tree species or a .lsys grammar)");
  }
  lsystem::GrammarOverrides o = species.overrides;
  for (const auto& d : extra.defines) o.defines.push_back(d);
  if (extra.derivationLength) o.derivationLength = extra.derivationLength;
  if (extra.seed) o.seed = extra.seed;
  try {
    return lsystem::parseGrammar(species.grammarText, species.grammarFile, o);
  } catch (const InputError& e) {
    if (species.bareGrammar || !species.yaml || species.grammarFile != species.yaml->displayPath()) throw;
    // Inline grammar: move positions from the grammar text into the species file.
    std::vector<Diagnostic> moved = e.diagnostics();
    for (auto& d : moved) {
      if (d.loc.file != species.grammarFile || d.loc.line <= 0) continue;
      d.loc.line += species.grammarLineOffset;
      if (d.loc.col > 0) d.loc.col += species.grammarColOffset;
      d.sourceLine = species.yaml->sourceLine(d.loc.line);
    }
    throw InputError(std::move(moved));
  }
}

lsystem::TurtleSettings speciesTurtle(const Species& species, const lsystem::Grammar& grammar) {
  lsystem::TurtleSettings t = species.turtle;
  if (!species.angleSet) t.angleDeg = grammar.angleDeg().value_or(90.0);
  return t;
}

std::vector<int> growthStages(const Species& species, int steps, int count) {
  std::vector<int> out;
  if (!species.stages.empty()) {
    for (int st : species.stages) out.push_back(std::min(st, steps));
    return out;
  }
  int k = std::max(1, std::min(steps, count));
  for (int i = 1; i <= k; ++i) {
    int st = static_cast<int>(std::lround(static_cast<double>(steps) * i / k));
    if (out.empty() || st != out.back()) out.push_back(st);
  }
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
