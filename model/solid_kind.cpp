#include "model/solid_kind.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <unordered_map>

#include "core/image.h"
#include "core/polymesh.h"
#include "core/srgb.h"
#include "core/timer.h"
#include "organisms/subdivision.h"
#include "model/solid_velocity.h"
#include "solids/front_field.h"
#include "model/species_field.h"
#include "solids/extrude_field.h"
#include "solids/tet_io.h"

namespace sprig {

namespace {

using namespace solids;

/// Grid nodes a solid may have: 16.8 million (256³). Meshing keeps about 100 bytes per node
/// and volume plus 40 bytes per tetrahedron.
constexpr size_t kMaxGridNodes = size_t(1) << 24;
/// The default cell: the largest side over this, or half the thinnest layer when smaller...
constexpr double kDefaultCellsAcross = 64;
/// ...but never finer than the largest side over this.
constexpr double kFinestCellsAcross = 200;

/// Largest coordinate (absolute, world units) of a solid's volumes: the meshing samples
/// the fields at single-precision points and squares distances.
constexpr double kMaxSolidCoordinate = 1e15;

bool withinSolidRange(const DBox3& box) {
  for (int a = 0; a < 3; ++a)
    if (!(std::abs(box.lo[a]) <= kMaxSolidCoordinate) || !(std::abs(box.hi[a]) <= kMaxSolidCoordinate)) return false;
  return true;
}

/// A count or size computed in double, printed as it is: a whole number up to 1e15, else %g.
std::string countText(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, std::abs(v) < 1e15 && v == std::floor(v) ? "%.0f" : "%g", v);
  return buf;
}

const std::vector<std::string> kVolumeForms = {"volume", "precedence"};
const std::vector<std::string> kFields = {"surface_mesh", "sphere",    "box",         "cylinder",
                                          "ground_plane", "union",     "intersection", "subtraction",
                                          "transform",    "from_volume_surface", "extrude_2d", "species"};
const std::vector<std::string> kLayers = {"interior_layer", "exterior_layer"};

/// What the key `velocity` of a volume or a surface_mesh field does.
constexpr const char* kVelocityHelp =
    "Interface velocity (§2.4): a number, an expression of x, y, z, noise and turbulence, `{expression, noise, max}` or `{painted: ...}`; a layer is v times as thick where the speed is v (default: 1).";

/// What an entry of `materials:` is (its key is the material's name).
constexpr const char* kMaterialEntryHelp =
    "A material of this file, named by its key (not a built-in name): concrete, `{base, color, roughness, specular, "
    "density, youngs_modulus, poisson_ratio, strength}`, or procedural, `{select, choices}` (an expression of x, y, z "
    "that picks among concrete materials).";

/// What each one-key alternative of a solid is (`sprig schema`'s text for its key).
std::string_view alternativeHelp(std::string_view kind) {
  static const HelpTable kHelp = {
      {"volume", "One layered volume: a `distance_field`, its `layers` and an optional `velocity`."},
      {"precedence", "Volumes by precedence (§2.3): a list of `{volume: ...}` or `{precedence: [...]}`; the first claims its space, each next fills only what is still unclaimed."},
      {"interior_layer", "A layer stacked inward from the volume's surface, in the order written."},
      {"exterior_layer", "A layer stacked outward from the volume's surface, in the order written."},
      {"surface_mesh", "The signed distance to a closed mesh file (OBJ, PLY or OFF)."},
      {"sphere", "The exact distance to a sphere."},
      {"box", "The exact distance to a box."},
      {"cylinder", "The exact distance to a capped cylinder."},
      {"ground_plane", "The half-space below n·p = height; unbounded, so give `grid.bounds`."},
      {"union", "Union of a list of distance fields: their minimum."},
      {"intersection", "Intersection of a list of distance fields: their maximum."},
      {"subtraction", "[a, b]: a minus b, max(a, −b)."},
      {"transform", "A field scaled, rotated and moved: d(p) = s·child(R⁻¹(p − t)/s), still Euclidean."},
      {"from_volume_surface", "The outermost interface of a volume or precedence list as a new field (§2.3, Fig. 2c); the inner volumes are part of the solid."},
      {"extrude_2d", "The paper's 2D_EXTRUDE (§5.2): the dark pixels of an image, extruded along `axis` between two heights."},
      {"species", "A Sprig blob, shell, tree or organism species as a field: its final stage meshed as `sprig mesh` does, then its signed distance."}};
  return helpIn(kHelp, kind);
}


/// Reads the solid section; every error goes to diags.
class SolidReader {
 public:
  SolidReader(DiagnosticList& diags, SolidSpec& spec, const PathPolicy& policy) : diags_(diags), spec_(spec), policy_(policy) {}

  void readMaterials(const YNode& section) {
    MapReader m(section, diags_, "materials");
    if (auto entry = describeEntry(section, kMaterialEntryHelp)) {  // `sprig schema`: either form's keys
      readConcrete(entry->first.scalar(), entry->second);
      readProcedural(entry->first.scalar(), entry->second);
    }
    const auto pairs = section.pairs();
    // Concrete materials first, so procedural ones may choose among any of them.
    for (int pass = 0; pass < 2; ++pass)
      for (const auto& [key, value] : pairs) {
        const std::string name = key.scalar();
        const bool procedural = value.isMap() && value.node()["select"].IsDefined();
        if (procedural != (pass == 1)) continue;
        m.get(name);
        if (name == "nothing" || findBuiltinMaterial(name)) {
          key.error(diags_, sprig::quoted(name) + " is a built-in material: name yours differently (or start from it with 'base: " + name + "')");
          continue;
        }
        if (procedural) readProcedural(name, value);
        else readConcrete(name, value);
      }
    m.finish();
  }

  void readSolid(const YNode& section) {
    MapReader m(section, diags_, "solid");
    std::optional<YNode> grid = m.section({"grid", "The tetrahedral grid: `cell` (edge of the cubic cells, world units) and `bounds` (the box meshed); default automatic."});
    spec_.smoothRounds = int(m.integer({"smooth", "Rounds of smoothing alone after meshing."}, 0, 0, 10));
    spec_.coarsenLevels = int(m.integer({"coarsen", "Octree levels merged where no interface crosses (§4.4, Fig. 4)."}, 0, 0, 6));
    spec_.coarsenTolerance = m.number({"coarsen_tolerance", "With `coarsen`: blocks an interface crosses merge too where every field is affine to within this many cells."}, 0, 0, 0.5);
    double toleranceCells = 0;
    if (std::optional<YNode> improve = m.section({"improve", "Quality improvement by flips, collapses and smoothing (§4.4): `quality_below`, `tolerance`, `target_tetrahedra`."})) {
      MapReader r(*improve, diags_, "improve");
      solids::ImproveOptions& o = spec_.improve.emplace();
      o.qualityBelow = double(r.integer({"quality_below", "The last quality threshold of the paper's loop (q = 1, 2, ... up to this)."}, 10, 1, 10));
      toleranceCells = r.number({"tolerance", "How far a collapse may move an interface, in cells (0: only where it is flat, so every material keeps its volume)."}, 0, 0, 0.5);
      o.targetCount = size_t(r.integer({"target_tetrahedra", "The count whose share of the volume is the ideal tetrahedron volume (0 = the count after meshing)."}, 0, 0, 1000000000));
      r.finish();
    }
    if (auto ops = m.get({"operations", "Simulation tools applied in order after meshing: `hammer`, `displace`, `polish`, `dirt`, `wash`, `erode`, `lichen`."})) spec_.operations = readSolidOperations(*ops, spec_.solid.materials, diags_);
    readVolumes(m, section, "solid");
    m.finish();
    if (!diags_.hasErrors() && !spec_.solid.volumes.empty()) resolveGrid(grid, section);
    if (spec_.improve) spec_.improve->interfaceTolerance = toleranceCells * spec_.grid.cell;
    // Wrappers reach two cells inward, closing the gap to the volumes they wrap.
    for (size_t v : wrappers_) closeInward(spec_.solid.volumes[v], 2 * spec_.grid.cell);
  }

