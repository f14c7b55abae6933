#include "model/solid_operations.h"

#include <limits>
#include <stdexcept>

#include "core/progress.h"

namespace sprig {

namespace {

const std::vector<std::string> kTools = {"hammer", "displace", "polish", "dirt", "wash", "erode", "lichen"};

DVec3 dvec(const Vec3& v) { return DVec3(v); }

/// Concrete material ids for the names listed under `key` of m.
std::vector<uint16_t> materialList(MapReader& m, const std::string& key, solids::MaterialTable& materials,
                                   DiagnosticList& diags) {
  std::vector<uint16_t> ids;
  for (const YNode& item : m.sequence(key)) {
    std::optional<std::string> name = item.asString(diags, "'" + key + "' entry");
    if (!name) continue;
    bool procedural = false;
    for (const auto& p : materials.procedural) procedural |= p.name == *name;
    if (procedural) {
      item.error(diags, "material " + sprig::quoted(*name) + " is procedural: name the concrete materials it chooses among");
      continue;
    }
    if (auto id = materials.concrete(*name)) {
      ids.push_back(uint16_t(*id));
      continue;
    }
    std::vector<std::string> all;
    for (const auto& mat : materials.materials) all.push_back(mat.name);
    for (const auto& mat : solids::builtinMaterials()) all.push_back(mat.name);
    item.error(diags, "unknown material " + sprig::quoted(*name) + didYouMean(*name, all));
  }
  return ids;
}

solids::HammerOptions readHammer(MapReader& m, solids::MaterialTable& materials, DiagnosticList& diags) {
  solids::HammerOptions o;
  o.position = dvec(m.vec3("position", Vec3(o.position)));
  o.orientation = dvec(m.vec3("orientation", Vec3(o.orientation)));
  if (o.orientation == DVec3(0.0))
    if (auto n = m.keyNode("orientation")) n->error(diags, "'orientation' must not be zero");
  o.magnitude = m.number("magnitude", o.magnitude, 0.0, 1e15);
  o.size = m.number("size", o.size, 1e-9, 1e9);
  o.affects = materialList(m, "affects", materials, diags);
  o.up = dvec(m.vec3("up", Vec3(o.up)));
  o.criterion = m.choice("criterion", "max_principal", {"max_principal", "von_mises"}) == "von_mises"
                    ? solids::FractureCriterion::VonMises
                    : solids::FractureCriterion::MaxPrincipal;
  o.rounds = int(m.integer("rounds", o.rounds, 1, 1000));
  o.manifold = m.boolean("manifold", o.manifold);
  return o;
}

solids::DisplaceOptions readDisplace(MapReader& m, const YNode& node, solids::MaterialTable& materials, DiagnosticList& diags) {
  solids::DisplaceOptions o;
  m.markRequired("moving");
  if (!m.has("moving")) node.error(diags, "missing required key 'moving' in displace (the materials whose vertices move)");
  o.moving = materialList(m, "moving", materials, diags);
  o.offset = dvec(m.vec3("offset", Vec3(o.offset)));
  o.up = dvec(m.vec3("up", Vec3(o.up)));
  o.steps = int(m.integer("steps", o.steps, 1, 1000));
  o.stiffening = m.number("stiffening", o.stiffening, 0.0, 10.0);
  o.maxStiffening = m.number("max_stiffening", o.maxStiffening, 1.0, 1e9);
  o.stiffenBelow = m.number("stiffen_below", o.stiffenBelow, 0.0, 1.0);
  o.minStepVolumeRatio = m.number("min_step_volume_ratio", o.minStepVolumeRatio, 0.01, 0.99);
  o.halvings = int(m.integer("halvings", o.halvings, 0, 30));
  return o;
}

/// The id of the one concrete material named under key, or -1 (absent: def, which may be empty).
int oneMaterial(MapReader& m, const std::string& key, const std::string& def, solids::MaterialTable& materials,
                DiagnosticList& diags) {
  std::optional<YNode> node = m.get(key);
  std::string name = def;
  if (node) {
    std::optional<std::string> s = node->asString(diags, "'" + key + "'");
    if (!s) return -1;
    name = *s;
  }
  if (name.empty()) return -1;
  if (auto id = materials.concrete(name)) return *id;
  std::vector<std::string> all;
  for (const auto& mat : materials.materials) all.push_back(mat.name);
  for (const auto& mat : solids::builtinMaterials()) all.push_back(mat.name);
  if (node) node->error(diags, "unknown material " + sprig::quoted(name) + didYouMean(name, all));
  return -1;
}

solids::PolishOptions readPolish(MapReader& m, solids::MaterialTable& materials, DiagnosticList& diags) {
  solids::PolishOptions o;
  o.position = dvec(m.vec3("position", Vec3(o.position)));
  o.size = m.number("size", o.size, 1e-9, 1e9);
  if (m.has("affects")) o.affects = materialList(m, "affects", materials, diags);
  else o.affects = {uint16_t(*materials.concrete("fired_clay"))};
  o.shiny = oneMaterial(m, "shiny", "shiny_bronze", materials, diags);
  o.shines = materialList(m, "shines", materials, diags);
  o.up = dvec(m.vec3("up", Vec3(o.up)));
  return o;
}

solids::DirtOptions readDirt(MapReader& m, solids::MaterialTable& materials, DiagnosticList& diags) {
  solids::DirtOptions o;
  o.color = m.color("color", o.color);
  o.amount = m.number("amount", o.amount, 0.0, 1.0);
  o.affects = materialList(m, "affects", materials, diags);
  return o;
}

solids::ParticleOptions readParticles(MapReader& m, solids::ParticleTool tool, solids::MaterialTable& materials,
                                      DiagnosticList& diags) {
  solids::ParticleOptions o = solids::particleDefaults(tool);
  o.particles = int(m.integer("particles", o.particles, 0, 100000000));
  o.life = m.number("life", o.life, 1e-9, 1e6);
  o.speed = m.number("speed", o.speed, 1e-9, 1e6);
  o.step = m.number("step", o.step, 0.0, 1e6);
  o.fallingAngleDeg = m.number("falling_angle", o.fallingAngleDeg, 0.0, 180.0);
  o.radius = m.number("radius", o.radius, 1e-9, 1e6);
  if (tool != solids::ParticleTool::Erode) o.strength = m.number("strength", o.strength, 0.0, 1.0);
  if (tool == solids::ParticleTool::Wash) {
    o.attraction = m.number("attraction", o.attraction, 0.0, 1e6);
    o.meander = m.number("meander", o.meander, 0.0, 1e6);
    o.meanderScale = m.number("meander_scale", o.meanderScale, 1e-6, 1e6);
  }
  if (tool == solids::ParticleTool::Lichen) {
    o.color = m.color("color", o.color);
    o.topAngleDeg = m.number("top_angle", o.topAngleDeg, 0.0, 90.0);
  }
  o.affects = materialList(m, "affects", materials, diags);
  o.seed = uint64_t(m.integer("seed", 0, 0, std::numeric_limits<int64_t>::max()));
  o.up = dvec(m.vec3("up", Vec3(o.up)));
  if (o.up == DVec3(0.0))
    if (auto n = m.keyNode("up")) n->error(diags, "'up' must not be zero");
  return o;
}

}  // namespace

std::vector<SolidOperation> readSolidOperations(const YNode& list, solids::MaterialTable& materials, DiagnosticList& diags) {
  std::vector<SolidOperation> out;
  if (!list.isSequence()) {
    list.error(diags, "'operations' must be a sequence of tools (hammer, displace, polish, dirt, wash, erode, lichen)");
    return out;
  }
  for (const YNode& item : list.items()) {
    auto one = singleKey(item, diags, "operation", kTools);
    if (!one) continue;
    SolidOperation op;
    op.tool = one->first.scalar();
    op.loc = one->first.loc();
    op.sourceLine = item.file().sourceLine(op.loc.line);
    MapReader m(one->second, diags, op.tool);
    if (op.tool == "hammer") op.options = readHammer(m, materials, diags);
    else if (op.tool == "displace") op.options = readDisplace(m, one->second, materials, diags);
    else if (op.tool == "polish") op.options = readPolish(m, materials, diags);
    else if (op.tool == "dirt") op.options = readDirt(m, materials, diags);
    else if (op.tool == "wash") op.options = readParticles(m, solids::ParticleTool::Wash, materials, diags);
    else if (op.tool == "erode") op.options = readParticles(m, solids::ParticleTool::Erode, materials, diags);
    else op.options = readParticles(m, solids::ParticleTool::Lichen, materials, diags);
    m.finish();
    out.push_back(std::move(op));
  }
  return out;
}

void applySolidOperation(solids::TetMesh& mesh, const std::vector<solids::Material>& materials, const SolidOperation& op) {
  try {
    if (const auto* h = std::get_if<solids::HammerOptions>(&op.options)) solids::hammer(mesh, materials, *h);
    else if (const auto* d = std::get_if<solids::DisplaceOptions>(&op.options)) solids::displace(mesh, materials, *d);
    else if (const auto* p = std::get_if<solids::PolishOptions>(&op.options)) solids::polish(mesh, materials, *p);
    else if (const auto* r = std::get_if<solids::DirtOptions>(&op.options)) solids::dirt(mesh, materials, *r);
    else solids::runParticles(mesh, materials, std::get<solids::ParticleOptions>(op.options));
  } catch (const std::exception& e) {
    if (dynamic_cast<const Cancelled*>(&e)) throw;
    std::string message = e.what();
    if (message.rfind(op.tool + ": ", 0) != 0) message = op.tool + ": " + message;
    throw InputError(op.loc, message, op.sourceLine);
  }
}

void applySolidOperations(solids::TetMesh& mesh, const std::vector<solids::Material>& materials,
                          const std::vector<SolidOperation>& operations) {
  for (const SolidOperation& op : operations) applySolidOperation(mesh, materials, op);
  // Vertices the blows left unused would be written out as loose nodes.
  if (!operations.empty()) solids::compactVertices(mesh);
}

}  // namespace sprig
