#include "model/tree_kind.h"
#include "core/timer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "blobtree/polygonize.h"
#include "core/atomic_file.h"
#include "core/paths.h"
#include "core/progress.h"
#include "lsystem/cpfg_materials.h"
#include "lsystem/turtle.h"
#include "model/cpfg_labels.h"
#include "model/bark_keys.h"
#include "model/growth.h"
#include "model/mesh_parts.h"
#include "organisms/skeleton_geometry.h"
#include "organisms/wind.h"
#include "textures/procedural.h"

namespace sprig {

namespace fs = std::filesystem;

namespace {

using organisms::BranchSelector;

constexpr double kInf = std::numeric_limits<double>::infinity();


std::vector<int> readInts(MapReader& m, Key key, int64_t min, int64_t max) {
  std::vector<int> out;
  std::string what("'");
  what.append(key.name).append("' element");
  for (const YNode& item : m.sequence(key))
    if (auto v = item.asInteger(m.diagnostics(), what, min, max))
      out.push_back(static_cast<int>(*v));
  return out;
}

void readSelector(MapReader& m, BranchSelector& s) {
  if (m.has("orders")) s.orders = readInts(m, {"orders", "Branch orders among which `probability` selects, e.g. [1, 2] (default: every order)."}, 0, 1000);
  if (m.has("internodes")) s.internodes = readInts(m, {"internodes", "Skeleton indices of internodes always selected (figure files, tests; default none)."}, 0, std::numeric_limits<int32_t>::max());
  s.belowHeight = m.number({"below_height", "Select branches whose base lies below this height (world units)."}, s.belowHeight);
  s.aboveHeight = m.number({"above_height", "Select branches whose base lies above this height (world units)."}, s.aboveHeight);
  s.probability = m.number({"probability", "Select each branch with this probability, seeded per internode (0 = only the listed `internodes`)."}, s.probability, 0.0, 1.0);
}

void readTurtle(MapReader& m, TreeSpec& s) {
  auto& t = s.turtle;
  t.stepLength = m.number({"step", "Length of `F f G g` without a parameter, in world units."}, t.stepLength, 1e-9, 1e9);
  if (m.has("angle")) {
    t.angleDeg = m.number({"angle", "Turn of `+ - & ^ \\ /` without a parameter, in degrees (default: the grammar's `angle:`, else 90)."}, t.angleDeg, -360.0, 360.0);
    s.angleSet = true;
  } else {
    m.allow({"angle"});
  }
  t.initialWidth = m.number({"width", "Initial line width (diameter units)."}, t.initialWidth, 0.0, 1e9);
  t.widthScale = m.number({"width_scale", "World units per width unit: radius = 0.5 · width · width_scale (ABOP's widths are pixel widths: about 0.01 for its figures 2.6 and 2.7)."}, t.widthScale, 1e-9, 1e9);
  t.widthFactor = m.number({"width_factor", "`!` without a parameter multiplies the width by this."}, t.widthFactor, 1e-6, 1e6);
  t.tropism = DVec3(m.vec3({"tropism", "Tropism vector T that bends branches (ABOP section 2.2), e.g. [0, -1, 0] for gravity."}, Vec3(t.tropism), -1e6, 1e6));
  t.elasticity = m.number({"elasticity", "Susceptibility e to the tropism (`@Ts(e)` changes it in the grammar; 0 = no bending)."}, t.elasticity, -10.0, 10.0);
  std::string radii = m.choice({"radii", "Internode radii from the `!` widths (`width`) or from the pipe model (`pipe`)."}, "width", {"width", "pipe"});
  t.radii = radii == "pipe" ? lsystem::RadiusModel::Pipe : lsystem::RadiusModel::Width;
  t.pipeExponent = m.number({"pipe_exponent", "Pipe model exponent e: r_parent^e = Σ r_child^e."}, t.pipeExponent, 0.5, 10.0);
  t.tipRadius = m.number({"tip_radius", "Pipe model: the radius of every branch tip, in world units."}, t.tipRadius, 1e-9, 1e9);
  t.taper = m.boolean({"taper", "Width model: an internode ends at its continuation's radius (false: cylinders)."}, t.taper);
  t.surfaceScale = m.number({"surface_scale", "Size of a `~` surface without a parameter."}, t.surfaceScale, 1e-9, 1e9);
  t.maxWidthToLength = m.number({"max_width_to_length", "Caps every internode's diameter at this multiple of its length (0 = off)."}, t.maxWidthToLength, 0.0, 1e6);
  m.finish();
}

/// Reads `grammar:`: inline text (contains a newline) or a path relative to the species file.
/// Returns false when it added an error (the grammar is then not checked: one error, not a
/// second one about the empty text).
bool readGrammar(MapReader& top, const Species& sp, TreeSpec& s, DiagnosticList& diags) {
  const PathPolicy& policy = sp.policy;
  auto g = top.get({"grammar", "The L-system: a `.lsys` (or cpfg `.l`) path relative to the species file, or the grammar itself inline as a block scalar (`grammar: |`)."});
  if (!g) {
    top.node().error(diags, "missing required key 'grammar' in species file");
    return false;
  }
  auto text = g->asString(diags, "'grammar'");
  if (!text) return false;
  if (text->find('\n') != std::string::npos) {
    s.grammarText = *text;
    s.grammarFile = sp.yaml->displayPath();
    // A block scalar's content starts on the line after its indicator; find that line's
    // indentation so grammar positions map back into the species file.
    SourceLoc at = g->loc();
    const std::string indicatorLine = sp.yaml->sourceLine(at.line);
    const bool block = at.col >= 1 && at.col <= static_cast<int>(indicatorLine.size()) &&
                       (indicatorLine[at.col - 1] == '|' || indicatorLine[at.col - 1] == '>');
    int line = block ? at.line + 1 : at.line;  // quoted multi-line strings map approximately
    const std::string& yamlText = sp.yaml->text();
    const int lines = static_cast<int>(std::count(yamlText.begin(), yamlText.end(), '\n')) + 1;
    s.grammarLineOffset = line - 1;
    for (int l = line; l <= lines; ++l) {
      std::string src = sp.yaml->sourceLine(l);
      size_t nonSpace = src.find_first_not_of(' ');
      if (nonSpace != std::string::npos) {
        s.grammarColOffset = static_cast<int>(nonSpace);
        break;
      }
    }
    return true;
  }
  auto p = resolveReference(*g, *text, policy, diags);
  if (!p) return false;
  try {
    s.grammarText = readFile(*p);
    s.grammarFile = p->string();
  } catch (const std::exception& e) {
    g->error(diags, e.what());
    return false;
  }
  return true;
}

void readDefines(MapReader& top, TreeSpec& s, DiagnosticList& diags) {
  auto d = top.section({"defines", "Replace the grammar's `#define NAME` values: NAME: number (an unknown name is an error)."});
  if (!d) return;
  if (auto entry = describeEntry(*d, "The value of the grammar's `#define NAME`, replacing the file's."))  // `sprig schema`
    entry->second.asNumber(diags, "'defines.NAME'");
  for (auto& [k, v] : d->pairs()) {
    if (!k.isScalar()) continue;
    auto value = v.asNumber(diags, "'defines." + k.scalar() + "'");
    if (value) s.overrides.defines.push_back(lsystem::DefineOverride{k.scalar(), *value, k.loc()});
  }
}

/// Parses the grammar with the species' own overrides, for its errors and counts.
/// Parses the species' grammar into spec.grammar; its errors go to diags, its warnings and
/// notes to the species' notes (printed by every command, errors under `--strict`).
void checkGrammar(Species& species, TreeSpec& spec, DiagnosticList& diags) {
  try {
    spec.grammar = speciesGrammar(species);
    for (Diagnostic& d : inSpeciesFile(species, spec, spec.grammar->warnings())) species.notes.push_back(std::move(d));
  } catch (const InputError& e) {
    diags.append(e.diagnostics());
  }
}

/// Appends b's triangles to a (positions, normals, uvs and colors kept where both have them).
void appendMesh(Mesh& a, const Mesh& b) {
  const uint32_t base = static_cast<uint32_t>(a.positions.size());
  const bool normals = a.normals.size() == a.positions.size() && b.normals.size() == b.positions.size();
  const bool colors = (a.positions.empty() || a.colors.size() == a.positions.size()) && b.colors.size() == b.positions.size();
  if (!normals) a.normals.clear();
  if (!colors) a.colors.clear();
  a.uvs.clear();
  a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
  if (normals) a.normals.insert(a.normals.end(), b.normals.begin(), b.normals.end());
  if (colors) a.colors.insert(a.colors.end(), b.colors.begin(), b.colors.end());
  for (const auto& t : b.triangles) a.triangles.push_back(t + glm::uvec3(base));
  a.materials.clear();
}

/// A cpfg texture shading one colour: texture number, the organ's colour index (-1: the
/// leaf colour, or the wood colour for tubes) and whether the organs are textured tubes
/// (`F` cylinders, generalized cylinders), the key of a group drawn as one part.
struct TexturedGroup {
  int texture = -1;
  int color = -1;
  bool tube = false;
  Mesh mesh;
};

/// Whether a textured organ is one of cpfg's tubes (wood) rather than a surface or polygon.
bool isTexturedTube(const lsystem::Organ& o) {
  return o.name == lsystem::kTexturedCylinderName || o.name == lsystem::kTexturedGcName;
}

/// Which textured organs a caller wants: the surfaces and polygons (leaves), the tubes (wood).
struct TexturedKinds {
  bool leaves = true;
  bool tubes = true;
};

/// The skeleton's textured cpfg organs (Organ::texture) of the kinds asked for, grouped by
/// texture, colour and kind, each group's mesh with its positions, normals and texture
/// coordinates. Colours follow the preview's rule: the palette entry of the organ's colour
/// index (> 0), else the leaf colour (the wood colour for tubes).
std::vector<TexturedGroup> texturedGroups(const lsystem::Skeleton& skeleton, const SkeletonStyle& style,
                                          TexturedKinds kinds = {}) {
  std::vector<TexturedGroup> groups;
  const size_t textureCount = style.cpfgTextures ? style.cpfgTextures->size() : 0;
  for (const lsystem::Organ& o : skeleton.organs) {
    if (o.texture < 0 || o.triangles.empty()) continue;
    const bool tube = isTexturedTube(o);
    if (!(tube ? kinds.tubes : kinds.leaves)) continue;
    if (static_cast<size_t>(o.texture) >= textureCount || o.uvs.size() != o.points.size())
      throw std::logic_error("a textured cpfg surface without its texture");
    // cpfg reads a texture's image only to draw: one that could not be read is an error now.
    if (const auto& unreadable = (*style.cpfgTextures)[static_cast<size_t>(o.texture)].unreadable)
      throw InputError(std::vector<Diagnostic>{*unreadable});
    const int color = o.color > 0 && static_cast<size_t>(o.color) < style.palette.size() ? o.color : -1;
    auto it = std::find_if(groups.begin(), groups.end(),
                           [&](const TexturedGroup& g) { return g.texture == o.texture && g.color == color && g.tube == tube; });
    if (it == groups.end()) {
      groups.push_back(TexturedGroup{o.texture, color, tube, {}});
      it = groups.end() - 1;
    }
    Mesh& m = it->mesh;
    const uint32_t base = static_cast<uint32_t>(m.positions.size());
    for (size_t k = 0; k < o.points.size(); ++k) {
      m.positions.push_back(Vec3(o.points[k]));
      m.normals.push_back(k < o.normals.size() ? Vec3(o.normals[k]) : Vec3(o.up));
      m.uvs.push_back(o.uvs[k]);
    }
    for (size_t k = 0; k + 2 < o.triangles.size(); k += 3)
      m.triangles.emplace_back(base + o.triangles[k], base + o.triangles[k + 1], base + o.triangles[k + 2]);
  }
  return groups;
}

Vec3 groupColor(const TexturedGroup& g, const SkeletonStyle& style) {
  return g.color >= 0 ? style.palette[static_cast<size_t>(g.color)] : (g.tube ? style.wood : style.leaf).baseColor;
}

/// Adds the skeleton's textured cpfg organs of the kinds asked for to out: one mesh part per
/// texture, colour and kind, the leaf material (the wood material for tubes) with the
/// texture's image map shading the colour (modulate or decal, by the H: or L: filter per
/// lookup) and, modulated, cut out by its alpha as cpfg does. Returns the triangles added.
size_t addTexturedSurfaces(render::Geometry& out, const lsystem::Skeleton& skeleton, const SkeletonStyle& style,
                           TexturedKinds kinds = {}) {
  size_t triangles = 0;
  for (TexturedGroup& g : texturedGroups(skeleton, style, kinds)) {
    triangles += g.mesh.triangleCount();
    auto tex = std::make_shared<const lsystem::CpfgTexture>((*style.cpfgTextures)[static_cast<size_t>(g.texture)]);
    const Vec3 color = groupColor(g, style);
    auto map = std::make_shared<render::ImageMap>();
    map->width = tex->image->width;
    map->height = tex->image->height;
    map->sample = [tex, color](Vec2 uv, double rho) { return tex->combine(tex->sampleFootprint(uv.x, uv.y, rho), color); };
    map->alphaCutoff = tex->cutsOut() ? lsystem::kCpfgAlphaCutoff : -1.0f;
    out.parts.push_back(render::MeshPart{std::move(g.mesh), g.tube ? style.wood : style.leaf, {}, {}, std::move(map)});
  }
  return triangles;
}

}  // namespace

render::Geometry skeletonPreview(const lsystem::Skeleton& skeleton, const SkeletonStyle& style) {
  organisms::SkeletonGeometryOptions o;
  o.radiusScale = style.radiusScale;
  o.minRadiusFraction = style.minRadiusFraction;
  o.organs = style.organs;
  o.palette = style.palette;
  o.leafColor = style.leaf.baseColor;
  o.fruitColor = style.fruit.baseColor;
  organisms::SkeletonGeometry g = organisms::buildSkeletonGeometry(skeleton, o);
  render::Geometry out;
  if (!g.internodes.empty()) out.parts.push_back(render::CurvesPart{std::move(g.internodes), style.wood});
  if (!g.leaves.triangles.empty())
    out.parts.push_back(render::MeshPart{std::move(g.leaves), style.leaf, std::move(g.leafColors), {}});
  if (!g.fruit.empty()) out.parts.push_back(render::SpheresPart{std::move(g.fruit), style.fruit});
  addTexturedSurfaces(out, skeleton, style, TexturedKinds{style.organs, true});  // tubes are wood
  out.labels = cpfgLabels(skeleton, style);
  return out;
}

namespace {

/// Primitives and triangles of a skeleton preview (internodes + organs; n - 2 per n-gon, and
/// the triangles of the textured cpfg organs drawn as meshes: surfaces, polygons and tubes).
void previewFigures(const lsystem::Skeleton& skeleton, ModelFigures& fig) {
  fig.primitives = skeleton.internodes.size() + skeleton.organs.size();
  fig.triangles = 0;
  for (const auto& o : skeleton.organs)
    if (o.texture >= 0 && !o.triangles.empty())
      fig.triangles += o.triangles.size() / 3;
    else if (o.kind == lsystem::Organ::Kind::Polygon && o.points.size() >= 3)
      fig.triangles += o.points.size() - 2;
}

/// The BlobTree tree as geometry: wood (exact or polygonized) with its bark texture, leaves.
render::Geometry surfaceGeometry(const TreeSurface& tree, const SpeciesRender& look,
                                 const std::shared_ptr<const blobtree::PolygonizeResult>& mesh) {
  render::TextureTable textures;
  if (tree.options.bark.enabled) {
    const organisms::BarkOptions& b = tree.options.bark;
    const Vec3 wood = look.style.wood.baseColor;
    // Ids below bark.texture hold the wood color; then one texture per bark class.
    for (int i = 0; i < b.texture; ++i) textures.push_back([wood](Vec2, const Vec3&) { return wood; });
    for (const organisms::BarkClass& c : tree.blob.barkClasses) {
      textures::BarkOptions bo = b.resolved(wood, wood * 0.3f);
      bo.seed = tree.options.seed;
      // Peeling patches as wide around as they are long, in world units, when ridges have a width.
      if (b.ridgeWidth > 0) bo.peelPerRidge = bo.peelFrequency * std::abs(b.vScale) * b.ridgeWidth;
      bo.furrows = c.furrows;
      bo.maturity = c.maturity;
      auto bark = std::make_shared<textures::BarkTexture>(bo);
      textures.push_back([bark](Vec2 uv, const Vec3&) { return bark->color(uv); });
    }
  }
  render::Material wood = look.style.wood;
  wood.textureLayers = true;  // every cone's bark in its own coordinates (furrows along each branch)
  {
    const organisms::BarkOptions& b = tree.options.bark;
    textures::RidgeOptions ridge = b.ridge();
    ridge.wanderScale = b.ridgeWidth > 0 ? 0.5 / b.ridgeWidth : ridge.wanderScale;  // one wave per two ridges
    ridge.seed = tree.options.seed;
    std::shared_ptr<const textures::RidgeArcs> arcs;
    if (b.enabled && b.hasArcs())
      arcs = std::make_shared<const textures::RidgeArcs>(organisms::ridgeArcs(tree.blob), b.ridgeArc);
    wood.ridge = textures::RidgeShade(ridge, std::move(arcs));
  }
  render::Geometry out;
  if (mesh)
    out.parts.push_back(render::PolygonizedPart{mesh, wood, std::move(textures), tree.axes});
  else
    out.parts.push_back(render::ImplicitPart{tree.compiled, wood, {}, std::move(textures), tree.axes});
  if (tree.leaves.triangleCount() > 0) {
    Mesh leaves = tree.leaves;
    leaves.materials.clear();  // one leaf material; the vertex colors carry each leaf's tint
    out.parts.push_back(render::MeshPart{std::move(leaves), look.style.leaf, {}, {}});
  }
  return out;
}

/// A tree species grown by the growth engine.
class TreeModel final : public KindModel {
 public:
  TreeModel(const Species& species, const TreeSpec& spec, const ModelOptions& options)
      : species_(species), spec_(spec), engine_(species, GrowthOptions{options.extra, options.lastStep, {}}) {}