 private:
  // ---- materials ----
  void readConcrete(const std::string& name, const YNode& value) {
    MapReader m(value, diags_, "material " + sprig::quoted(name));
    Material mat;
    if (auto b = m.get({"base", "A built-in material to start from (its values, then the keys below override them)."})) {
      const std::string base = b->scalar();
      if (const Material* bm = findBuiltinMaterial(base)) mat = *bm;
      else b->error(diags_, "unknown built-in material " + sprig::quoted(base) + didYouMean(base, builtinNames()));
    }
    mat.name = name;
    mat.color = m.color({"color", "Render colour of the material."}, mat.color);
    mat.roughness = float(m.number({"roughness", "Render roughness, 0 to 1."}, mat.roughness, 0.0, 1.0));
    mat.specular = float(m.number({"specular", "Render specular reflectance."}, mat.specular, 0.0, 1.0));
    mat.density = m.number({"density", "Density, kg/m³ (one world unit is one metre)."}, mat.density, 1e-9, 1e6);
    mat.youngsModulus = m.number({"youngs_modulus", "Young's modulus, Pa: the stiffness the simulation tools use."}, mat.youngsModulus, 1e-9, 1e15);
    mat.poissonRatio = m.number({"poisson_ratio", "Poisson's ratio, in [0, 0.5)."}, mat.poissonRatio, 0.0, 0.4999);
    mat.strength = m.number({"strength", "Tensile strength, Pa: `hammer` breaks a tetrahedron whose stress exceeds it."}, mat.strength, 1e-9, 1e15);
    m.finish();
    spec_.solid.materials.materials.push_back(mat);
    names_[name] = int(spec_.solid.materials.materials.size() - 1);
  }

  void readProcedural(const std::string& name, const YNode& value) {
    MapReader m(value, diags_, "material " + sprig::quoted(name));
    ProceduralMaterial p;
    p.name = name;
    std::optional<YNode> sel = m.get({"select", "An expression of x, y, z (the grammar's expression language): its value, truncated and clamped to the list, picks among `choices`."});
    std::vector<YNode> choices = m.sequence({"choices", "The concrete materials `select` picks among; required."});
    m.finish();
    if (choices.empty()) {
      value.error(diags_, "missing required key 'choices' in material " + sprig::quoted(name) + " (the materials 'select' indexes)");
      return;
    }
    for (const YNode& c : choices) {
      const int id = materialId(c, false);
      if (id >= 0) p.choices.push_back(id);
      else if (id == kNothing || id <= kProcedural0) c.error(diags_, "a choice of a procedural material must be a concrete material");
    }
    if (auto text = sel ? sel->asString(diags_, "'select'") : std::nullopt) {
      try {
        const SourceLoc at = sel->loc();
        p.select = lsystem::Expression::compile(*text, {"x", "y", "z"}, at, sel->file().sourceLine(at.line));
      } catch (const InputError& e) {
        diags_.append(e.diagnostics());
        return;
      }
    }
    if (p.choices.size() != choices.size()) return;
    spec_.solid.materials.procedural.push_back(std::move(p));
    names_[name] = kProcedural0 - int(spec_.solid.materials.procedural.size() - 1);
  }

  static std::vector<std::string> builtinNames() {
    std::vector<std::string> n;
    for (const Material& m : builtinMaterials()) n.push_back(m.name);
    return n;
  }

  /// The id of the material named at node; kUnclaimed after an error.
  int materialId(const YNode& node, bool allowNothing = true) {
    std::optional<std::string> name = node.asString(diags_, "'material'");
    if (!name) return kUnclaimed;
    if (*name == "nothing" && allowNothing) return kNothing;
    if (auto it = names_.find(*name); it != names_.end()) return it->second;
    if (auto id = spec_.solid.materials.concrete(*name)) return *id;
    std::vector<std::string> all = builtinNames();
    for (const auto& [n, id] : names_) all.push_back(n);
    all.push_back("nothing");
    node.error(diags_, "unknown material " + sprig::quoted(*name) + didYouMean(*name, all) +
                           " (built-in: chocolate, white_chocolate, nut, pink_frosting, foil, bronze, shiny_bronze, "
                           "fired_clay, stone, dirt, brick, wood; or define it under 'materials')");
    return kUnclaimed;
  }

  // ---- volumes ----
  /// The one `volume` or `precedence` of map m (in `what`); false after an error.
  bool readVolumes(MapReader& m, const YNode& node, const std::string& what) {
    bool any = false;
    for (const std::string& form : kVolumeForms)
      if (auto v = m.get({form, alternativeHelp(form)})) {
        if (any) v->error(diags_, "a " + what + " takes one 'volume' or one 'precedence' list, not both");
        any = true;
        readVolumeForm(form, *v);
      }
    if (!any) node.error(diags_, "missing required key 'volume' or 'precedence' in " + what);
    return any;
  }

  void readVolumeForm(const std::string& form, const YNode& value) {
    if (form == "volume") {
      readVolume(value);
      return;
    }
    if (!value.isSequence()) {
      value.error(diags_, "'precedence' must be a sequence of volumes ({volume: ...} or {precedence: [...]}), first claims first");
      return;
    }
    for (const YNode& item : value.items())
      if (auto one = singleKey(item, diags_, "precedence entry", kVolumeForms)) {
        describeHelp(one->second, alternativeHelp(one->first.scalar()));
        readVolumeForm(one->first.scalar(), one->second);
      }
  }

  void readVolume(const YNode& value) {
    MapReader m(value, diags_, "volume");
    FieldPtr field;
    bool wraps = false;  // the field is the outermost interface of earlier volumes
    if (auto f = m.get({"distance_field", "The volume's shape: a distance field (a primitive, a mesh, an image extruded, a union, a transform ...)."})) {
      field = readField(*f);
      wraps = f->isMap() && f->node().size() == 1 && f->node()["from_volume_surface"].IsDefined();
    } else {
      value.error(diags_, "missing required key 'distance_field' in volume");
    }
    std::optional<VelocityWrap> velocity;
    std::optional<YNode> velocityNode = m.get({"velocity", kVelocityHelp});
    if (velocityNode) velocity = readVelocity(*velocityNode, diags_, nullptr, false);
    std::vector<Layer> layers;
    std::vector<std::optional<YNode>> layerVelocity;
    const std::vector<YNode> items = m.sequence({"layers", "The volume's layers from its surface: `interior_layer` entries inward, `exterior_layer` entries outward."});
    if (items.empty() && !m.has("layers")) value.error(diags_, "missing required key 'layers' in volume");
    for (const YNode& item : items) {
      std::optional<YNode> lv;
      if (auto l = readLayer(item, &lv)) {
        layers.push_back(*l);
        layerVelocity.push_back(lv);
      }
    }
    m.finish();
    if (!field || layers.size() != items.size() || layers.empty() || (velocityNode && !velocity)) return;
    // Per-layer velocity (§2.4, LUMPY_CANDY) is sugar for nested volumes: the first exterior
    // layer's velocity is the field's; each later exterior layer with a velocity starts a
    // volume of its own whose field is the outermost interface of the volumes before it.
    std::vector<size_t> starts{0};
    bool firstExterior = true;
    for (size_t i = 0; i < layers.size(); ++i) {
      if (!layerVelocity[i]) {
        if (!layers[i].interior) firstExterior = false;
        continue;
      }
      if (layers[i].interior) {
        layerVelocity[i]->error(diags_, "a per-layer 'velocity' is for exterior layers (they nest outward, as in the paper's "
                                        "LUMPY_CANDY); give the volume a 'velocity' for its interior layers");
        return;
      }
      if (firstExterior) {
        if (velocityNode) {
          layerVelocity[i]->error(diags_, "the volume has a 'velocity' already: the first exterior layer's velocity is the volume's");
          return;
        }
        velocity = readVelocity(*layerVelocity[i], diags_, nullptr, false);
        if (!velocity) return;
      } else {
        starts.push_back(i);
      }
      firstExterior = false;
    }
    if (velocity) field = (*velocity)(field);
    if (!field) return;
    std::vector<Volume> nest;
    for (size_t r = 0; r < starts.size(); ++r) {
      const size_t end = r + 1 < starts.size() ? starts[r + 1] : layers.size();
      const std::vector<Layer> run(layers.begin() + long(starts[r]), layers.begin() + long(end));
      if (r > 0) {
        std::optional<VelocityWrap> v = readVelocity(*layerVelocity[starts[r]], diags_, nullptr, true);
        if (!v) return;
        field = (*v)(volumeSurfaceField(nest));
        if (!field) return;
      }
      if (!addVolume(value, field, run)) return;
      if (wraps || r > 0) wrappers_.push_back(spec_.solid.volumes.size() - 1);
      nest.push_back(spec_.solid.volumes.back());
    }
  }

