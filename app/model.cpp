#include "app/model.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "app/animate.h"
#include "app/commands.h"
#include "app/preview.h"
#include "app/species_blob.h"
#include "app/species_shell.h"
#include "app/species_tree.h"
#include "blobtree/compiled.h"
#include "blobtree/polygonize.h"
#include "core/timer.h"
#include "render/camera.h"

namespace sprig {

namespace {

/// Where errors about the species as a whole point: its `kind:` value, else its first line.
SourceLoc speciesLoc(const Species& s) {
  return s.kindNode ? s.kindNode->loc() : SourceLoc{s.file.string(), 1, 1};
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

}  // namespace

const char* geometryModeName(GeometryMode mode) {
  switch (mode) {
    case GeometryMode::Exact: return "exact";
    case GeometryMode::Mesh: return "mesh";
    case GeometryMode::Skeleton: return "skeleton";
  }
  return "?";
}

struct SpeciesModel::Impl {
  // kind: tree
  std::unique_ptr<GrowthSequence> seq;
  // kind: shell
  std::optional<ShellSpecies> shell;
  std::optional<ShellBuild> finalShell;  ///< cached: frames the camera, reused for the final stage
  // kind: blob
  std::optional<BlobSpecies> blob;
  std::optional<blobtree::CompiledBlob> blobCompiled;