  bool hasSurface() const override { return spec_.surface.has_value(); }

  Stage finalStage() const override {
    Stage s;
    s.step = engine_.lastStep();
    return s;
  }

  Stage stageFromIndex(int k) const override {
    if (k > engine_.lastStep())
      throw UsageError("stage " + std::to_string(k) + ": the species grows for only " +
                       std::to_string(engine_.lastStep()) + " steps");
    Stage s;
    s.step = k;
    return s;
  }

  std::vector<Stage> stripStages(int count) const override {
    std::vector<Stage> out;
    for (int step : growthStages(species_, engine_.lastStep(), count)) {
      Stage s;
      s.step = step;
      out.push_back(s);
    }
    return out;
  }

  std::vector<Stage> animationFrames(int framesPerStage, int first, int last) const override {
    const int lastStep = last < 0 ? engine_.lastStep() : std::min(last, engine_.lastStep());
    std::vector<Stage> out;
    for (const GrowthFrame& f : growthFrames(std::clamp(first, 0, lastStep), lastStep, std::max(1, framesPerStage))) {
      Stage s;
      s.step = f.stage;
      s.fraction = f.fraction;
      out.push_back(s);
    }
    return out;
  }

  std::string stageName(const Stage& stage) const override {
    char buf[64];
    if (stage.fraction < 1.0)
      std::snprintf(buf, sizeof buf, "step %d at %.0f%%", stage.step, stage.fraction * 100.0);
    else
      std::snprintf(buf, sizeof buf, "step %d", stage.step);
    return buf;
  }