  /// Appends a volume of field with layers; false after an error at node.
  bool addVolume(const YNode& node, const FieldPtr& field, const std::vector<Layer>& layers) {
    try {
      spec_.solid.volumes.push_back(makeVolume(field, layers));
      maxExterior_ = std::max(maxExterior_, spec_.solid.volumes.back().boundaries.back());
      for (const Layer& l : layers)
        if (!l.fill) thinnest_ = std::min(thinnest_, l.thickness * std::min(1.0, field->reach()));
      return true;
    } catch (const std::invalid_argument& e) {
      node.error(diags_, e.what());
      return false;
    }
  }

  std::optional<Layer> readLayer(const YNode& item, std::optional<YNode>* velocity) {
    auto one = singleKey(item, diags_, "layer", kLayers);
    if (!one) return std::nullopt;
    describeHelp(one->second, alternativeHelp(one->first.scalar()));
    Layer l;
    l.interior = one->first.scalar() == "interior_layer";
    MapReader m(one->second, diags_, one->first.scalar());
    const size_t errors = errorCount();
    *velocity = m.get({"velocity", "An exterior layer's own interface velocity (§2.4, LUMPY_CANDY): it starts a volume wrapping the ones before it (an error on an interior layer); forms as the volume's `velocity`."});
    m.markRequired("material");
    if (auto mat = m.get({"material", "The layer's material: one of the file's `materials:`, a built-in material, or `nothing` (air that claims its space)."})) l.material = materialId(*mat);
    else one->second.error(diags_, "missing required key 'material' in " + one->first.scalar() + " (a material name or nothing)");
    if (auto t = m.get({"thickness", "How thick the layer is, in world units, or `fill` (an interior layer fills the rest of the volume)."})) {
      describeValue(*t, 0.0, {"fill"});
      if (t->isPlainScalar() && t->scalar() == "fill") {
        l.fill = true;
        if (!l.interior) t->error(diags_, "'thickness: fill' is for interior layers (an exterior layer needs a number)");
      } else if (auto v = t->asNumber(diags_, "'thickness'")) {
        if (*v <= 0) t->error(diags_, "'thickness' must be positive (world units, or fill), got " + t->scalar());
        l.thickness = *v;
      }
    }
    m.finish();
    return errorCount() == errors ? std::optional<Layer>(l) : std::nullopt;
  }

  // ---- distance fields ----
  FieldPtr readField(const YNode& node) {
    auto one = singleKey(node, diags_, "distance field", kFields);
    if (!one) return nullptr;
    const std::string kind = one->first.scalar();
    const YNode& value = one->second;
    describeHelp(value, alternativeHelp(kind));
    if (kind == "from_volume_surface") return readVolumeSurface(value);
    if (kind == "union" || kind == "intersection" || kind == "subtraction") {
      if (!value.isSequence() || value.items().empty()) {
        value.error(diags_, sprig::quoted(kind) + " must be a sequence of distance fields");
        return nullptr;
      }
      std::vector<FieldPtr> parts;
      for (const YNode& item : value.items()) parts.push_back(readField(item));
      if (std::find(parts.begin(), parts.end(), nullptr) != parts.end()) return nullptr;
      if (kind == "union") return unionField(parts);
      if (kind == "intersection") return intersectionField(parts);
      if (parts.size() != 2) {
        value.error(diags_, "'subtraction' takes two distance fields [a, b] (a minus b), got " + std::to_string(parts.size()));
        return nullptr;
      }
      return subtractionField(parts[0], parts[1]);
    }
    MapReader m(value, diags_, kind);
    FieldPtr out;
    if (kind == "surface_mesh") {
      PolyMesh mesh;
      out = readMesh(m, &mesh);
      out = withOffset(m, out);
      if (auto v = m.get({"velocity", kVelocityHelp})) {
        std::optional<VelocityWrap> w = readVelocity(*v, diags_, &mesh, false, &policy_);
        out = w && out ? (*w)(out) : nullptr;
      }
    } else if (kind == "species") {
      out = readSpeciesField(m, policy_);
      out = withOffset(m, out);
    } else if (kind == "sphere") {
      out = sphereField(DVec3(m.vec3({"center", "Centre of the sphere."}, Vec3(0.0f))),
                        m.number({"radius", "Radius of the sphere, world units."}, 1.0, 1e-6, 1e6));
    } else if (kind == "box") {
      out = boxField(DVec3(m.vec3({"center", "Centre of the box."}, Vec3(0.0f))),
                     DVec3(m.vec3({"size", "Edge lengths of the box along x, y and z, world units."}, Vec3(1.0f), 1e-6, 1e6)));
    } else if (kind == "cylinder") {
      const Vec3 c = m.vec3({"center", "Centre of the cylinder (the middle of its axis)."}, Vec3(0.0f));
      const double r = m.number({"radius", "Radius of the cylinder, world units."}, 0.5, 1e-6, 1e6),
                   h = m.number({"height", "Height of the cylinder along its axis, world units."}, 1.0, 1e-6, 1e6);
      out = cylinderField(DVec3(c), r, h, DVec3(axisOf(m, {"axis", "Direction of the cylinder's axis (not zero)."})));
    } else if (kind == "ground_plane") {
      out = groundPlaneField(DVec3(axisOf(m, {"normal", "Normal n of the plane, pointing out of the ground (not zero)."})),
                             m.number({"height", "The plane is n·p = height; the ground lies below it."}, 0.0));
    } else if (kind == "transform") {
      FieldPtr child;
      m.markRequired("distance_field");
      if (auto f = m.get({"distance_field", "The distance field transformed."})) child = readField(*f);
      else value.error(diags_, "missing required key 'distance_field' in transform");
      const double scale = m.number({"scale", "Uniform scale s, applied first (the paper's scaling)."}, 1.0, 1e-6, 1e6);
      Vec3 axis(0, 1, 0);
      double angle = 0;
      if (auto r = m.section({"rotate", "Rotation `{axis, angle_deg}` about the origin, after the scale."})) {
        MapReader rm(*r, diags_, "rotate");
        axis = axisOf(rm, {"axis", "Axis of the rotation (not zero)."});
        angle = rm.number({"angle_deg", "Angle of the rotation, in degrees."}, 0.0, -360.0, 360.0);
        rm.finish();
      }
      const Vec3 t = m.vec3({"translate", "Translation, applied last, world units."}, Vec3(0.0f));
      if (child) out = transformField(child, scale, DVec3(axis), angle, DVec3(t));
    } else if (kind == "extrude_2d") {
      out = readExtrude(m);
    }
    m.finish();
    return out;
  }

  /// A mesh field grown by its `offset` (world units, >= 0; 0: as it is), so walls thinner
  /// than the grid's cells survive meshing (docs/SOLIDS.md).
  FieldPtr withOffset(MapReader& m, FieldPtr field) {
    const double by = m.number({"offset", "Grow the solid by this distance before meshing, world units: walls thinner than a cell survive (0 = as it is)."}, 0.0, 0.0, 1e6);
    return field && by > 0 ? offsetField(std::move(field), by) : field;
  }

  /// A unit direction at key (default +y); zero is an error.
  Vec3 axisOf(MapReader& m, Key key) {
    const Vec3 a = m.vec3(key, Vec3(0, 1, 0));
    if (glm::length(a) == 0) {
      m.get(key)->error(diags_, sprig::quoted(key.name) + " must not be zero");
      return Vec3(0, 1, 0);
    }
    return glm::normalize(a);
  }

  /// The outermost interface of a volume or a precedence list (§2.3, Fig. 2c). The inner
  /// volumes are part of the solid, in precedence before the volume that uses the field.
  FieldPtr readVolumeSurface(const YNode& value) {
    MapReader m(value, diags_, "from_volume_surface");
    const size_t first = spec_.solid.volumes.size();
    const bool any = readVolumes(m, value, "from_volume_surface");
    std::optional<VelocityWrap> velocity;
    std::optional<YNode> vn = m.get({"velocity", "Speed of the front that measures the wrapped volumes' outer surface again as a distance (arrival time); forms as a volume's `velocity` (default: 1)."});
    if (vn) velocity = readVelocity(*vn, diags_, nullptr, true);
    m.finish();
    if (!any || spec_.solid.volumes.size() == first || (vn && !velocity)) return nullptr;
    std::vector<Volume> inner(spec_.solid.volumes.begin() + long(first), spec_.solid.volumes.end());
    FieldPtr surface = volumeSurfaceField(std::move(inner));
    return velocity ? (*velocity)(surface) : redistanced(surface);
  }

