#include "model/solid_operations.h"

#include <limits>
#include <map>
#include <stdexcept>
#include <string_view>

#include "core/progress.h"

namespace sprig {

namespace {

const std::vector<std::string> kTools = {"hammer", "displace", "polish", "dirt", "wash", "erode", "lichen"};

/// What each tool does (`sprig schema`'s text for its key).
std::string_view toolHelp(std::string_view tool) {
  static const HelpTable kHelp = {
      {"hammer", "A blow (§3.1): a Gaussian sphere of force; the FEM is solved and over-stressed tetrahedra break, loose pieces fall."},
      {"displace", "Push materials (§5.2): the `moving` materials' vertices move by `offset`, the rest follows by linear elasticity."},
      {"polish", "The paper's POLISH (§5.1): subtract a sphere from the `affects` materials and blend those near it toward `shiny`."},
      {"dirt", "An even layer of dirt (§3.2): every visible vertex blends toward `color` by `amount`."},
      {"wash", "REMOVE_DIRT (§3.2, §5.3): falling water particles wash the tint off along their paths."},
      {"erode", "Falling particles (§5.3) remove a sphere of `radius` where each one's life ends."},
      {"lichen", "Lichen (§5.3): particles with minimal motion blend upward-facing surface toward `color`."}};
  return helpIn(kHelp, tool);
}

DVec3 dvec(const Vec3& v) { return DVec3(v); }

/// Concrete material ids for the names listed under `key` of m.
std::vector<uint16_t> materialList(MapReader& m, Key key, solids::MaterialTable& materials, DiagnosticList& diags) {
  std::vector<uint16_t> ids;
  for (const YNode& item : m.sequence(key)) {
    std::optional<std::string> name = item.asString(diags, "'" + std::string(key.name) + "' entry");
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
  o.position = dvec(m.vec3({"position", "Centre of the blow's Gaussian sphere of force, m."}, Vec3(o.position)));
  o.orientation = dvec(m.vec3({"orientation", "Direction of the force (normalized; not zero)."}, Vec3(o.orientation)));
  if (o.orientation == DVec3(0.0))
    if (auto n = m.keyNode("orientation")) n->error(diags, "'orientation' must not be zero");
  o.magnitude = m.number({"magnitude", "Total force of the blow, N, shared among the loaded vertices."}, o.magnitude, 0.0, 1e15);
  o.size = m.number({"size", "Radius of the Gaussian sphere of force, m: weight exp(−(d/size)²), none beyond 3·size."}, o.size, 1e-9, 1e9);
  o.affects = materialList(m, {"affects", "Material names that may break; the others are held (default: every material)."}, materials, diags);
  o.up = dvec(m.vec3({"up", "Up: the ground that holds the model when nothing else does lies at its lowest 2% along it."}, Vec3(o.up)));
  o.criterion = m.choice({"criterion", "Stress that breaks a tetrahedron when above its material's strength: the largest principal stress or von Mises."}, "max_principal", {"max_principal", "von_mises"}) == "von_mises"
                    ? solids::FractureCriterion::VonMises
                    : solids::FractureCriterion::MaxPrincipal;
  o.rounds = int(m.integer({"rounds", "Solves of the same blow on what is left, until nothing more breaks (cracks run)."}, o.rounds, 1, 1000));
  o.manifold = m.boolean({"manifold", "Mend the broken surface where pieces touch along an edge or at a vertex only."}, o.manifold);
  return o;
}

solids::DisplaceOptions readDisplace(MapReader& m, const YNode& node, solids::MaterialTable& materials, DiagnosticList& diags) {
  solids::DisplaceOptions o;
  m.markRequired("moving");
  if (!m.has("moving")) node.error(diags, "missing required key 'moving' in displace (the materials whose vertices move)");
  o.moving = materialList(m, {"moving", "Material names whose vertices move by `offset`; required."}, materials, diags);
  o.offset = dvec(m.vec3({"offset", "Displacement prescribed to the moving vertices, m."}, Vec3(o.offset)));
  o.up = dvec(m.vec3({"up", "Up: the ground held at zero is the lowest 2% of the model's height along it."}, Vec3(o.up)));
  o.steps = int(m.integer({"steps", "The offset is applied in at least this many equal increments, each solved on the mesh the last left."}, o.steps, 1, 1000));
  o.stiffening = m.number({"stiffening", "Exponent of the Jacobian stiffening: a tetrahedron crushed to volume fraction r is r^-stiffening stiffer (0 = off)."}, o.stiffening, 0.0, 10.0);
  o.maxStiffening = m.number({"max_stiffening", "Cap of the stiffening factor."}, o.maxStiffening, 1.0, 1e9);
  o.stiffenBelow = m.number({"stiffen_below", "Tetrahedra of mean ratio quality below this are stiffened too (0 = off)."}, o.stiffenBelow, 0.0, 1.0);
  o.minStepVolumeRatio = m.number({"min_step_volume_ratio", "An increment leaving a tetrahedron no more than this fraction of its volume is undone and halved."}, o.minStepVolumeRatio, 0.01, 0.99);
  o.halvings = int(m.integer({"halvings", "Halvings of an increment before displace gives up with an error (0: never halve)."}, o.halvings, 0, 30));
  return o;
}

/// The id of the one concrete material named under key, or -1 (absent: def, which may be empty).
int oneMaterial(MapReader& m, Key key, const std::string& def, solids::MaterialTable& materials, DiagnosticList& diags) {
  std::optional<YNode> node = m.get(key);
  std::string name = def;
  if (node) {
    std::optional<std::string> s = node->asString(diags, "'" + std::string(key.name) + "'");
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
  o.position = dvec(m.vec3({"position", "Centre of the polishing sphere, m."}, Vec3(o.position)));
  o.size = m.number({"size", "Radius of the polishing sphere, m."}, o.size, 1e-9, 1e9);
  if (m.has("affects")) o.affects = materialList(m, {"affects", "Material names subtracted inside the sphere (default: [fired_clay])."}, materials, diags);
  else o.affects = {uint16_t(*materials.concrete("fired_clay"))};
  o.shiny = oneMaterial(m, {"shiny", "The material blended in near the centre (default: shiny_bronze)."}, "shiny_bronze", materials, diags);
  o.shines = materialList(m, {"shines", "Material names that blend toward `shiny` within the sphere (default: every material not in `affects`)."}, materials, diags);
  o.up = dvec(m.vec3({"up", "Up: the ground that holds loose pieces when nothing else does lies at the model's lowest 2% along it."}, Vec3(o.up)));
  return o;
}

solids::DirtOptions readDirt(MapReader& m, solids::MaterialTable& materials, DiagnosticList& diags) {
  solids::DirtOptions o;
  o.color = m.color({"color", "Colour of the dirt."}, o.color);
  o.amount = m.number({"amount", "How far every visible vertex blends toward `color`."}, o.amount, 0.0, 1.0);
  o.affects = materialList(m, {"affects", "Material names dirtied (default: every material)."}, materials, diags);
  return o;
}

solids::ParticleOptions readParticles(MapReader& m, solids::ParticleTool tool, solids::MaterialTable& materials,
                                      DiagnosticList& diags) {
  solids::ParticleOptions o = solids::particleDefaults(tool);
  o.particles = int(m.integer({"particles", "Particles dropped (the paper's num_particles)."}, o.particles, 0, 100000000));
  o.life = m.number({"life", "Life of a particle, s (the paper's particle_life): at most life·speed/step steps."}, o.life, 1e-9, 1e6);
  o.speed = m.number({"speed", "Speed of a particle along the surface, m/s."}, o.speed, 1e-9, 1e6);
  o.step = m.number({"step", "Length of a particle's step, m (0 = half the radius)."}, o.step, 0.0, 1e6);
  o.fallingAngleDeg = m.number({"falling_angle", "CLINGING's falling angle, degrees from straight down: on a face steeper than this a particle drips."}, o.fallingAngleDeg, 0.0, 180.0);
  o.radius = m.number({"radius", "Radius of a particle's action, m (erode: the sphere removed where its life ends)."}, o.radius, 1e-9, 1e6);
  if (tool != solids::ParticleTool::Erode) o.strength = m.number({"strength", "Blend weight per step at the particle, falling off linearly to `radius`."}, o.strength, 0.0, 1.0);
  if (tool == solids::ParticleTool::Wash) {
    o.attraction = m.number({"attraction", "Rivulets: each step turns toward cleaner surface by this much (0 = the paper's CLINGING)."}, o.attraction, 0.0, 1e6);
    o.meander = m.number({"meander", "Wandering tracks: each step also turns sideways by this much along a smooth seeded noise (0 = off)."}, o.meander, 0.0, 1e6);
    o.meanderScale = m.number({"meander_scale", "Wavelength of the meander noise, about this many m."}, o.meanderScale, 1e-6, 1e6);
  }
  if (tool == solids::ParticleTool::Lichen) {
    o.color = m.color({"color", "Colour of the lichen."}, o.color);
    o.topAngleDeg = m.number({"top_angle", "Lichen grows only on faces within this angle of straight up, degrees."}, o.topAngleDeg, 0.0, 90.0);
  }
  o.affects = materialList(m, {"affects", "Material names this tool acts on (default: every material)."}, materials, diags);
  o.seed = uint64_t(m.integer({"seed", "Seed of the particles' starting points (and of wash's meander noise)."}, 0, 0, std::numeric_limits<int64_t>::max()));
  o.up = dvec(m.vec3({"up", "Up: gravity is −up (not zero)."}, Vec3(o.up)));
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
    describeHelp(one->second, toolHelp(one->first.scalar()));
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