  int stageNumber(const Stage& stage) const override { return stage.step; }

  Box3 frameBox() override {
    const DBox3& b = engine_.frameBox();
    Box3 box = b.empty() ? Box3{Vec3(-0.5f), Vec3(0.5f)} : Box3{Vec3(b.lo), Vec3(b.hi)};
    return box.empty() ? Box3{Vec3(-0.5f), Vec3(0.5f)} : box;
  }

  Box3 partBox(const CloseUpSpec& target) override {
    const lsystem::Skeleton skeleton = engine_.skeletonAt(engine_.lastStep());
    const std::vector<lsystem::Internode>& in = skeleton.internodes;
    const bool junction = target.junction >= 0;
    const int index = junction ? target.junction : target.internode;
    if (index < 0 || static_cast<size_t>(index) >= in.size())
      throw InputError(target.loc, std::string("render.close_up: ") + (junction ? "junction " : "internode ") +
                                       std::to_string(index) + " is beyond the tree's " + std::to_string(in.size()) +
                                       " internodes" + (in.empty() ? "" : " (0.." + std::to_string(in.size() - 1) + ")"));
    const lsystem::Internode& i = in[static_cast<size_t>(index)];
    if (junction) {
      // The point where internode i leaves its parent, 4 of the larger radius across.
      const double parentRadius = i.parent >= 0 ? in[static_cast<size_t>(i.parent)].tipRadius : 0.0;
      const double r = 2.0 * std::max({i.baseRadius, parentRadius, 1e-6});
      return Box3{Vec3(i.start - DVec3(r)), Vec3(i.start + DVec3(r))};
    }
    const double r = std::max({i.baseRadius, i.tipRadius, 1e-6});
    return Box3{Vec3(glm::min(i.start, i.end) - DVec3(r)), Vec3(glm::max(i.start, i.end) + DVec3(r))};
  }

  BuiltStage build(const Stage& stage, GeometryMode mode, const SpeciesRender& look) override {
    BuiltStage out;
    ModelFigures& fig = out.figures;
    const auto t0 = std::chrono::steady_clock::now();
    const int step = stage.step < 0 ? engine_.lastStep() : stage.step;
    lsystem::Skeleton skeleton = windy(engine_.skeletonAt(step, stage.fraction), stage);
    fig.modules = engine_.moduleCount(step);
    fig.internodes = skeleton.internodes.size();
    if (mode == GeometryMode::Skeleton || skeleton.internodes.empty()) {
      // Skeleton mode, or nothing to build a surface from yet (the axiom draws nothing):
      // the preview shows the organs.
      previewFigures(skeleton, fig);
      fig.buildSeconds = secondsSince(t0);
      out.geometry = skeletonPreview(skeleton, look.style);
      addBackground(out, look.style);
      return out;
    }
    TreeSurface tree = buildTreeSurface(skeleton, spec_.surface.value_or(organisms::TreeOptions{}));
    fig.primitives = tree.compiled->primitiveCount();
    fig.triangles = tree.leaves.triangleCount();
    std::shared_ptr<const blobtree::PolygonizeResult> mesh;
    if (mode == GeometryMode::Mesh) {
      mesh = std::make_shared<blobtree::PolygonizeResult>(polygonizeForLook(*tree.compiled, polygonizeOptions(look), look));
      fig.triangles += mesh->mesh.triangleCount();
    }
    fig.buildSeconds = secondsSince(t0);
    out.geometry = surfaceGeometry(tree, look, mesh);
    // Textured tubes are wood, drawn always; their triangles are not among tree.leaves.
    fig.triangles += addTexturedSurfaces(out.geometry, skeleton, look.style, TexturedKinds{tree.options.leaves.enabled, true});
    addBackground(out, look.style);
    out.geometry.labels = cpfgLabels(skeleton, look.style);
    return out;
  }