  /// A closed mesh file as a field; the first open edge is an error at its face.
  FieldPtr readMesh(MapReader& m, PolyMesh* keep = nullptr) {
    m.markRequired("file");
    auto file = m.path({"file", "A closed mesh file (OBJ, PLY or OFF), relative to the species file; required."}, policy_);
    if (!file) {
      if (!m.has("file")) m.node().error(diags_, "missing required key 'file' in surface_mesh (an OBJ, PLY or OFF file)");
      return nullptr;
    }
    try {
      PolyMesh mesh = readPolyMesh(*file);
      const size_t before = errorCount();
      checkPolyMesh(mesh, diags_);
      if (errorCount() != before) return nullptr;
      if (auto open = firstOpenEdge(mesh)) {
        const std::string what = "mesh " + sprig::quoted(file->string()) + " is not closed: the edge from vertex " +
                                 std::to_string(open->a + 1) + " to vertex " + std::to_string(open->b + 1) +
                                 " has only this face (a distance field needs a closed mesh)";
        if (open->face < mesh.faceLocs.size() && mesh.faceLocs[open->face].line > 0) {
          const SourceLoc& at = mesh.faceLocs[open->face];
          diags_.error(at, what);
        } else {
          m.get("file")->error(diags_, what);
        }
        return nullptr;
      }
      FieldPtr field = meshField(mesh);
      if (keep) *keep = std::move(mesh);
      return field;
    } catch (const InputError& e) {
      diags_.append(e.diagnostics());
    } catch (const std::invalid_argument& e) {
      m.get("file")->error(diags_, e.what());
    }
    return nullptr;
  }

  // ---- grid ----
  void resolveGrid(const std::optional<YNode>& gridNode, const YNode& section) {
    std::optional<DBox3> box;
    double cell = 0;
    if (gridNode) {
      MapReader gm(*gridNode, diags_, "grid");
      cell = gm.number({"cell", "Edge of the cubic cells, world units (default: min(largest side / 64, thinnest layer / 2), at least largest side / 200)."}, 0.0, 1e-6, 1e6);
      if (auto b = gm.section({"bounds", "The box meshed: `{min: [x, y, z], max: [x, y, z]}` (default: every volume's box and outermost layer, plus a cell)."})) {
        MapReader bm(*b, diags_, "bounds");
        const Vec3 lo = bm.vec3({"min", "Lowest corner of the box meshed."}, Vec3(-1.0f)),
                   hi = bm.vec3({"max", "Highest corner of the box meshed."}, Vec3(1.0f));
        bm.finish();
        if (!(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z)) b->error(diags_, "'bounds' needs min < max on every axis");
        box = DBox3{DVec3(lo), DVec3(hi)};
      }
      gm.finish();
    }
    if (!box) {
      DBox3 all;
      for (const Volume& v : spec_.solid.volumes) {
        std::optional<DBox3> b = v.field->bounds();
        if (!b) {
          (gridNode ? *gridNode : section)
              .error(diags_, "a volume has no bounds (a ground plane): give 'grid: {bounds: {min: [x, y, z], max: [x, y, z]}}'");
          return;
        }
        all.extend(b->expanded(std::max(0.0, v.boundaries.back()) * v.field->reach()));
      }
      box = all;
    }
    const YNode& at = gridNode ? *gridNode : section;
    if (box->empty()) {  // (an intersection of volumes that do not meet)
      at.error(diags_, "the solid's volumes hold no point: there is nothing to mesh");
      return;
    }
    if (!withinSolidRange(*box)) {
      char buf[256];
      std::snprintf(buf, sizeof buf, "the solid's volumes reach (%g, %g, %g) - (%g, %g, %g): every coordinate must be finite and within %g",
                    box->lo.x, box->lo.y, box->lo.z, box->hi.x, box->hi.y, box->hi.z, kMaxSolidCoordinate);
      at.error(diags_, buf);
      return;
    }
    const DVec3 size = box->size();
    const double largest = std::max(size.x, std::max(size.y, size.z));
    if (cell <= 0) cell = std::max(std::min(largest / kDefaultCellsAcross, thinnest_ / 2), largest / kFinestCellsAcross);
    if (!(cell > 0)) {  // a box of zero size (every volume a point) and no 'cell'
      at.error(diags_, "the solid's volumes have zero size: there is nothing to mesh");
      return;
    }
    // One cell of margin around the box so the outermost interface closes inside the grid.
    const DBox3 padded = box->expanded(gridNode && gridNode->node()["bounds"].IsDefined() ? 0.0 : cell);
    // Counts in double (the box and cell are finite, the quotients may still be huge).
    double cells[3], nodes = 1;
    for (int a = 0; a < 3; ++a) {
      cells[a] = std::max(1.0, std::ceil((padded.hi[a] - padded.lo[a]) / cell - 1e-9));
      nodes *= cells[a] + 1;
    }
    if (!(nodes <= double(kMaxGridNodes))) {
      at.error(diags_, "'grid' of cell " + countText(cell) + " makes " + countText(cells[0]) + " x " + countText(cells[1]) +
                           " x " + countText(cells[2]) + " cells (" + countText(nodes) + " nodes), more than the limit " +
                           std::to_string(kMaxGridNodes) + "; use a larger 'cell'");
      return;
    }
    Grid g;
    g.origin = padded.lo;
    g.cell = cell;
    for (int a = 0; a < 3; ++a) g.cells[a] = int(cells[a]);
    spec_.grid = g;
  }

  size_t errorCount() const {
    return size_t(std::count_if(diags_.items().begin(), diags_.items().end(),
                                [](const Diagnostic& d) { return d.severity == Severity::Error; }));
  }

  DiagnosticList& diags_;
  SolidSpec& spec_;
  const PathPolicy& policy_;
  std::map<std::string, int> names_;  ///< file materials: concrete ids and procedural codes
  std::vector<size_t> wrappers_;  ///< volumes whose field is from_volume_surface
  double maxExterior_ = 0;
  double thinnest_ = 1e30;

  // ---- extrude_2d ----
  /// `[a, b]` of finite numbers at key (def when absent; after an error too).
  glm::dvec2 pairOf(MapReader& m, Key key, glm::dvec2 def) {
    std::optional<YNode> v = m.get(key);
    if (!v) return def;
    const std::vector<YNode> items = v->items();
    if (!v->isSequence() || items.size() != 2) {
      v->error(diags_, sprig::quoted(key.name) + " must be [a, b]");
      return def;
    }
    auto a = items[0].asNumber(diags_, sprig::quoted(key.name)), b = items[1].asNumber(diags_, sprig::quoted(key.name));
    return a && b ? glm::dvec2(*a, *b) : def;
  }