  std::optional<Box3> frame;
};

SpeciesModel::SpeciesModel(const Species& species, const lsystem::GrammarOverrides& extra, int lastStep)
    : species_(species), impl_(std::make_unique<Impl>()) {
  switch (species_.kind) {
    case SpeciesKind::Tree:
      impl_->seq = std::make_unique<GrowthSequence>(species_, lastStep, extra);
      break;
    case SpeciesKind::Shell: {
      DiagnosticList diags;
      if (species_.shellSection) impl_->shell = readShellSpecies(*species_.shellSection, diags);
      diags.throwIfErrors();
      if (!impl_->shell) throw InputError(speciesLoc(species_), "the species has no valid 'shell' section");
      break;
    }
    case SpeciesKind::Blob: {
      DiagnosticList diags;
      MapReader top(species_.yaml->rootNode(), diags, "species file");
      // The other keys were checked by loadSpecies; texture images are opened here.
      impl_->blob = readBlobSpecies(top, diags, species_.policy);
      diags.throwIfErrors();
      if (!impl_->blob) throw InputError(speciesLoc(species_), "invalid blob species");
      impl_->blobCompiled = blobtree::compile(impl_->blob->tree, impl_->blob->root);
      break;
    }
    default:
      throw InputError(speciesLoc(species_), std::string("species kind '") + speciesKindName(species_.kind) +
                                                 "' is not supported by this version of Sprig");
  }
}

SpeciesModel::~SpeciesModel() = default;

bool SpeciesModel::hasSurfaceSettings() const {
  return species_.kind != SpeciesKind::Tree || species_.treeSection.has_value();
}

Stage SpeciesModel::finalStage() const {
  Stage s;
  if (impl_->seq) s.step = impl_->seq->lastStage();
  if (impl_->shell) s.age = impl_->shell->params.endDeg();
  return s;
}

Stage SpeciesModel::stageFromIndex(int k) const {
  Stage s = finalStage();
  if (impl_->seq) {
    if (k > impl_->seq->lastStage())
      throw UsageError("stage " + std::to_string(k) + ": the species grows for only " +
                       std::to_string(impl_->seq->lastStage()) + " steps");
    s.step = k;
  } else if (impl_->shell) {
    s.age = std::min(s.age, std::max(1, k) * impl_->shell->params.whorlDeg);
  }
  return s;
}

std::vector<Stage> SpeciesModel::stripStages(int count) const {
  std::vector<Stage> out;
  if (impl_->seq) {
    for (int step : growthStages(species_, impl_->seq->lastStage(), count)) {
      Stage s;
      s.step = step;
      out.push_back(s);
    }
  } else if (impl_->shell) {
    for (double age : shellGrowthStages(*impl_->shell, count)) {
      Stage s;
      s.age = age;
      out.push_back(s);
    }
  } else {
    out.push_back(finalStage());
  }
  return out;
}

std::vector<Stage> SpeciesModel::animationFrames(int framesPerStage, int first, int last) const {
  std::vector<Stage> out;
  framesPerStage = std::max(1, framesPerStage);
  if (impl_->seq) {
    const int lastStep = last < 0 ? impl_->seq->lastStage() : std::min(last, impl_->seq->lastStage());
    for (const GrowthFrame& f : growthFrames(std::clamp(first, 0, lastStep), lastStep, framesPerStage)) {
      Stage s;
      s.step = f.stage;
      s.fraction = f.fraction;
      out.push_back(s);
    }
  } else if (impl_->shell) {
    // From the youngest strip stage to the final age, framesPerStage frames per whorl.
    const double end = finalStage().age;
    const double whorl = impl_->shell->params.whorlDeg;
    const std::vector<double> stages = shellGrowthStages(*impl_->shell, 5);
    const double begin = std::min(end, stages.empty() ? whorl : stages.front());
    const int n = std::max(1, static_cast<int>(std::ceil((end - begin) / whorl * framesPerStage)));
    for (int i = 0; i <= n; ++i) {
      Stage s;
      s.age = begin + (end - begin) * i / n;
      out.push_back(s);
    }
  } else {
    out.push_back(finalStage());
  }
  return out;
}

std::string SpeciesModel::stageName(const Stage& stage) const {
  char buf[64];
  if (impl_->seq) {
    if (stage.fraction < 1.0)
      std::snprintf(buf, sizeof buf, "step %d at %.0f%%", stage.step, stage.fraction * 100.0);
    else
      std::snprintf(buf, sizeof buf, "step %d", stage.step);
    return buf;
  }
  if (impl_->shell) {
    std::snprintf(buf, sizeof buf, "age %.0f deg", stage.age);
    return buf;
  }
  return {};
}

Box3 SpeciesModel::frameBox() {
  if (impl_->frame) return *impl_->frame;
  Box3 box;
  if (impl_->seq) {
    const DBox3& b = impl_->seq->frameBox();
    box = b.empty() ? Box3{Vec3(-0.5f), Vec3(0.5f)} : Box3{Vec3(b.lo), Vec3(b.hi)};
  } else if (impl_->shell) {
    if (!impl_->finalShell) impl_->finalShell = buildShellSpecies(*impl_->shell);
    box = impl_->finalShell->blob.bounds();
  } else {
    // The blob's surface lies inside its support; a scene shrinks the support to the
    // surface with interval bounds, which is what the camera should frame.
    render::Scene probe;
    probe.addImplicit(*impl_->blobCompiled, probe.addMaterial({}));
    box = probe.bounds();
  }
  if (box.empty()) box = Box3{Vec3(-0.5f), Vec3(0.5f)};
  impl_->frame = box;
  return box;
}

ModelFigures SpeciesModel::addToScene(render::Scene& scene, const Stage& stage, GeometryMode mode,
                                      const SpeciesRender& look) {
  ModelFigures fig;
  const auto t0 = std::chrono::steady_clock::now();
  if (impl_->seq) {
    const int step = stage.step < 0 ? impl_->seq->lastStage() : stage.step;
    lsystem::Skeleton skeleton = impl_->seq->skeletonAt(step, stage.fraction);
    fig.modules = impl_->seq->modulesAt(step);
    fig.internodes = skeleton.internodes.size();
    if (mode == GeometryMode::Skeleton) {
      const SkeletonFigures sf = skeletonFigures(skeleton);
      fig.primitives = sf.primitives;
      fig.triangles = sf.triangles;
      fig.buildSeconds = secondsSince(t0);
      scene.addSkeleton(skeleton, look.style);
      return fig;
    }
    if (skeleton.internodes.empty()) {
      // Nothing to build a surface from yet (the axiom draws nothing): show the organs.
      scene.addSkeleton(skeleton, look.style);
      fig.buildSeconds = secondsSince(t0);
      return fig;
    }
    TreeModel tree = buildTreeModel(species_, skeleton);
    fig.primitives = tree.compiled.primitiveCount();
    fig.triangles = tree.leaves.triangleCount();
    std::optional<blobtree::PolygonizeResult> mesh;
    if (mode == GeometryMode::Mesh) {
      mesh = blobtree::polygonizeDetailed(tree.compiled, {});
      fig.triangles += mesh->mesh.triangleCount();
    }
    fig.buildSeconds = secondsSince(t0);
    addTreeToScene(scene, tree, look, {}, mesh ? &*mesh : nullptr);
  } else if (impl_->shell) {
    if (mode == GeometryMode::Skeleton) throw UsageError("shells have no skeleton: use --mode exact or mesh");
    const double age = stage.age < 0 ? finalStage().age : stage.age;
    std::optional<ShellBuild> built;
    const ShellBuild* shell = nullptr;
    if (impl_->finalShell && age == finalStage().age) {
      shell = &*impl_->finalShell;
    } else {
      built = buildShellSpecies(*impl_->shell, age);
      shell = &*built;
    }
    fig.primitives = shell->blob.primitiveCount();
    std::optional<blobtree::PolygonizeResult> mesh;
    if (mode == GeometryMode::Mesh) {
      blobtree::PolygonizeOptions po;
      po.cellSize = glm::length(shell->blob.bounds().size()) / 340.0f;
      mesh = blobtree::polygonizeDetailed(shell->blob, po);
      fig.triangles = mesh->mesh.triangleCount();
    }
    fig.buildSeconds = secondsSince(t0);
    addShellToScene(scene, *shell, {}, mesh ? &*mesh : nullptr);
  } else {
    if (mode == GeometryMode::Skeleton) throw UsageError("blob species have no skeleton: use --mode exact or mesh");
    const blobtree::CompiledBlob& blob = *impl_->blobCompiled;
    fig.primitives = blob.primitiveCount();
    if (impl_->blob->textures) scene.addTextures(impl_->blob->textures);  // ids = the primitives' texture ids
    const uint32_t material = scene.addMaterial(look.surface);
    if (mode == GeometryMode::Mesh) {
      blobtree::PolygonizeOptions po;
      po.cellSize = impl_->blob->cellSize;
      blobtree::PolygonizeResult mesh = blobtree::polygonizeDetailed(blob, po);
      fig.triangles = mesh.mesh.triangleCount();
      fig.buildSeconds = secondsSince(t0);
      scene.addPolygonized(mesh, material);
    } else {
      fig.buildSeconds = secondsSince(t0);
      scene.addImplicit(blob, material);
    }
  }
  return fig;
}

Mesh SpeciesModel::buildMesh(const Stage& stage, float cellSize, bool progress, ModelFigures* figures) {
  ModelFigures fig;
  const auto t0 = std::chrono::steady_clock::now();
  blobtree::PolygonizeOptions po;
  po.cellSize = cellSize;
  po.progress = progress;
  Mesh out;
  if (impl_->seq) {
    const int step = stage.step < 0 ? impl_->seq->lastStage() : stage.step;
    lsystem::Skeleton skeleton = impl_->seq->skeletonAt(step, stage.fraction);
    fig.modules = impl_->seq->modulesAt(step);
    fig.internodes = skeleton.internodes.size();
    if (skeleton.internodes.empty())
      throw InputError(speciesLoc(species_), "the species draws no internodes at " + stageName(stage) +
                                                 ": there is no surface to mesh");
    TreeModel tree = buildTreeModel(species_, skeleton);
    fig.primitives = tree.compiled.primitiveCount();
    out = blobtree::polygonize(tree.compiled, po);
    if (tree.leaves.triangleCount() > 0) appendMesh(out, tree.leaves);
  } else if (impl_->shell) {
    const ShellBuild shell = buildShellSpecies(*impl_->shell, stage.age < 0 ? std::nullopt : std::optional(stage.age));
    fig.primitives = shell.blob.primitiveCount();
    if (po.cellSize <= 0) po.cellSize = glm::length(shell.blob.bounds().size()) / 340.0f;
    out = blobtree::polygonize(shell.blob, po);
  } else {
    fig.primitives = impl_->blobCompiled->primitiveCount();
    if (po.cellSize <= 0) po.cellSize = impl_->blob->cellSize;
    out = blobtree::polygonize(*impl_->blobCompiled, po);
  }
  fig.triangles = out.triangleCount();
  fig.buildSeconds = secondsSince(t0);
  if (figures) *figures = fig;
  return out;
}

render::Camera modelCamera(const SpeciesRender& look, const Box3& box, int width, int height) {
  const double aspect = static_cast<double>(width) / height;
  if (!look.camera) return render::frameBounds(box, look.view, aspect);
  const CameraSpec& c = *look.camera;
  const Vec3 target = c.target ? *c.target : box.center();
  if (c.position) {
    render::Camera cam;
    cam.position = *c.position;
    cam.target = target;
    cam.fovYDeg = static_cast<float>(look.view.fovYDeg);
    return cam;
  }
  if (c.distance)
    return render::orbitCamera(target, look.view.azimuthDeg, look.view.elevationDeg, *c.distance, look.view.fovYDeg);
  // Only a target: the automatic distance, aimed at the target.
  render::Camera cam = render::frameBounds(box, look.view, aspect);
  cam.position += target - cam.target;
  cam.target = target;
  return cam;
}

Image renderModel(SpeciesModel& model, const SpeciesRender& look, const RenderJob& job, ModelFigures* figures,
                          render::RenderStats* stats) {
  int width = job.width > 0 ? job.width : look.width;
  int height = job.height > 0 ? job.height : look.height;
  if (job.width > 0 && job.height <= 0) height = std::max(16, look.height * job.width / look.width);
  if (job.height > 0 && job.width <= 0) width = std::max(16, look.width * job.height / look.height);
  const Box3 frame = model.frameBox();
  render::Scene scene;
  ModelFigures fig = model.addToScene(scene, job.stage, job.mode, look);
  const auto t0 = std::chrono::steady_clock::now();
  scene.commit();
  fig.buildSeconds += secondsSince(t0);
  fig.cells = scene.stats().implicitCells;
  render::RenderSettings rs = look.settings(width, height);
  if (job.samples > 0) rs.spp = job.samples;
  rs.progress = job.progress;
  rs.progressLabel = job.progressLabel;
  Image image = render::renderImage(scene, modelCamera(look, frame, width, height), rs, stats);
  if (figures) *figures = fig;
  return image;
}

}  // namespace sprig