  /// The cpfg background scene, drawn with the plant in its coordinates (cpfg's TurtleDrawFinishUp).
  static void addBackground(BuiltStage& out, const SkeletonStyle& style) {
    if (!style.cpfgBackground) return;
    out.geometry.parts.push_back(*style.cpfgBackground);
    out.figures.triangles += style.cpfgBackground->mesh.triangleCount();
  }

  /// The stage's skeleton (swayed by the stage's wind when sway) and its BlobTree surface,
  /// for `sprig mesh`; fills fig's modules, internodes and primitives. When the stage draws
  /// no internode: nothing if tubesSuffice and it draws textured cpfg tubes (they are
  /// meshes of their own), else throws InputError.
  std::optional<TreeSurface> meshSurface(const Stage& stage, bool sway, ModelFigures& fig, lsystem::Skeleton& skeleton,
                                         bool tubesSuffice = false) const {
    const int step = stage.step < 0 ? engine_.lastStep() : stage.step;
    skeleton = engine_.skeletonAt(step, stage.fraction);
    if (sway) skeleton = windy(std::move(skeleton), stage);
    fig.modules = engine_.moduleCount(step);
    fig.internodes = skeleton.internodes.size();
    if (skeleton.internodes.empty()) {
      if (tubesSuffice && std::any_of(skeleton.organs.begin(), skeleton.organs.end(),
                                      [](const lsystem::Organ& o) { return o.texture >= 0 && isTexturedTube(o); }))
        return std::nullopt;
      throw InputError(species_.loc(), "the species draws no internodes at " + stageName(stage) +
                                           ": there is no surface to mesh");
    }
    TreeSurface tree = buildTreeSurface(skeleton, spec_.surface.value_or(organisms::TreeOptions{}));
    fig.primitives = tree.compiled->primitiveCount();
    return tree;
  }

  Mesh buildMesh(const Stage& stage, float cellSize, bool progress, ModelFigures& fig) override {
    lsystem::Skeleton skeleton;
    TreeSurface tree = *meshSurface(stage, true, fig, skeleton);
    blobtree::PolygonizeOptions po;
    po.cellSize = cellSize;
    po.progress = progress;
    Mesh out = blobtree::polygonize(*tree.compiled, po);
    if (tree.leaves.triangleCount() > 0) appendMesh(out, tree.leaves);
    return out;
  }

  std::vector<ExportPart> exportParts(const Stage& stage, float cellSize, bool progress, const SpeciesRender& look,
                                      const MeshCleanOptions& clean, ModelFigures& fig) override {
    lsystem::Skeleton skeleton;
    // A stage drawn only with textured cpfg tubes has no BlobTree: its parts are the tubes.
    std::optional<TreeSurface> surface = meshSurface(stage, false, fig, skeleton, true);
    const organisms::TreeOptions& options = surface ? surface->options : spec_.surface.value_or(organisms::TreeOptions{});
    std::vector<ExportPart> parts;
    if (surface) {
      TreeSurface& tree = *surface;
      blobtree::PolygonizeOptions po = polygonizeOptions(look);
      // The leaves and fruit (made before the wood: a crown of leaves hides the twigs that a
      // coarser cell for the levels cuts, lodCellCeiling).
      const std::pair<organisms::OrganSet, const char*> sets[] = {{organisms::OrganSet::Leaves, "leaves"},
                                                                   {organisms::OrganSet::Fruit, "fruit"}};
      Mesh organs[2];
      for (int k = 0; k < 2; ++k) organs[k] = organisms::buildOrganMesh(skeleton, options, sets[k].first);
      po.cellSize = cellSize;
      if (!(cellSize > 0) && look.meshTriangles > 0) {
        const bool keepLimbs = organs[0].triangleCount() == 0;
        fig.autoCell = blobtree::resolveCellSize(*tree.compiled, po);
        fig.ceilingCell = lodCellCeiling(*tree.compiled, po, fig.autoCell, keepLimbs);
        po.cellSize = fig.lodCell = lodCellSize(*tree.compiled, po, look.meshTriangles, keepLimbs);
      }
      po.progress = progress;
      // The wood: coloured by its bark as the renderer colours it, then cleaned.
      const render::Geometry geometry = surfaceGeometry(tree, look, nullptr);
      const auto& implicit = std::get<render::ImplicitPart>(geometry.parts.front());
      parts.resize(1);
      parts[0].name = "wood";
      {  // (the attributes are freed once painted)
        blobtree::PolygonizeResult polygonized = blobtree::polygonizeDetailed(*tree.compiled, po);
        // Each cone's bark in its own coordinates: the bark image is read at each vertex's heaviest cone's (u, v).
        if (implicit.material.textureLayers) useHeaviestLayerUvs(polygonized);
        parts[0].mesh = paintPolygonized(polygonized, implicit.textures, implicit.material);
      }
      fig.clean = cleanMesh(parts[0].mesh, clean);
      parts[0].mesh.materials.clear();
      parts[0].material = {"wood", look.style.wood.baseColor, look.style.wood.roughness, false, nullptr};
      // The bark as an image over the wood's (u, v), the renderer's own bark function baked.
      // One image reproduces the render only where every cone wears the same bark: with bark
      // per girth (several classes, each cone coloured in its own coordinates and the colours
      // blended) or darkened PCM seams, the wood keeps the renderer's vertex colours.
      const uint16_t barkId = static_cast<uint16_t>(tree.options.bark.texture);
      const bool oneBark = tree.blob.barkClasses.size() == 1 && !(tree.options.bark.ridgeDarkening > 0) &&
                           !(tree.options.bark.ridgeArc.darkening > 0);  // (relief is shading only)
      if (tree.options.bark.enabled && oneBark && barkId < implicit.textures.size() && parts[0].mesh.triangleCount() > 0) {
        const render::ColorTexture& bark = implicit.textures[barkId];
        textureBark(parts[0], [&bark](Vec2 uv) { return bark(uv, Vec3(0.0f)); });
      } else {
        // Bark per girth or darkened seams: every triangle's own patch of an atlas, each
        // texel the renderer's blend of the cones' barks at its surface point.
        atlasBlobPart(parts[0], tree.compiled, implicit.textures, implicit.material);
      }
      for (int k = 0; k < 2; ++k) {
        const auto& [set, name] = sets[k];
        if (organs[k].triangleCount() == 0) continue;
        organs[k].materials.clear();
        const render::Material& m = set == organisms::OrganSet::Leaves ? look.style.leaf : look.style.fruit;
        // Leaves are open polygons seen from both sides; fruit are closed spheres.
        const bool leaves = set == organisms::OrganSet::Leaves;
        parts.push_back(ExportPart{name, std::move(organs[k]), PartMaterial{name, m.baseColor, m.roughness, leaves, nullptr}, leaves});
        atlasVertexColors(parts.back());  // each leaf's tint, unclamped
      }
    }
    // Textured cpfg surfaces and tubes: one part per texture, colour and kind, the image
    // shading the colour baked at the image's own size over the organs' texture coordinates.
    {
      for (TexturedGroup& g : texturedGroups(skeleton, look.style, TexturedKinds{options.leaves.enabled, true})) {
        const lsystem::CpfgTexture& tex = (*look.style.cpfgTextures)[static_cast<size_t>(g.texture)];
        const Vec3 color = groupColor(g, look.style);
        auto baked = std::make_shared<PartTexture>();
        const int w = tex.image->width, h = tex.image->height;
        baked->image = Image(w, h);
        for (int y = 0; y < h; ++y)
          for (int x = 0; x < w; ++x)  // texel centres (either filter gives the texel); top row is t of 1
            baked->image.set(x, y, tex.fragment((x + 0.5) / w, 1.0 - (y + 0.5) / h, color));
        if (g.tube) {
          // Tubes: s runs 0 to 1 around (the seam has its own vertices) and t on along the
          // branch beyond 1: the sampler repeats (cpfg's GL_REPEAT), the uvs are kept.
          baked->seams.repeatU = baked->seams.repeatV = true;
          baked->seams.continuous = true;
        }
        baked->magFilter = tex.magLinear ? PartTexture::Filter::Linear : PartTexture::Filter::Nearest;
        // Mipmapped (L: m...): glTF's LINEAR_MIPMAP_LINEAR, the viewer building the levels.
        baked->minFilter = tex.mipmap      ? PartTexture::Filter::Default
                           : tex.minLinear ? PartTexture::Filter::Linear
                                           : PartTexture::Filter::Nearest;
        const std::string name = (g.tube ? "textured_wood_" : "textured_leaves_") + std::to_string(parts.size());
        const render::Material& m = g.tube ? look.style.wood : look.style.leaf;
        // Both sides: leaves are open polygons, tubes open at their ends (cpfg draws no caps).
        PartMaterial material{name, color, m.roughness, true, std::move(baked)};
        material.alphaCutoff = tex.cutsOut() ? lsystem::kCpfgAlphaCutoff : -1.0f;  // glTF MASK, the image's alpha kept
        parts.push_back(ExportPart{name, std::move(g.mesh), std::move(material), !g.tube});  // leaves: scattered pieces
      }
    }
    return parts;
  }