  /// `extrude_2d: {file, size, center, axis, height, threshold}` (the paper's 2D_EXTRUDE):
  /// pixels of the image darker than threshold (the sRGB encoding of the linear Rec. 709
  /// luminance: 0 black, 1 white) form the region; solids/extrude_field.h places and extrudes it.
  FieldPtr readExtrude(MapReader& m) {
    m.markRequired("file");
    auto file = m.path({"file", "The image (PNG, PPM/PGM or any format OpenImageIO reads, at most 2048 × 2048), relative to the species file; required."}, policy_);
    if (!file && !m.has("file"))
      m.node().error(diags_, "missing required key 'file' in extrude_2d (a PNG or PPM image; dark pixels are inside)");
    ExtrudeOptions o;
    o.size = pairOf(m, {"size", "[along columns, along rows]: the image's size in world units (default [1, 1])."}, glm::dvec2(1.0));
    o.center = pairOf(m, {"center", "Plane coordinates of the image's centre (default [0, 0])."}, glm::dvec2(0.0));
    o.axis = DVec3(axisOf(m, {"axis", "Extrusion axis; the image lies on the plane across it (for y: columns along +x, rows along +z)."}));
    const glm::dvec2 h = pairOf(m, {"height", "[lo, hi]: the extrusion's extent along the axis, lo < hi (default [0, 1])."}, glm::dvec2(0.0, 1.0));
    o.heightLo = h.x;
    o.heightHi = h.y;
    const double threshold = m.number({"threshold", "Pixels darker than this (sRGB-encoded luminance: 0 black, 1 white) are the region."}, 0.5, 0.0, 1.0);
    if (!(o.size.x > 0 && o.size.y > 0)) m.get("size")->error(diags_, "'size' must be positive, world units [along columns, along rows]");
    if (!(o.heightHi > o.heightLo)) m.get("height")->error(diags_, "'height' must be [lo, hi] with lo < hi");
    if (!file || !(o.size.x > 0 && o.size.y > 0) || !(o.heightHi > o.heightLo)) return nullptr;
    try {
      // The transform keeps about 80 bytes per pixel of the padded image (4 times the image).
      constexpr uint64_t kMaxMaskPixels = uint64_t(2048) * 2048;
      const ImageInfo info = readImageInfo(*file);
      if (uint64_t(info.width) * uint64_t(info.height) > kMaxMaskPixels) {
        m.get("file")->error(diags_, "image " + sprig::quoted(file->string()) + " is " + std::to_string(info.width) + " x " +
                                         std::to_string(info.height) + " pixels, more than extrude_2d takes (" +
                                         std::to_string(kMaxMaskPixels) + ", 2048 x 2048)");
        return nullptr;
      }
      if (std::string why = extrudeScaleProblem(info.width, info.height, o); !why.empty()) {
        (m.has("size") ? *m.get("size") : *m.get("file")).error(diags_, why);
        return nullptr;
      }
      const Image image = readImage(*file);
      Mask2d mask;
      mask.width = image.width;
      mask.height = image.height;
      mask.inside.resize(size_t(image.width) * image.height);
      for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
          const Vec4 c = image.at(x, y);
          const float lum = linearToSrgb(0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b);
          mask.inside[size_t(y) * image.width + x] = lum < threshold ? 1 : 0;
        }
      return extrudeField(mask, o);
    } catch (const ImageReadError& e) {
      m.get("file")->error(diags_, e.what());
    } catch (const std::invalid_argument& e) {
      m.get("file")->error(diags_, e.what());
    }
    return nullptr;
  }
};

/// A solid: its tetrahedral mesh, built once.
class SolidModel final : public StillKindModel {
 public:
  explicit SolidModel(const SolidSpec& spec) : spec_(spec) {}

  // Stages of a solid with operations (`sprig animate`, the gallery's strip): stage k is the
  // solid after its first k operations, 0 the solid as meshed; the final stage all of them.
  // Without operations a solid has the one still stage.
  int operationCount() const { return int(spec_.operations.size()); }
  Stage finalStage() const override { return operationCount() == 0 ? Stage{} : stageAt(operationCount()); }
  Stage stageFromIndex(int k) const override { return operationCount() == 0 ? Stage{} : stageAt(std::clamp(k, 0, operationCount())); }
  std::vector<Stage> stripStages(int) const override { return animationFrames(1, 0, operationCount()); }
  std::vector<Stage> animationFrames(int, int first, int last) const override {
    if (operationCount() == 0) return {Stage{}};
    std::vector<Stage> out;
    const int end = last < 0 ? operationCount() : std::min(last, operationCount());
    for (int k = std::clamp(first, 0, operationCount()); k <= end; ++k) out.push_back(stageAt(k));
    return out;
  }
  std::string stageName(const Stage& stage) const override {
    if (operationCount() == 0) return {};
    const int k = stepOf(stage);
    if (k == 0) return "before the operations";
    return "after operation " + std::to_string(k) + " of " + std::to_string(operationCount()) + " (" +
           spec_.operations[size_t(k - 1)].tool + ")";
  }
  GalleryMotion galleryMotion(bool final) override {
    if (operationCount() == 0) return StillKindModel::galleryMotion(final);
    GalleryMotion m;
    m.framesPerStage = 1;
    return m;
  }

  Box3 frameBox() override {
    // The solid as meshed, so every stage of an operation sequence is framed alike.
    Box3 box;
    for (const DVec3& p : stageMesh(0).positions) box.extend(Vec3(p));
    return box.empty() ? Box3{Vec3(-1.0f), Vec3(1.0f)} : box;
  }

  BuiltStage build(const Stage& stage, GeometryMode mode, const SpeciesRender& look) override {
    const int k = stepOf(stage);
    if (mode == GeometryMode::Skeleton) throw UsageError("solid species have no skeleton: use --mode exact or mesh");
    BuiltStage out;
    const auto t0 = std::chrono::steady_clock::now();
    // Smoothed by subdivision, but not under a wireframe, which draws the tetrahedra's faces.
    VisibleMeshOptions options;
    options.subdivisions = look.wireframe ? 0 : kRenderSubdivisions;
    VisibleParts parts = look.section ? visibleParts(clipByPlane(stageMesh(k), DVec3(Vec3(*look.section)), double(look.section->w)),
                                                     &spec_.solid.materials.materials, options)
                                      : visible(k, options.subdivisions);
    for (size_t i = 0; i < parts.meshes.size(); ++i) {
      const Material& m = spec_.solid.materials.materials[parts.materials[i]];
      render::MeshPart part;
      out.figures.triangles += parts.meshes[i].triangleCount();
      part.mesh = std::move(parts.meshes[i]);
      part.material = render::Material{m.color, m.roughness, m.specular};
      part.material.smoothTerminator = true;  // coarse facets, smooth normals (render::Material)
      part.vertexSurfaces = std::move(parts.surfaces[i]);
      out.geometry.parts.push_back(std::move(part));
    }
    if (look.wireframe) addWireframe(out, *look.wireframe, look);
    out.figures.primitives = stageMesh(k).tets.size();
    out.figures.buildSeconds = secondsSince(t0) + buildSeconds_;
    return out;
  }

  /// `render.wireframe`: the edges of built's mesh parts as curves, wire.widthPixels wide
  /// at each end's depth seen through look.pixels (without a camera: 1/1000 of the frame
  /// box's diagonal per pixel of width), and never thinner than look.image.thinMinPixels
  /// (a little wider): the scene would widen a thinner curve and make it partly transparent,
  /// and a ray through it continues past its tube, which straddles the surface, so the line
  /// would show the solid's far side instead of darkening this one.
  void addWireframe(BuiltStage& built, const WireframeSpec& wire, const SpeciesRender& look) {
    const std::optional<render::PixelScale>& pixels = look.pixels;
    std::vector<Mesh> meshes;
    for (const render::GeometryPart& part : built.geometry.parts)
      if (const auto* m = std::get_if<render::MeshPart>(&part)) meshes.push_back(m->mesh);
    const float half = 0.5f * std::max(float(wire.widthPixels), 1.001f * look.image.thinMinPixels);
    const float fallback = half * glm::length(frameBox().size()) / 1000.0f;
    render::CurvesPart lines;
    lines.curves = wireframeCurves(meshes, [&](const Vec3& p) {
      if (!pixels) return fallback;
      const float depth = std::max(glm::dot(p - pixels->eye, pixels->forward), 1e-6f);
      return half * pixels->pixelPerDepth * depth;
    });
    lines.material = render::Material{wire.color, 1.0f, 0.0f};
    built.geometry.parts.push_back(std::move(lines));
  }

  Mesh buildMesh(const Stage& stage, float, bool, ModelFigures& figures) override {
    Mesh all;
    const int k = stepOf(stage);
    const VisibleParts& v = visible(k);
    const std::vector<Mesh>& parts = v.meshes;
    const std::vector<uint16_t>& mats = v.materials;
    for (size_t i = 0; i < parts.size(); ++i) {
      Mesh part = parts[i];
      if (part.colors.size() != part.vertexCount()) part.colors.assign(part.vertexCount(), spec_.solid.materials.materials[mats[i]].color);
      all.append(part);
    }
    figures.triangles = all.triangleCount();
    figures.primitives = stageMesh(k).tets.size();
    figures.buildSeconds = buildSeconds_;
    return all;
  }

  std::vector<ExportPart> exportParts(const Stage& stage, float, bool, const SpeciesRender&, const MeshCleanOptions&,
                                      ModelFigures& figures) override {
    std::vector<ExportPart> out;
    const int k = stepOf(stage);
    const VisibleParts& v = visible(k);
    const std::vector<Mesh>& parts = v.meshes;
    const std::vector<uint16_t>& mats = v.materials;
    for (size_t i = 0; i < parts.size(); ++i) {
      const Material& m = spec_.solid.materials.materials[mats[i]];
      figures.triangles += parts[i].triangleCount();
      auto same = std::find_if(out.begin(), out.end(), [&](const ExportPart& p) { return p.name == m.name; });
      if (same != out.end()) {
        same->mesh.append(parts[i]);
        continue;
      }
      out.push_back(ExportPart{m.name, parts[i], PartMaterial{m.name, m.color, m.roughness, false}});
    }
    figures.primitives = stageMesh(k).tets.size();
    figures.buildSeconds = buildSeconds_;
    return out;
  }

