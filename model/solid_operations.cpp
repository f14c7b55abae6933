#include "model/solid_operations.h"

#include <stdexcept>

#include "core/progress.h"

namespace sprig {

namespace {

const std::vector<std::string> kTools = {"hammer", "displace"};

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
  return o;
}

solids::DisplaceOptions readDisplace(MapReader& m, const YNode& node, solids::MaterialTable& materials, DiagnosticList& diags) {
  solids::DisplaceOptions o;
  if (!m.has("moving")) node.error(diags, "missing required key 'moving' in displace (the materials whose vertices move)");
  o.moving = materialList(m, "moving", materials, diags);
  o.offset = dvec(m.vec3("offset", Vec3(o.offset)));
  o.up = dvec(m.vec3("up", Vec3(o.up)));
  o.steps = int(m.integer("steps", o.steps, 1, 1000));
  return o;
}

}  // namespace

std::vector<SolidOperation> readSolidOperations(const YNode& list, solids::MaterialTable& materials, DiagnosticList& diags) {
  std::vector<SolidOperation> out;
  if (!list.isSequence()) {
    list.error(diags, "'operations' must be a sequence of tools (hammer, displace)");
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
    else op.options = readDisplace(m, one->second, materials, diags);
    m.finish();
    out.push_back(std::move(op));
  }
  return out;
}

void applySolidOperations(solids::TetMesh& mesh, const std::vector<solids::Material>& materials,
                          const std::vector<SolidOperation>& operations) {
  for (const SolidOperation& op : operations) {
    try {
      if (const auto* h = std::get_if<solids::HammerOptions>(&op.options)) solids::hammer(mesh, materials, *h);
      else solids::displace(mesh, materials, std::get<solids::DisplaceOptions>(op.options));
    } catch (const std::exception& e) {
      if (dynamic_cast<const Cancelled*>(&e)) throw;
      std::string message = e.what();
      if (message.rfind(op.tool + ": ", 0) != 0) message = op.tool + ": " + message;
      throw InputError(op.loc, message, op.sourceLine);
    }
  }
  // Vertices the blows left unused would be written out as loose nodes.
  if (!operations.empty()) solids::compactVertices(mesh);
}

}  // namespace sprig