  std::optional<std::pair<lsystem::Skeleton, organisms::WindOptions>> windSource(const Stage& stage) override {
    const int step = stage.step < 0 ? engine_.lastStep() : stage.step;
    organisms::WindOptions w;
    w.speed = species_.render.windSpeed;
    w.directionDeg = species_.render.windDirectionDeg;
    w.seed = spec_.surface ? spec_.surface->seed : organisms::TreeOptions{}.seed;
    return std::make_pair(engine_.skeletonAt(step, stage.fraction), w);
  }

  /// LOD0 of a tree: wood, leaves and fruit within 300,000 triangles (docs/MESHES.md "Levels of detail").
  size_t lodBudget() const override { return 300000; }

  GalleryMotion galleryMotion(bool final) override {
    // Exact frames rebuild the BlobTree each time: drafts show one frame per step.
    const int steps = std::max(1, engine_.lastStep());
    GalleryMotion m;
    m.framesPerStage = hasSurface() && !final ? 1 : std::clamp((final ? 120 : 36) / steps, 1, final ? 8 : 4);
    return m;
  }

 private:
  /// The skeleton swayed by the stage's wind (unchanged without wind).
  lsystem::Skeleton windy(lsystem::Skeleton skeleton, const Stage& stage) const {
    if (!(stage.windSpeed > 0)) return skeleton;
    organisms::WindOptions w;
    w.speed = stage.windSpeed;
    w.directionDeg = stage.windDirectionDeg;
    w.seed = spec_.surface ? spec_.surface->seed : organisms::TreeOptions{}.seed;
    return organisms::swayInWind(skeleton, w, stage.windSeconds);
  }