  std::vector<std::string> volumeMeshExtensions() const override { return {".msh", ".vtu", ".mesh"}; }

  std::vector<std::pair<std::string, Mesh>> interfaceMeshes(const Stage& stage) override {
    const TetMesh& m = stageMesh(stepOf(stage));
    const auto& mats = spec_.solid.materials.materials;
    // (A, B) with A < B, or (A, outside): triangles oriented out of A.
    std::map<std::pair<int, int>, std::vector<std::array<uint32_t, 3>>> groups;
    const std::vector<InterfaceTriangle> inner = materialInterfaces(m);
    for (size_t k = 0; k + 1 < inner.size(); k += 2) {
      const InterfaceTriangle& a = inner[k].material < inner[k + 1].material ? inner[k] : inner[k + 1];
      const InterfaceTriangle& b = &a == &inner[k] ? inner[k + 1] : inner[k];
      groups[{a.material, b.material}].push_back(a.v);
    }
    for (const InterfaceTriangle& t : visibleInterface(m)) groups[{t.material, -1}].push_back(t.v);
    std::vector<std::pair<std::string, Mesh>> out;
    for (const auto& [pair, tris] : groups) {
      Mesh mesh;
      std::map<uint32_t, uint32_t> index;
      for (const auto& t : tris) {
        glm::uvec3 tri;
        for (int c = 0; c < 3; ++c) {
          auto [it, fresh] = index.emplace(t[size_t(c)], uint32_t(mesh.positions.size()));
          if (fresh) mesh.positions.push_back(Vec3(m.positions[t[size_t(c)]]));
          tri[c] = it->second;
        }
        mesh.triangles.push_back(tri);
      }
      mesh.colors.assign(mesh.positions.size(), mats[size_t(pair.first)].color);
      if (pair.second < 0 && m.tints.size() == m.positions.size())  // the visible faces carry the tools' tints
        for (const auto& [x, i] : index)
          mesh.colors[i] = glm::mix(mats[size_t(pair.first)].color, Vec3(m.tints[x]), std::clamp(m.tints[x].w, 0.0f, 1.0f));
      out.emplace_back(mats[size_t(pair.first)].name + "_" + (pair.second < 0 ? "outside" : mats[size_t(pair.second)].name),
                       std::move(mesh));
    }
    return out;
  }

  std::string writeVolumeMesh(const Stage& stage, const std::filesystem::path& path, bool) override {
    const TetMesh& m = stageMesh(stepOf(stage));
    writeTetMesh(m, spec_.solid.materials.materials, path);
    // Smoothing or improvement measured it already, unless operations changed the mesh since.
    const bool measured = stepOf(stage) == 0;
    const QualityStats q = measured && improved_ ? improved_->after : measured && smooth_ ? smooth_->after : measureQuality(m);
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "%s: %zu tetrahedra, %zu vertices (grid %dx%dx%d of cell %g; fields %.2f s, mesh %.2f s); "
                  "quality min %.2f mean %.2f, smallest solid angle %.2g sr",
                  path.string().c_str(), m.tets.size(), m.positions.size(), spec_.grid.cells[0], spec_.grid.cells[1],
                  spec_.grid.cells[2], spec_.grid.cell, stats_.fieldSeconds, stats_.meshSeconds, q.minQuality,
                  q.meanQuality, q.minSolidAngle);
    std::string line = buf;
    if (spec_.coarsenLevels > 0) {
      std::snprintf(buf, sizeof buf, "; octree %zu leaves, %zu coarse, %zu transition", stats_.cubes, stats_.coarseCubes,
                    stats_.transitionCubes);
      line += buf;
    }
    if (smooth_) {
      std::snprintf(buf, sizeof buf, "; smoothing %.2f s, %zu moves, quality min %.2f -> %.2f, mean %.2f -> %.2f", smoothSeconds_,
                    smooth_->moved, smooth_->before.minQuality, smooth_->after.minQuality, smooth_->before.meanQuality,
                    smooth_->after.meanQuality);
      line += buf;
    }
    if (improved_) {
      const ImproveStats& i = *improved_;
      std::snprintf(buf, sizeof buf,
                    "; improvement %.2f s: %zu -> %zu tetrahedra (%zu 2-3, %zu 3-2 and %zu 2-2 flips, %zu collapses, %zu moves), "
                    "quality min %.2f -> %.2f, mean %.2f -> %.2f",
                    improveSeconds_, i.tetsBefore, i.tetsAfter, i.flips23, i.flips32, i.flips22, i.collapses, i.moves, i.before.minQuality,
                    i.after.minQuality, i.before.meanQuality, i.after.meanQuality);
      line += buf;
    }
    return line;
  }

 private:
  static Stage stageAt(int k) {
    Stage st;
    st.step = k;
    return st;
  }
  /// The operations a stage has applied (-1 and out of range: all).
  int stepOf(const Stage& stage) const {
    return stage.step < 0 || stage.step > operationCount() ? operationCount() : stage.step;
  }

  /// The mesh after the first k operations, unused vertices dropped (built once per k; the
  /// operations run once, in order, whatever stages are asked for).
  const TetMesh& stageMesh(int k) {
    if (!mesh_) {
      const auto t0 = std::chrono::steady_clock::now();
      solids::MeshOptions options;
      options.coarsenLevels = spec_.coarsenLevels;
      options.coarsenTolerance = spec_.coarsenTolerance;
      mesh_ = meshSolid(spec_.solid, spec_.grid, options, &stats_);
      if (spec_.smoothRounds > 0) {
        const auto s0 = std::chrono::steady_clock::now();
        smooth_ = smoothInterior(*mesh_, spec_.smoothRounds);
        smoothSeconds_ = secondsSince(s0);
      }
      if (spec_.improve) {
        const auto s0 = std::chrono::steady_clock::now();
        improved_ = improveQuality(*mesh_, *spec_.improve);
        improveSeconds_ = secondsSince(s0);
      }
      working_ = *mesh_;
      applied_ = 0;
      stages_.clear();
      stages_.emplace(0, *mesh_);
      buildSeconds_ = secondsSince(t0);
    }
    auto it = stages_.find(k);
    if (it != stages_.end()) return it->second;
    const auto t0 = std::chrono::steady_clock::now();
    while (applied_ < k) {
      applySolidOperation(working_, spec_.solid.materials.materials, spec_.operations[size_t(applied_)]);
      ++applied_;
      TetMesh out = working_;
      solids::compactVertices(out);
      stages_.emplace(applied_, std::move(out));
    }
    buildSeconds_ += secondsSince(t0);
    return stages_.at(k);
  }

  /// A stage's render meshes and their materials at `levels` of subdivision, kept: turntable
  /// frames reuse them. A subdivided stage has 16 times the triangles, so only the last one
  /// asked for is kept (a sequence's pictures take the stages one after another).
  const VisibleParts& visible(int k, int levels = 0) {
    auto it = visible_.find({k, levels});
    if (it == visible_.end()) {
      if (levels > 0) std::erase_if(visible_, [](const auto& entry) { return entry.first.second > 0; });
      VisibleMeshOptions options;
      options.subdivisions = levels;
      it = visible_.emplace(std::make_pair(k, levels), visibleParts(stageMesh(k), &spec_.solid.materials.materials, options)).first;
    }
    return it->second;
  }

  const SolidSpec& spec_;
  std::optional<TetMesh> mesh_;
  std::optional<SmoothStats> smooth_;
  double smoothSeconds_ = 0;
  std::optional<ImproveStats> improved_;
  double improveSeconds_ = 0;
  TetMesh working_;   ///< the mesh after `applied_` operations, vertices not yet dropped
  int applied_ = 0;
  std::map<int, TetMesh> stages_;
  std::map<std::pair<int, int>, VisibleParts> visible_;  ///< by (stage, subdivision levels)
  MeshStats stats_;
  double buildSeconds_ = 0;
};

}  // namespace

