#include "app/species_tree.h"

#include "textures/procedural.h"

namespace sprig {

namespace {

using organisms::BranchSelector;
using organisms::TreeOptions;

constexpr double kInf = std::numeric_limits<double>::infinity();

std::vector<int> readInts(MapReader& m, std::string_view key, int64_t min, int64_t max) {
  std::vector<int> out;
  std::string what("'");
  what.append(key).append("' element");
  for (const YNode& item : m.sequence(key))
    if (auto v = item.asInteger(m.diagnostics(), what, min, max))
      out.push_back(static_cast<int>(*v));
  return out;
}

void readSelector(MapReader& m, BranchSelector& s) {
  if (m.has("orders")) s.orders = readInts(m, "orders", 0, 1000);
  if (m.has("internodes")) s.internodes = readInts(m, "internodes", 0, std::numeric_limits<int32_t>::max());
  s.belowHeight = m.number("below_height", s.belowHeight);
  s.aboveHeight = m.number("above_height", s.aboveHeight);
  s.probability = m.number("probability", s.probability, 0.0, 1.0);
}

}  // namespace

TreeOptions readTreeOptions(const YNode& section, DiagnosticList& diags, const TreeOptions& defaults) {
  TreeOptions o = defaults;
  MapReader m(section, diags, "tree");
  o.junctions = m.choice("junctions", o.junctions == organisms::JunctionModel::Pcm ? "pcm" : "smooth",
                         {"smooth", "pcm"}) == "pcm"
                    ? organisms::JunctionModel::Pcm
                    : organisms::JunctionModel::Smooth;
  o.deltaA = m.number("delta_a", o.deltaA, 0.0, 10.0);
  o.deltaAMulti = m.number("delta_a_multi", o.deltaAMulti, 0.0, 10.0);
  o.basalOffset = m.boolean("basal_offset", o.basalOffset);
  o.branchOffset = m.boolean("branch_offset", o.branchOffset);
  o.pcmWidth = m.number("pcm_width", o.pcmWidth, 1e-3, 0.5);
  o.pcmBulge = m.number("pcm_bulge", o.pcmBulge, 0.0, 4.0);
  o.softKernel = m.choice("kernel", o.softKernel ? "soft" : "wyvill", {"wyvill", "soft"}) == "soft";
  o.controlledBlend = m.boolean("controlled_blend", o.controlledBlend);
  o.tips = m.choice("tips", o.tips == organisms::TipStyle::Taper ? "taper" : "hemisphere",
                    {"taper", "hemisphere"}) == "taper"
               ? organisms::TipStyle::Taper
               : organisms::TipStyle::Hemisphere;
  o.tipTaper = m.number("tip_taper", o.tipTaper, 0.01, 1.0);
  o.radiusScale = m.number("radius_scale", o.radiusScale, 1e-6, 1e6);
  o.minRadius = m.number("min_radius", o.minRadius, 0.0, 1e6);
  o.seed = static_cast<uint64_t>(m.integer("seed", static_cast<int64_t>(o.seed), 0));

  if (auto s = m.section("prune")) {
    MapReader p(*s, diags, "prune");
    o.prune.fromGrammar = p.boolean("from_grammar", o.prune.fromGrammar);
    o.prune.cutFraction = p.number("cut_fraction", o.prune.cutFraction, 0.0, 1.0);
    o.prune.minCutDistance = p.number("min_cut_distance", o.prune.minCutDistance, 0.0, 100.0);
    readSelector(p, o.prune.select);
    p.finish();
  }
  if (auto s = m.section("scars")) {
    MapReader p(*s, diags, "scars");
    o.scars.stubLength = p.number("stub_length", o.scars.stubLength, 0.01, 100.0);
    o.scars.stubRadius = p.number("stub_radius", o.scars.stubRadius, 0.01, 10.0);
    o.scars.negativeRadius = p.number("negative_radius", o.scars.negativeRadius, 0.0, 10.0);
    o.scars.negativeWeight = p.number("negative_weight", o.scars.negativeWeight, 0.0, 10.0);
    readSelector(p, o.scars.select);
    p.finish();
  }
  if (auto s = m.section("bends")) {
    MapReader p(*s, diags, "bends");
    o.bends.angleDeg = p.number("angle", o.bends.angleDeg, 0.0, 80.0);
    o.bends.orderScale = p.number("order_scale", o.bends.orderScale, 0.0, 10.0);
    o.bends.randomness = p.number("randomness", o.bends.randomness, 0.0, 1.0);
    o.bends.minBranchAngleDeg = p.number("min_branch_angle", o.bends.minBranchAngleDeg, 0.0, 90.0);
    o.bends.trunk = p.boolean("trunk", o.bends.trunk);
    p.finish();
  }
  if (auto s = m.section("bark")) {
    MapReader p(*s, diags, "bark");
    o.bark.enabled = p.boolean("enabled", o.bark.enabled);
    o.bark.texture = static_cast<int>(p.integer("texture", o.bark.texture, 0, 65535));
    o.bark.uScale = p.number("u_scale", o.bark.uScale, -kInf, kInf);
    o.bark.vScale = p.number("v_scale", o.bark.vScale, -kInf, kInf);
    p.finish();
  }
  if (auto s = m.section("leaves")) {
    MapReader p(*s, diags, "leaves");
    o.leaves.enabled = p.boolean("enabled", o.leaves.enabled);
    o.leaves.scale = p.number("scale", o.leaves.scale, 0.0, 1e6);
    o.leaves.material = static_cast<uint32_t>(p.integer("material", o.leaves.material, 0, 65535));
    p.finish();
  }
  m.finish();
  return o;
}

TreeOptions parseTreeOptions(std::string text, const std::string& displayPath) {
  DiagnosticList diags;
  auto file = YamlFile::parse(std::move(text), displayPath, diags);
  TreeOptions o;
  if (file) o = readTreeOptions(file->rootNode(), diags);
  diags.throwIfErrors();
  return o;
}

TreeModel buildTreeModel(const Species& species, const lsystem::Skeleton& skeleton) {
  TreeModel m;
  if (species.treeSection) {
    DiagnosticList diags;
    m.options = readTreeOptions(*species.treeSection, diags);
    diags.throwIfErrors();
  }
  m.blob = organisms::buildTreeBlob(skeleton, m.options);
  m.compiled = blobtree::compile(m.blob.tree, m.blob.root);
  m.leaves = organisms::buildLeafMesh(skeleton, m.options);
  return m;
}

uint32_t addTreeToScene(render::Scene& scene, const TreeModel& model, const SpeciesRender& look,
                        const render::ImplicitOptions& implicit, const blobtree::PolygonizeResult* mesh) {
  if (model.options.bark.enabled) {
    textures::BarkOptions bo;
    bo.seed = model.options.seed;
    bo.ridgeColor = look.style.wood.baseColor;
    bo.furrowColor = look.style.wood.baseColor * 0.3f;
    auto bark = std::make_shared<textures::BarkTexture>(bo);
    scene.addTexture([bark](Vec2 uv, const Vec3&) { return bark->color(uv); });
  }
  const uint32_t wood = scene.addMaterial(look.style.wood);
  const uint32_t id = mesh ? scene.addPolygonized(*mesh, wood) : scene.addImplicit(model.compiled, wood, implicit);
  if (model.leaves.triangleCount() > 0) {
    Mesh leaves = model.leaves;
    leaves.materials.clear();  // one leaf material; the vertex colors carry each leaf's tint
    scene.addMesh(leaves, scene.addMaterial(look.style.leaf));
  }
  return id;
}

}  // namespace sprig