  const Species& species_;
  const TreeSpec& spec_;
  mutable GrowthEngine engine_;
};

}  // namespace

std::vector<GrowthFrame> growthFrames(int first, int last, int framesPerStage) {
  std::vector<GrowthFrame> frames;
  frames.push_back({first, 1.0});
  const int k = std::max(framesPerStage, 1);
  for (int stage = first + 1; stage <= last; ++stage)
    for (int j = 1; j <= k; ++j) frames.push_back({stage, static_cast<double>(j) / k});
  return frames;
}

std::shared_ptr<const KindSpec> readTreeSpec(MapReader& top, Species& species, DiagnosticList& diags) {
  auto spec = std::make_shared<TreeSpec>();
  TreeSpec& s = *spec;
  const bool grammarRead = readGrammar(top, species, s, diags);
  readDefines(top, s, diags);
  if (top.has("steps")) {
    s.overrides.derivationLength = static_cast<int>(top.integer({"steps", "Derivation steps (default: the grammar's `derivation length:`; another value prints a note naming both)."}, 0, 0, 100000));
    if (auto key = top.keyNode("steps")) s.overrides.derivationLengthLoc = key->loc();  // none while describing
  } else
    top.allow({"steps"});
  if (top.has("seed"))
    s.overrides.seed = static_cast<uint64_t>(top.integer({"seed", "Seed of stochastic productions and `ran`/`nran` (default: the grammar's `seed:`, else 0)."}, 0, 0));
  else
    top.allow({"seed"});
  s.maxModules = static_cast<size_t>(top.integer({"max_modules", "Module limit of the derivation: a grammar that grows past it stops with an error."}, static_cast<int64_t>(s.maxModules), 1,
                                                 int64_t(4'000'000'000)));
  if (auto t = top.section({"turtle", "How the module string is drawn: step, angle, widths, tropism, radii."})) {
    MapReader turtle(*t, diags, "turtle");
    readTurtle(turtle, s);
  }
  if (auto section = top.section({"tree", "The BlobTree tree builder (δA offsets, PCM junctions, pruning, scars, bends, bark, leaves); without it a tree is its skeleton only."})) s.surface = readTreeOptions(*section, diags);
  if (grammarRead) {
    species.spec = spec;  // speciesGrammar reads the spec through the species
    checkGrammar(species, s, diags);
  }
  return spec;
}

namespace {

/// cpfg's colour map file (`-m NAME.map` on the object's cpfg command line; irisGL.c,
/// load_in_colormaps): 256 entries of 3 bytes (red, green, blue), colour index i being
/// entry i. Another size is an InputError at the file.
std::vector<Vec3> readCpfgColormap(const fs::path& path) {
  std::string bytes;
  try {
    bytes = readFile(path);
  } catch (const FileReadError& e) {
    throw InputError(SourceLoc{path.string(), 0, 0}, e.reason());
  }
  if (bytes.size() != 768)
    throw InputError(SourceLoc{path.string(), 0, 0}, "a cpfg colour map holds 256 entries of 3 bytes (768 bytes), this file has " +
                                                          std::to_string(bytes.size()));
  std::vector<Vec3> palette(256);
  for (size_t i = 0; i < 256; ++i)
    for (int c = 0; c < 3; ++c) palette[i][c] = static_cast<float>(static_cast<unsigned char>(bytes[3 * i + c])) / 255.0f;
  return palette;
}

/// cpfg's materials file (`-M NAME.mat`, written by vlab's medit; irisGL.c,
/// load_in_materials): records of 15 bytes, the material's colour index, then transparency,
/// ambient, diffuse, emissive and specular red-green-blue and shininess. The palette holds
/// the diffuse colours; an index no record names keeps cpfg's default material (diffuse
/// white). A size that is not a whole number of records is an InputError at the file. A
/// transparent material is drawn opaque, said in a note.
std::vector<Vec3> readCpfgMaterials(const fs::path& path, std::vector<Diagnostic>& notes) {
  std::string bytes;
  try {
    bytes = readFile(path);
  } catch (const FileReadError& e) {
    throw InputError(SourceLoc{path.string(), 0, 0}, e.reason());
  }
  return lsystem::parseCpfgMaterials(bytes, path.string(), notes);
}

/// The view file's background scene as the species' background part (SkeletonStyle::
/// cpfgBackground): its triangles in their materials' diffuse colours, the leaf material's
/// finish. cpfg draws a background scene only with a colour map or materials file
/// (background.c: not "in index mode"); without one (coloured false) it is left out, with
/// a note.
void addCpfgBackground(const lsystem::ViewFile& view, bool coloured, Species& s) {
  if (!coloured) {
    Diagnostic d;
    d.severity = Severity::Note;
    d.loc = SourceLoc{view.file, 0, 0};
    d.message = "the background scene is not drawn: cpfg draws it only with a colour map or materials file (-m, -M), and the object names none";
    s.notes.push_back(std::move(d));
    return;
  }
  const lsystem::CpfgBackground& b = *view.background;
  const lsystem::CpfgBackgroundMesh m = b.triangulate();
  render::MeshPart part;
  part.material = s.render.style.leaf;
  for (size_t k = 0; k < m.positions.size(); ++k) {
    part.mesh.positions.push_back(Vec3(m.positions[k]));
    part.mesh.normals.push_back(Vec3(m.normals[k]));
  }
  for (size_t t = 0; t < m.triangleMaterials.size(); ++t) {
    part.mesh.triangles.emplace_back(m.triangles[3 * t], m.triangles[3 * t + 1], m.triangles[3 * t + 2]);
    part.triangleColors.push_back(b.materials[static_cast<size_t>(m.triangleMaterials[t])].diffuse);
  }
  s.render.style.cpfgBackground = std::make_shared<const render::MeshPart>(std::move(part));
}

/// A bare grammar (viewFile: its cpfg view file, empty for none; colormap: its colour map,
/// empty for none; materials: its materials file, empty for none, which colours organs in
/// place of the colour map as cpfg's -M does).
Species grammarSpecies(const fs::path& path, const fs::path& viewFile, const fs::path& colormap = {},
                       const fs::path& materials = {}) {
  Species s;
  s.kind = "tree";
  s.bareGrammar = true;
  s.file = path;
  s.name = path.stem().string();
  auto spec = std::make_shared<TreeSpec>();
  try {
    spec->grammarText = readFile(path);
  } catch (const FileReadError& e) {
    throw InputError(SourceLoc{path.string(), 0, 0}, e.reason());
  }
  spec->grammarFile = path.string();
  // ABOP widths are pixel widths: keep a bare grammar's internodes slender (lsystem/turtle.h).
  spec->turtle.maxWidthToLength = 0.12;
  if (!viewFile.empty()) {
    spec->view = lsystem::loadViewFile(viewFile.string());
    for (const Diagnostic& w : spec->view->warnings) s.notes.push_back(w);
  }
  // The colour map colours organs by their colour index (`;`, `,`, `initial color:`).
  if (!colormap.empty()) s.render.style.palette = readCpfgColormap(colormap);
  // A materials file (`-M NAME.mat`) colours them by their materials' diffuse colours.
  if (!materials.empty()) s.render.style.palette = readCpfgMaterials(materials, s.notes);
  if (spec->view && spec->view->background) addCpfgBackground(*spec->view, !colormap.empty() || !materials.empty(), s);
  if (spec->view) s.render.style.cpfgFont = spec->view->font;
  if (spec->view && !spec->view->textures.empty())
    s.render.style.cpfgTextures = std::make_shared<const std::vector<lsystem::CpfgTexture>>(spec->view->textures);
  s.spec = spec;
  DiagnosticList diags;
  checkGrammar(s, *spec, diags);
  diags.throwIfErrors();
  const lsystem::Grammar& g = *spec->grammar;
  auto note = [&](const std::string& msg) {
    Diagnostic d;
    d.severity = Severity::Note;
    d.loc = SourceLoc{path.string(), 0, 0};
    d.message = msg;
    s.notes.push_back(std::move(d));
  };
  if (g.cpfgNotation()) {
    const lsystem::ViewFile* v = spec->view ? &*spec->view : nullptr;
    if (!v)
      note("no view file '" + fs::path(path).replace_extension(".v").filename().string() +
           "' beside it: using cpfg's defaults: " + lsystem::cpfgDefaultsUsed(nullptr));
    else if (!v->angleDeg && g.usesDefaultAngle())
      note("the view file '" + viewFile.string() + "' sets no angle: turns without an angle use cpfg's default angle increment, 45 degrees");
  } else if (!g.angleDeg() && g.usesDefaultAngle()) {
    note("no 'angle:' header: turns without an angle use cpfg's default angle increment, 45 degrees");
  }
  return s;
}

/// Whether text holds an `axiom:` (cpfg capitalizes it at will): a grammar, not a panel file.
bool hasAxiom(const fs::path& p) {
  try {
    std::string t = readFile(p);
    std::transform(t.begin(), t.end(), t.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return t.find("axiom:") != std::string::npos;
  } catch (const std::exception&) {
    return false;
  }
}

/// Throws InputError at path unless it is a regular file.
void requireObjectFile(const fs::path& path) {
  if (std::string reason = notRegularFileReason(path); !reason.empty()) throw InputError(SourceLoc{path.string(), 0, 0}, reason);
}

/// Whether the optional file path (a view file, colour map, ... found by its name) is there:
/// false when nothing is, an InputError when something that is not a regular file is.
bool optionalObjectFile(const fs::path& path) {
  const std::string reason = notRegularFileReason(path);
  if (reason == "cannot find file") return false;
  requireObjectFile(path);
  return true;
}

}  // namespace

Species speciesFromGrammarFile(const fs::path& path) {
  fs::path view;
  if (lowerExtension(path) == ".l") {
    fs::path v = fs::path(path).replace_extension(".v");
    if (optionalObjectFile(v)) view = v;
  }
  return grammarSpecies(path, view);
}

namespace {

/// The files a vlab object's cpfg command line names.
struct CpfgObjectFiles {
  fs::path grammar, view, colormap, materials;
};

/// Reads the `cpfg` line of folder/specifications (if any): the grammar (`.l`), the view
/// file (`.v`), the colour map (`-m NAME` or `.map`) and the materials (`-M NAME`). Each
/// name passes policy (pathRefusal) or is an InputError at its word.
CpfgObjectFiles readSpecifications(const fs::path& folder, const PathPolicy& policy) {
  CpfgObjectFiles f;
  const fs::path specPath = folder / "specifications";
  std::string text;
  try {
    text = readFile(specPath);
  } catch (const FileReadError& e) {
    if (e.reason() == "cannot find file") return f;
    throw InputError(SourceLoc{specPath.string(), 0, 0}, e.reason());
  }
  std::istringstream spec(text);
  int lineNo = 0;
  for (std::string line; std::getline(spec, line);) {
    ++lineNo;
    std::vector<std::pair<std::string, size_t>> w;  // word, 0-based column
    for (size_t pos = line.find_first_not_of(" \t\r"); pos != std::string::npos; pos = line.find_first_not_of(" \t\r", pos)) {
      const size_t end = std::min(line.find_first_of(" \t\r", pos), line.size());
      w.emplace_back(line.substr(pos, end - pos), pos);
      pos = end;
    }
    if (w.empty() || w[0].first != "cpfg") continue;
    auto take = [&](fs::path& slot, size_t k) {
      if (!slot.empty()) return;
      const std::string& name = w[k].first;
      const fs::path resolved = (folder / name).lexically_normal();
      if (std::string refusal = pathRefusal(name, resolved, policy); !refusal.empty())
        throw InputError(SourceLoc{specPath.string(), lineNo, static_cast<int>(w[k].second) + 1}, refusal, line);
      slot = resolved;
    };
    for (size_t k = 1; k < w.size(); ++k) {
      const std::string& x = w[k].first;
      if ((x == "-M" || x == "-m") && k + 1 < w.size()) {
        take(x == "-M" ? f.materials : f.colormap, k + 1);
        ++k;
        continue;
      }
      const std::string e = lowerExtension(x);
      if (e == ".l") take(f.grammar, k);
      if (e == ".v") take(f.view, k);
      if (e == ".map") take(f.colormap, k);
    }
    break;
  }
  return f;
}

}  // namespace

Species speciesFromCpfgObject(const fs::path& folder, const PathPolicy& policy) {
  std::error_code ec;
  // The `specifications` file's cpfg command line names the grammar, the view file and the
  // colour map (`-m NAME.map`).
  auto [grammar, view, colormap, materials] = readSpecifications(folder, policy);
  if (grammar.empty()) {
    std::vector<fs::path> grammars, views, maps, mats;
    for (const auto& e : fs::directory_iterator(folder, ec)) {
      if (!e.is_regular_file()) continue;
      const std::string x = lowerExtension(e.path());
      if (x == ".l" && hasAxiom(e.path())) grammars.push_back(e.path());
      if (x == ".v") views.push_back(e.path());
      if (x == ".map") maps.push_back(e.path());
      if (x == ".mat") mats.push_back(e.path());
    }
    std::sort(grammars.begin(), grammars.end());
    if (grammars.size() != 1) {
      std::string list;
      for (const fs::path& p : grammars) list += (list.empty() ? "" : ", ") + p.filename().string();
      throw InputError(SourceLoc{folder.string(), 0, 0},
                       grammars.empty() ? "no cpfg grammar (a .l file with an 'axiom:') in this folder"
                                        : "several cpfg grammars in this folder (" + list +
                                              ") and no 'specifications' naming one: give the .l file");
    }
    grammar = grammars[0];
    fs::path same = fs::path(grammar).replace_extension(".v");
    if (optionalObjectFile(same)) view = same;
    else if (views.size() == 1) view = views[0];
    fs::path sameMap = fs::path(grammar).replace_extension(".map");
    if (optionalObjectFile(sameMap)) colormap = sameMap;
    else if (maps.size() == 1) colormap = maps[0];
    fs::path sameMat = fs::path(grammar).replace_extension(".mat");
    if (optionalObjectFile(sameMat)) materials = sameMat;
    else if (mats.size() == 1) materials = mats[0];
  }
  for (const fs::path& p : {grammar, view, colormap, materials})
    if (!p.empty()) requireObjectFile(p);
  return grammarSpecies(grammar, view, colormap, materials);
}

const TreeSpec& treeSpec(const Species& species) {
  const auto* tree = dynamic_cast<const TreeSpec*>(species.spec.get());
  if (!tree)
    throw InputError(species.loc(), std::string(species.kind == "organism" ? "an " : "a ") + species.kind +
                                        " species has no grammar (this command needs a tree species or a .lsys grammar)");
  return *tree;
}

lsystem::Grammar speciesGrammar(const Species& species, const lsystem::GrammarOverrides& extra) {
  const TreeSpec& tree = treeSpec(species);
  if (tree.grammar && extra.defines.empty() && !extra.derivationLength && !extra.seed) return *tree.grammar;
  lsystem::GrammarOverrides o = tree.overrides;
  if (tree.view) {
    o.cpfgFunctions = tree.view->functions;
    o.cpfgCurves = tree.view->curves;
    o.cpfgFunctionNames = tree.view->functionNames;
    for (const auto& sf : tree.view->surfaces) o.cpfgSurfaceIds += sf.id;
    o.cpfgUndrawnSurfaceIds = tree.view->tsurfaceIds;
  }
  for (const auto& d : extra.defines) o.defines.push_back(d);
  if (extra.derivationLength) o.derivationLength = extra.derivationLength;
  if (extra.seed) o.seed = extra.seed;
  try {
    return lsystem::parseGrammar(tree.grammarText, tree.grammarFile, o);
  } catch (const InputError& e) {
    throw InputError(inSpeciesFile(species, tree, e.diagnostics()));
  }
}

lsystem::FormatOptions speciesStringFormat(const Species& species) {
  lsystem::FormatOptions fo;
  const auto* tree = dynamic_cast<const TreeSpec*>(species.spec.get());
  if (!tree) return fo;
  const std::string& f = tree->grammarFile;
  fo.floatParams = tree->grammar ? tree->grammar->cpfgNotation() : f.size() > 2 && f.compare(f.size() - 2, 2, ".l") == 0;
  return fo;
}

std::vector<Diagnostic> inSpeciesFile(const Species& species, const TreeSpec& tree, std::vector<Diagnostic> diags) {
  if (species.bareGrammar || !species.yaml || tree.grammarFile != species.yaml->displayPath()) return diags;
  // Inline grammar: move positions from the grammar text into the species file.
  for (auto& d : diags) {
    if (d.loc.file != tree.grammarFile || d.loc.line <= 0) continue;
    d.loc.line += tree.grammarLineOffset;
    if (d.loc.col > 0) d.loc.col += tree.grammarColOffset;
    d.sourceLine = species.yaml->sourceLine(d.loc.line);
  }
  return diags;
}

lsystem::TurtleSettings speciesTurtle(const Species& species, const lsystem::Grammar& grammar) {
  const TreeSpec& tree = treeSpec(species);
  lsystem::TurtleSettings t = tree.turtle;
  if (grammar.cpfgNotation()) {
    t = lsystem::cpfgTurtleSettings(tree.view ? &*tree.view : nullptr, t);
    t.labelFormats = grammar.strings();
    if (tree.angleSet) t.angleDeg = tree.turtle.angleDeg;
    else if (grammar.angleDeg()) t.angleDeg = *grammar.angleDeg();
    return t;
  }
  // cpfg's default angle increment (its view file's, interpret.c): 45 degrees.
  if (!tree.angleSet) t.angleDeg = grammar.angleDeg().value_or(lsystem::kCpfgDefaultAngleDeg);
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

organisms::TreeOptions readTreeOptions(const YNode& section, DiagnosticList& diags, const organisms::TreeOptions& defaults) {
  organisms::TreeOptions o = defaults;
  MapReader m(section, diags, "tree");
  o.junctions = m.choice({"junctions", "How a branch meets its parent: `smooth` summation (§3.3) or `pcm` (precise contact modelling with a ridge, §3.4)."}, o.junctions == organisms::JunctionModel::Pcm ? "pcm" : "smooth",
                         {"smooth", "pcm"}) == "pcm"
                    ? organisms::JunctionModel::Pcm
                    : organisms::JunctionModel::Smooth;
  o.deltaA = m.number({"delta_a", "δA offset factor of Eq. 4 (BlobTree Trees): shortens a basal internode so the joint does not bulge."}, o.deltaA, 0.0, 10.0);
  o.deltaAMulti = m.number({"delta_a_multi", "δA factor of Eq. 8, for junctions with several branches."}, o.deltaAMulti, 0.0, 10.0);
  o.basalOffset = m.boolean({"basal_offset", "Apply the δA offset (false: Fig. 9 left, the joint bulges)."}, o.basalOffset);
  o.branchOffset = m.boolean({"branch_offset", "PCM: apply δB_i of Eq. 7 (false: Fig. 12 left)."}, o.branchOffset);
  o.pcmWidth = m.number({"pcm_width", "PCM propagation width w, in field units."}, o.pcmWidth, 1e-3, 0.5);
  o.pcmBulge = m.number({"pcm_bulge", "PCM bulge a₀ = pcm_bulge · w / 4."}, o.pcmBulge, 0.0, 4.0);
  o.softKernel = m.choice({"kernel", "Field kernel: `wyvill` (1 − s)³ or `soft` (the soft-object kernel, iso radius exactly R/2)."}, o.softKernel ? "soft" : "wyvill", {"wyvill", "soft"}) == "soft";
  o.controlledBlend = m.boolean({"controlled_blend", "Blend each internode only with its skeleton neighbours (false: every internode blends with every other)."}, o.controlledBlend);
  o.tips = m.choice({"tips", "Terminal internodes end in a `taper` (closing exactly at the end point) or a `hemisphere` (the paper's caps)."}, o.tips == organisms::TipStyle::Taper ? "taper" : "hemisphere",
                    {"taper", "hemisphere"}) == "taper"
               ? organisms::TipStyle::Taper
               : organisms::TipStyle::Hemisphere;
  o.tipTaper = m.number({"tip_taper", "Tip radius / base radius of a terminal internode (with `tips: taper`)."}, o.tipTaper, 0.01, 1.0);
  o.radiusScale = m.number({"radius_scale", "Multiplies every internode radius."}, o.radiusScale, 1e-6, 1e6);
  o.minRadius = m.number({"min_radius", "Floor of every internode radius, in world units."}, o.minRadius, 0.0, 1e6);
  o.seed = static_cast<uint64_t>(m.integer({"seed", "Seed of pruning, scars, bends, leaf tints and wind phases."}, static_cast<int64_t>(o.seed), 0));

  if (auto s = m.section({"prune", "Pruning (§3.5, Fig. 14): which branches are sawn off and where; plus selector keys."})) {
    MapReader p(*s, diags, "prune");
    o.prune.fromGrammar = p.boolean({"from_grammar", "Prune where the grammar says so (`%` marks the last internode drawn as cut)."}, o.prune.fromGrammar);
    o.prune.cutFraction = p.number({"cut_fraction", "Where the saw cuts the first internode of a pruned branch, as a fraction of its length."}, o.prune.cutFraction, 0.0, 1.0);
    o.prune.minCutDistance = p.number({"min_cut_distance", "The cut lies at least this many base radii from the branching point."}, o.prune.minCutDistance, 0.0, 100.0);
    readSelector(p, o.prune.select);
    p.finish();
  }
  if (auto s = m.section({"scars", "Scars of lost branches (§3.5, Fig. 15): a stub and a negative field; plus selector keys."})) {
    MapReader p(*s, diags, "scars");
    const std::string style = p.choice({"style", "`flush`: a round, shallow scar flush with the bark; `knob`: a raised stub dented at its end."}, "flush", {"flush", "knob"});
    o.scars.style = style == "knob" ? organisms::ScarStyle::Knob : organisms::ScarStyle::Flush;
    if (o.scars.style == organisms::ScarStyle::Knob || !p.has("stub_length"))
      o.scars.stubLength = p.number({"stub_length", "Knob scars: length of the stub along the branch, in branch radii (an error with `style: flush`)."}, o.scars.stubLength, 0.01, 100.0);
    else if (auto stub = p.get({"stub_length", "Knob scars: length of the stub along the branch, in branch radii (an error with `style: flush`)."}))  // (sprig schema's describe mode may answer has() and get() differently)
      stub->error(diags, "'scars.stub_length' applies to style knob only (a flush scar's stub reaches the bark)");
    o.scars.stubRadius = p.number({"stub_radius", "Radius of the stub, in branch radii (at most 0.9 of its parent's)."}, o.scars.stubRadius, 0.01, 10.0);
    o.scars.negativeRadius = p.number({"negative_radius", "Radius of the negative field at the stub's end, in branch radii."}, o.scars.negativeRadius, 0.0, 10.0);
    o.scars.negativeWeight = p.number({"negative_weight", "Weight of the negative field (how deep the scar is)."}, o.scars.negativeWeight, 0.0, 10.0);
    readSelector(p, o.scars.select);
    p.finish();
  }
  if (auto s = m.section({"bends", "Endpoint-preserving bends of lateral branches (§3.6, Fig. 16)."})) {
    MapReader p(*s, diags, "bends");
    o.bends.angleDeg = p.number({"angle", "Bend angle in degrees (0 = off)."}, o.bends.angleDeg, 0.0, 80.0);
    o.bends.orderScale = p.number({"order_scale", "Multiplies the bend angle per branch order."}, o.bends.orderScale, 0.0, 10.0);
    o.bends.randomness = p.number({"randomness", "Random share of each bend's angle (seeded)."}, o.bends.randomness, 0.0, 1.0);
    o.bends.minBranchAngleDeg = p.number({"min_branch_angle", "Only branches leaving their basal internode's axis by more than this many degrees bend."}, o.bends.minBranchAngleDeg, 0.0, 90.0);
    o.bends.trunk = p.boolean({"trunk", "Bend the trunk too."}, o.bends.trunk);
    p.finish();
  }
  if (auto s = m.section({"bark", "The bark texture on the cones (see docs/TREES.md, Bark)."})) {
    MapReader p(*s, diags, "bark");
    o.bark.enabled = p.boolean({"enabled", "Put the bark texture on the cones."}, o.bark.enabled);
    o.bark.texture = static_cast<int>(p.integer({"texture", "Texture id of the first bark class."}, o.bark.texture, 0, 16383));
    o.bark.uScale = p.number({"u_scale", "Texture u per turn around the branch."}, o.bark.uScale, -kInf, kInf);
    o.bark.vScale = p.number({"v_scale", "Texture v per world unit along the skeleton."}, o.bark.vScale, -kInf, kInf);
    o.bark.ridgeWidth = p.number({"ridge_width", "World width of a bark ridge (0: `furrows` ridges on every cone)."}, o.bark.ridgeWidth, 0.0, 1e6);
    o.bark.matureRadius = p.number({"mature_radius", "Branch radius with fully furrowed bark (0: `maturity` everywhere)."}, o.bark.matureRadius, 0.0, 1e6);
    readBarkLook(p, o.bark);  // the keys a blob species' bark texture reads too
    p.finish();
  }
  if (auto s = m.section({"leaves", "Leaves on the BlobTree tree."})) {
    MapReader p(*s, diags, "leaves");
    o.leaves.enabled = p.boolean({"enabled", "Put leaves on the tree (false: bare branches)."}, o.leaves.enabled);
    o.leaves.scale = p.number({"scale", "Multiplies the size of every leaf."}, o.leaves.scale, 0.0, 1e6);
    o.leaves.material = static_cast<uint32_t>(p.integer({"material", "Material index of the leaves."}, o.leaves.material, 0, 65535));
    p.finish();
  }
  m.finish();
  return o;
}

organisms::TreeOptions parseTreeOptions(std::string text, const std::string& displayPath) {
  DiagnosticList diags;
  auto file = YamlFile::parse(std::move(text), displayPath, diags);
  organisms::TreeOptions o;
  if (file) o = readTreeOptions(file->rootNode(), diags);
  diags.throwIfErrors();
  return o;
}

TreeSurface buildTreeSurface(const lsystem::Skeleton& skeleton, const organisms::TreeOptions& options) {
  TreeSurface m;
  m.options = options;
  m.blob = organisms::buildTreeBlob(skeleton, m.options);
  m.compiled = std::make_shared<const blobtree::CompiledBlob>(blobtree::compile(m.blob.tree, m.blob.root));
  m.axes = organisms::treeAxes(m.blob);
  m.leaves = organisms::buildLeafMesh(skeleton, m.options);
  return m;
}

std::string TreeSpec::checkSummary(const Species& species) const {
  // A view file command Sprig cannot draw: the grammar derives, the species cannot be shown.
  if (view && view->unsupportedDrawing) throw InputError(std::vector<Diagnostic>{*view->unsupportedDrawing});
  const size_t productions = grammar ? grammar->productionCount() : 0;
  const int steps = grammar ? grammar->derivationLength() : 0;
  return " '" + species.name + "', " + std::to_string(productions) + " productions, " + std::to_string(steps) +
         " steps" + (surface ? ", BlobTree surface" : "");
}

std::unique_ptr<KindModel> TreeSpec::makeModel(const Species& species, const ModelOptions& options) const {
  return std::make_unique<TreeModel>(species, *this, options);
}

}  // namespace sprig