CurveSet wireframeCurves(const std::vector<Mesh>& parts, const std::function<float(const Vec3&)>& radiusAt) {
  using Point = std::array<float, 3>;
  std::vector<std::pair<Point, Point>> edges;
  for (const Mesh& m : parts)
    for (const auto& t : m.triangles)
      for (int i = 0; i < 3; ++i) {
        const Vec3 a = m.positions[t[i]], b = m.positions[t[(i + 1) % 3]];
        Point pa{a.x, a.y, a.z}, pb{b.x, b.y, b.z};
        if (pb < pa) std::swap(pa, pb);
        if (pa != pb) edges.push_back({pa, pb});
      }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  CurveSet out;
  out.vertices.reserve(2 * edges.size());
  for (const auto& [pa, pb] : edges) {
    out.segments.push_back(uint32_t(out.vertices.size()));
    out.flags.push_back(0);
    for (const Point& p : {pa, pb}) {
      const Vec3 v(p[0], p[1], p[2]);
      out.vertices.push_back(Vec4(v, radiusAt(v)));
    }
  }
  return out;
}

namespace {

/// A boundary surface as its render and export meshes are made from it: the surface
/// vertices (each with its tint when the mesh has tints), the triangles with their
/// material, and the smooth groups: around each vertex the faces are grouped (in face
/// order, each face joining the first group whose direction lies within 60° of its own;
/// sharper edges, a cut-away's rim or a box's edges, stay creased), whatever material each
/// face is, so where two materials meet on a smooth surface (polished and plain bronze)
/// the shading is continuous. Each group gets one normal and one output vertex per part.
struct GroupedSurface {
  std::vector<DVec3> positions;                   ///< per surface vertex
  std::vector<Vec4> tints;                        ///< per surface vertex; empty when untinted
  std::vector<std::array<uint32_t, 3>> tris;      ///< surface vertex ids
  std::vector<uint16_t> materials;                ///< per triangle
  std::vector<std::array<uint32_t, 3>> corner;    ///< per triangle, the group of each corner
  std::vector<uint32_t> vertexOf;                 ///< the surface vertex of each group
  /// With materials (blendGroups), per group: the base colour and the render surface
  /// (roughness, specular, metallic 0), each the area-weighted mean over its faces' materials.
  std::vector<Vec3> groupColor, groupSurface;
};

Vec3 faceCross(const GroupedSurface& s, size_t f) {
  const auto& v = s.tris[f];
  const Vec3 a(s.positions[v[0]]), b(s.positions[v[1]]), c(s.positions[v[2]]);
  return glm::cross(b - a, c - a);
}

GroupedSurface groupedSurface(const solids::BoundarySurface& surface, const TetMesh& mesh, bool tinted) {
  constexpr float kCreaseCos = 0.5f;
  GroupedSurface out;
  out.positions = surface.positions;
  for (const InterfaceTriangle& t : surface.triangles) {
    out.tris.push_back(t.v);
    out.materials.push_back(t.material);
  }
  if (tinted)
    for (const auto& [sa, sb] : surface.sources)  // an inserted midpoint takes the mean of its edge's ends
      out.tints.push_back(0.5f * (mesh.tints[sa] + mesh.tints[sb]));
  std::vector<Vec3> faceNormal(out.tris.size());
  std::vector<std::vector<uint32_t>> around(out.positions.size());
  for (size_t f = 0; f < out.tris.size(); ++f) {
    faceNormal[f] = faceCross(out, f);
    for (uint32_t x : out.tris[f]) around[x].push_back(uint32_t(f));
  }
  out.corner.resize(out.tris.size());
  for (uint32_t x = 0; x < around.size(); ++x) {
    std::vector<Vec3> groups;  // summed unit directions, for group ids first .. first + size
    const uint32_t first = uint32_t(out.vertexOf.size());
    for (uint32_t f : around[x]) {
      const float len = glm::length(faceNormal[f]);
      const Vec3 n = len > 0 ? faceNormal[f] / len : Vec3(0.0f);
      // A degenerate face (no direction) joins the first group; a group of such faces alone
      // takes the next face that has one.
      auto joins = [&](const Vec3& direction) {
        const float d = glm::length(direction);
        return len == 0 || d == 0 || glm::dot(direction / d, n) >= kCreaseCos;
      };
      size_t g = 0;
      while (g < groups.size() && !joins(groups[g])) ++g;
      if (g == groups.size()) {
        groups.push_back(Vec3(0.0f));
        out.vertexOf.push_back(x);
      }
      groups[g] += n;
      const auto& v = out.tris[f];
      out.corner[f][size_t(std::find(v.begin(), v.end(), x) - v.begin())] = first + uint32_t(g);
    }
  }
  return out;
}

/// Each group's normal: the area-weighted mean of its faces' normals (the sum of their
/// cross products), unit.
std::vector<Vec3> groupNormals(const GroupedSurface& s) {
  std::vector<Vec3> normals(s.vertexOf.size(), Vec3(0.0f));
  for (size_t f = 0; f < s.tris.size(); ++f) {
    const Vec3 n = faceCross(s, f);
    for (uint32_t g : s.corner[f]) normals[g] += n;
  }
  for (Vec3& n : normals) n = glm::length(n) > 0 ? glm::normalize(n) : Vec3(0, 1, 0);
  return normals;
}

/// Fills s.groupColor and s.groupSurface: where two materials meet (polish's shiny bronze
/// among plain bronze: one material per tetrahedron, a step along triangle edges) colour and
/// shine fade across one ring of triangles instead of outlining them; a group among faces
/// of one material keeps that material's values.
void blendGroups(GroupedSurface& s, const std::vector<solids::Material>& materials) {
  const size_t groups = s.vertexOf.size();
  std::vector<Vec3> color(groups, Vec3(0.0f)), surface(groups, Vec3(0.0f));
  std::vector<float> area(groups, 0.0f);
  std::vector<int> firstFace(groups, -1);
  for (size_t f = 0; f < s.tris.size(); ++f) {
    const solids::Material& m = materials[s.materials[f]];
    const float a = 0.5f * glm::length(faceCross(s, f));
    for (uint32_t g : s.corner[f]) {
      color[g] += a * m.color;
      surface[g] += a * Vec3(m.roughness, m.specular, 0.0f);
      area[g] += a;
      if (firstFace[g] < 0) firstFace[g] = int(f);
    }
  }
  s.groupColor.resize(groups);
  s.groupSurface.resize(groups);
  for (size_t g = 0; g < groups; ++g) {
    // A group of degenerate faces only takes its first face's material.
    const solids::Material& first = materials[s.materials[size_t(std::max(firstFace[g], 0))]];
    s.groupColor[g] = area[g] > 0 ? color[g] / area[g] : first.color;
    s.groupSurface[g] = area[g] > 0 ? surface[g] / area[g] : Vec3(first.roughness, first.specular, 0.0f);
  }
}

/// The edges between two smooth groups: an edge whose two faces' corners lie in different
/// groups at either end (a cut-away's rim, a box's edges). Each once, in face order.
std::vector<std::array<uint32_t, 2>> creaseEdges(const GroupedSurface& s) {
  auto key = [](uint32_t a, uint32_t b) { return (uint64_t(a) << 32) | b; };
  std::unordered_map<uint64_t, std::array<uint32_t, 2>> groups;  // directed edge a -> b: its face's groups at a, b
  for (size_t f = 0; f < s.tris.size(); ++f)
    for (size_t k = 0; k < 3; ++k) {
      const size_t j = (k + 1) % 3;
      groups.emplace(key(s.tris[f][k], s.tris[f][j]), std::array{s.corner[f][k], s.corner[f][j]});
    }
  std::vector<std::array<uint32_t, 2>> out;
  for (size_t f = 0; f < s.tris.size(); ++f)
    for (size_t k = 0; k < 3; ++k) {
      const size_t j = (k + 1) % 3;
      const uint32_t a = s.tris[f][k], b = s.tris[f][j];
      const auto twin = groups.find(key(b, a));  // none: a boundary edge, which OpenSubdiv keeps sharp
      if (a < b && twin != groups.end() && (twin->second[1] != s.corner[f][k] || twin->second[0] != s.corner[f][j]))
        out.push_back({a, b});
    }
  return out;
}

/// `levels` of Loop subdivision of s with creases (OpenSubdiv's Loop scheme through
/// organisms::Subdivision): every triangle into four, each level; the edges between smooth
/// groups (creaseEdges) are infinitely sharp creases refined as the curve's cubic B-spline,
/// and a vertex where three or more creases meet stays, so a box keeps its edges straight,
/// its faces flat and its corners. The groups are the subdivision's face-varying channel
/// (an edge point on a crease gets one per side); their colour and surface ride it
/// linearly, and tints ride the vertices linearly (a vertex keeps its value, an edge point
/// takes its ends' mean); each face keeps its material. Sequential; cost O(4^levels T).
void subdivide(GroupedSurface& s, int levels) {
  if (levels == 0 || s.tris.empty()) return;
  organisms::ControlMesh control;
  organisms::SubdivisionOptions options;
  options.scheme = organisms::SubdivisionScheme::Loop;
  for (const DVec3& p : s.positions) control.positions.push_back(Vec3(p));
  control.faceSizes.assign(s.tris.size(), 3);
  for (size_t f = 0; f < s.tris.size(); ++f)
    for (size_t k = 0; k < 3; ++k) {
      control.faceVertices.push_back(s.tris[f][k]);
      options.faceVaryingIndices.push_back(s.corner[f][k]);
    }
  options.faceVaryingCount = s.vertexOf.size();
  options.creases = creaseEdges(s);
  const organisms::Subdivision sub(control, levels, options);
  std::vector<Vec3> positions = std::move(control.positions);
  // Level by level: values of level l - 1 -> level l, Vec3 or Vec4 each (empty: none).
  auto refine = [&sub](auto& values, organisms::Primvar kind, int l) {
    using T = typename std::decay_t<decltype(values)>::value_type;
    constexpr size_t width = sizeof(T) / sizeof(float);
    if (values.empty()) return;
    std::vector<T> fine(kind == organisms::Primvar::FaceVarying ? sub.topology(l).faceVaryingCount : sub.vertexCount(l));
    sub.interpolate(l, kind, {&values[0].x, width * values.size()}, {&fine[0].x, width * fine.size()}, width);
    values = std::move(fine);
  };
  for (int l = 1; l <= levels; ++l) {
    refine(positions, organisms::Primvar::Vertex, l);
    refine(s.tints, organisms::Primvar::Varying, l);
    refine(s.groupColor, organisms::Primvar::FaceVarying, l);
    refine(s.groupSurface, organisms::Primvar::FaceVarying, l);
    std::vector<uint16_t> materials(sub.topology(l).faceCount());
    for (uint32_t f = 0; f < materials.size(); ++f) materials[f] = s.materials[sub.parentFace(l, f)];
    s.materials = std::move(materials);
  }
  const organisms::LevelTopology& fine = sub.topology(levels);
  s.positions.assign(positions.begin(), positions.end());
  s.tris.resize(fine.faceCount());
  s.corner.resize(fine.faceCount());
  s.vertexOf.assign(fine.faceVaryingCount, 0);
  for (size_t i = 0; i < fine.faceVertices.size(); ++i) {
    s.tris[i / 3][i % 3] = fine.faceVertices[i];
    s.corner[i / 3][i % 3] = fine.faceVaryingIndices[i];
    s.vertexOf[fine.faceVaryingIndices[i]] = fine.faceVertices[i];
  }
}

}  // namespace

void smoothSurfaceNormals(const std::vector<std::array<uint32_t, 3>>& corner, const std::vector<float>& area,
                          std::vector<Vec3>& normals, int rounds) {
  for (int r = 0; r < rounds; ++r) {
    std::vector<Vec3> sum(normals.size(), Vec3(0.0f));
    for (size_t f = 0; f < corner.size(); ++f) {
      const auto& c = corner[f];
      const Vec3 mean = area[f] * (normals[c[0]] + normals[c[1]] + normals[c[2]]);
      for (uint32_t g : c) sum[g] += mean;
    }
    for (size_t g = 0; g < normals.size(); ++g)
      if (glm::length(sum[g]) > 0) normals[g] = glm::normalize(sum[g]);
  }
}

VisibleParts visibleParts(const TetMesh& mesh, const std::vector<solids::Material>* materials, const VisibleMeshOptions& options) {
  const bool tinted = materials && !mesh.tints.empty() && mesh.tints.size() == mesh.positions.size();
  // The visible interface with pieces that touch along an edge or at a vertex only pulled
  // apart (solids::boundarySurface): every part together is a closed 2-manifold.
  GroupedSurface s = groupedSurface(solids::boundarySurface(mesh), mesh, tinted);
  if (materials && !s.tris.empty()) blendGroups(s, *materials);
  int levels = 0;
  while (levels < options.subdivisions && (s.tris.size() << (2 * (levels + 1))) <= kMaxSubdividedTriangles) ++levels;
  subdivide(s, levels);
  std::vector<Vec3> normals = groupNormals(s);
  std::vector<float> area(s.tris.size());
  for (size_t f = 0; f < s.tris.size(); ++f) area[f] = 0.5f * glm::length(faceCross(s, f));
  smoothSurfaceNormals(s.corner, area, normals, options.normalRounds);
  std::map<uint16_t, std::vector<size_t>> byMaterial;
  for (size_t i = 0; i < s.tris.size(); ++i) byMaterial[s.materials[i]].push_back(i);
  VisibleParts out;
  constexpr uint32_t kNone = ~0u;
  std::vector<uint32_t> outputOf(normals.size(), kNone);  // group -> vertex of this part
  for (const auto& [mat, list] : byMaterial) {
    Mesh m;
    std::vector<Vec3> surfaces;
    for (size_t f : list) {
      std::array<uint32_t, 3> c;
      for (int k = 0; k < 3; ++k) {
        const uint32_t g = s.corner[f][k];
        if (outputOf[g] == kNone) {
          const uint32_t x = s.vertexOf[g];
          outputOf[g] = uint32_t(m.positions.size());
          m.positions.push_back(Vec3(s.positions[x]));
          m.normals.push_back(normals[g]);
          if (tinted) m.colors.push_back(glm::mix(s.groupColor[g], Vec3(s.tints[x]), std::clamp(s.tints[x].w, 0.0f, 1.0f)));
          if (materials) surfaces.push_back(s.groupSurface[g]);
        }
        c[k] = outputOf[g];
      }
      m.triangles.push_back({c[0], c[1], c[2]});
    }
    for (size_t f : list)
      for (uint32_t g : s.corner[f]) outputOf[g] = kNone;
    out.materials.push_back(mat);
    out.meshes.push_back(std::move(m));
    if (materials) out.surfaces.push_back(std::move(surfaces));
  }
  return out;
}

std::vector<Mesh> visibleMeshes(const TetMesh& mesh, std::vector<uint16_t>* partMaterials,
                                const std::vector<solids::Material>* materials, int normalRounds) {
  VisibleParts parts = visibleParts(mesh, materials, VisibleMeshOptions{normalRounds, 0});
  if (partMaterials) *partMaterials = std::move(parts.materials);
  return std::move(parts.meshes);
}

std::shared_ptr<const KindSpec> readSolidSpec(MapReader& top, Species& species, DiagnosticList& diags) {
  auto spec = std::make_shared<SolidSpec>();
  SolidReader reader(diags, *spec, species.policy);
  if (auto m = top.section({"materials", "Materials of this file by name (beside the built-in ones), each a colour or a choice among materials by an expression (docs/SOLIDS.md)."})) reader.readMaterials(*m);
  std::optional<YNode> section = top.section({"solid", "The layered solid: a volume (distance field and layers), more volumes, precedence and operations (docs/SOLIDS.md)."});
  if (!section) {
    if (!top.has("solid")) top.node().error(diags, "missing required key 'solid' in species file");
    return nullptr;
  }
  spec->loc = section->loc();
  reader.readSolid(*section);
  if (diags.hasErrors()) return nullptr;
  return spec;
}

std::string SolidSpec::checkSummary(const Species& species) const {
  char buf[256];
  std::snprintf(buf, sizeof buf, " '%s', %zu volume%s, grid %dx%dx%d of cell %g", species.name.c_str(), solid.volumes.size(),
                solid.volumes.size() == 1 ? "" : "s", grid.cells[0], grid.cells[1], grid.cells[2], grid.cell);
  return buf;
}

std::unique_ptr<KindModel> SolidSpec::makeModel(const Species&, const ModelOptions&) const {
  return std::make_unique<SolidModel>(*this);
}

}  // namespace sprig
