#include "model/model.h"
#include "core/timer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <tuple>

#include "core/diagnostics.h"
#include "core/mesh_clean.h"
#include "core/phases.h"
#include "render/camera.h"

namespace sprig {

namespace {

std::string pointText(const Vec3& p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%g, %g, %g)", double(p.x), double(p.y), double(p.z));
  return buf;
}

/// Throws InputError at the species when the box the camera frames cannot be framed: not
/// finite, reaching beyond render::kMaxRenderCoordinate, or of zero size (the whole model at
/// one point). An empty box (nothing built) is framed as the unit cube.
void checkFrameBox(const Species& species, const Box3& box) {
  if (box.empty()) return;
  if (!render::boxInRenderRange(box))
    throw InputError(species.loc(), "the model's bounding box " + pointText(box.lo) + " - " + pointText(box.hi) +
                                        " is not finite or reaches beyond 1e15: it cannot be rendered");
  const Vec3 size = box.size();
  if (!(std::max(size.x, std::max(size.y, size.z)) > 0))
    throw InputError(species.loc(), "the model has zero size (all of it lies at " + pointText(box.lo) +
                                        "): there is nothing to frame");
}

/// The job's image size: its own, else the look's (one side given: the other keeps the look's aspect).
std::pair<int, int> imageSize(const SpeciesRender& look, const RenderJob& job) {
  const int lookWidth = look.image.width, lookHeight = look.image.height;
  int width = job.width > 0 ? job.width : lookWidth;
  int height = job.height > 0 ? job.height : lookHeight;
  if (job.width > 0 && job.height <= 0) height = std::max(16, lookHeight * job.width / lookWidth);
  if (job.height > 0 && job.width <= 0) width = std::max(16, lookWidth * job.height / lookHeight);
  return {width, height};
}

void addStats(render::RenderStats& sum, const render::RenderStats& s) {
  sum.cameraRays += s.cameraRays;
  sum.shadowRays += s.shadowRays;
  sum.skyRays += s.skyRays;
  sum.seconds += s.seconds;
}

}  // namespace

SpeciesModel::SpeciesModel(const Species& species, const ModelOptions& options) : species_(species) {
  const Phase phase("read");
  if (!species_.spec) throw InputError(species_.loc(), "invalid " + species_.kind + " species");
  kind_ = species_.spec->makeModel(species_, options);
}

SpeciesModel::SpeciesModel(const Species& species, const lsystem::GrammarOverrides& extra, int lastStep)
    : SpeciesModel(species, ModelOptions{extra, lastStep}) {}

SpeciesModel::~SpeciesModel() = default;

ModelFigures SpeciesModel::addToScene(render::Scene& scene, const Stage& stage, GeometryMode mode,
                                      const SpeciesRender& look) {
  BuiltStage built = [&] {
    const Phase phase("build");
    return kind_->build(stage, mode, look);
  }();
  const Phase phase("scene");
  scene.add(built.geometry);
  return built.figures;
}

Mesh SpeciesModel::buildMesh(const Stage& stage, float cellSize, bool progress, ModelFigures* figures) {
  ModelFigures fig;
  const auto t0 = std::chrono::steady_clock::now();
  Mesh out = [&] {
    const Phase phase("build");
    return kind_->buildMesh(stage, cellSize, progress, fig);
  }();
  fig.triangles = out.triangleCount();
  fig.buildSeconds = secondsSince(t0);
  if (figures) *figures = fig;
  return out;
}

Mesh SpeciesModel::cleanSurface(const MeshCleanOptions& clean, MeshCleanReport* report, ModelFigures* figures) {
  Mesh out = buildMesh(finalStage(), 0.0f, false, figures);
  const MeshCleanReport r = cleanMesh(out, clean);
  if (report) *report = r;
  return out;
}

std::vector<ExportPart> SpeciesModel::exportParts(const Stage& stage, float cellSize, bool progress,
                                                 const MeshCleanOptions& clean, ModelFigures* figures, size_t meshTriangles) {
  ModelFigures fig;
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<ExportPart> parts = [&] {
    const Phase phase("build");
    SpeciesRender look = species_.render;
    look.meshTriangles = meshTriangles;
    return kind_->exportParts(stage, cellSize, progress, look, clean, fig);
  }();
  fig.triangles = 0;
  for (const ExportPart& p : parts) fig.triangles += p.mesh.triangleCount();
  fig.buildSeconds = secondsSince(t0);
  if (figures) *figures = fig;
  return parts;
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

Box3 SpeciesModel::frameBox() {
  const Phase phase("build");
  return kind_->frameBox();
}

Box3 SpeciesModel::closeUpBox(const CloseUpSpec& target) {
  const Phase phase("build");
  return target.point ? Box3{*target.point, *target.point} : kind_->partBox(target);
}

render::Camera speciesCamera(SpeciesModel& model, const SpeciesRender& look, const Box3& frame, int width, int height) {
  if (!look.closeUp) return modelCamera(look, frame, width, height);
  const Box3 target = model.closeUpBox(*look.closeUp);
  const double aspect = static_cast<double>(width) / height;
  if (!(look.closeUp->size > 0)) return render::frameBounds(target, look.view, aspect);
  // A size: the square of that side across the view at the target's centre fills the
  // frame's shorter side, less the margin.
  const double halfTan = std::tan(0.5 * radians(look.view.fovYDeg)) * std::min(1.0, aspect) *
                         (1.0 - std::clamp(look.view.margin, 0.0, 0.9));
  return render::orbitCamera(target.center(), look.view.azimuthDeg, look.view.elevationDeg,
                             0.5 * look.closeUp->size / halfTan, look.view.fovYDeg);
}

void checkCameraRays(int width, int height, int samples) {
  const uint64_t rays = uint64_t(std::max(width, 0)) * uint64_t(std::max(height, 0)) * uint64_t(std::max(samples, 0));
  if (rays <= kMaxCameraRays) return;
  throw UsageError("the image takes " + std::to_string(width) + " x " + std::to_string(height) + " x " +
                   std::to_string(samples) + " samples = " + std::to_string(rays) + " camera rays, more than the limit of " +
                   std::to_string(kMaxCameraRays) + " (2^34): lower --width, --height or --samples (render: width, height, samples in the species file)");
}

Box3 restingFrame(const Box3& frame, const Box3& stage, bool groundAtModelBase) {
  if (!groundAtModelBase || stage.empty() || !std::isfinite(stage.lo.y)) return frame;
  const Vec3 up(0, stage.lo.y - frame.lo.y, 0);
  return Box3{frame.lo + up, frame.hi + up};
}

namespace {

/// The image size, frame box and camera of a job (renderModel's first step).
struct FramePlan {
  int width = 0, height = 0;
  Box3 frame;
  render::Camera camera;
  bool fixedCamera = false;  ///< job.camera or a close-up: not moved to the resting frame
};

FramePlan planFrame(SpeciesModel& model, const SpeciesRender& look, const RenderJob& job) {
  FramePlan p;
  std::tie(p.width, p.height) = imageSize(look, job);
  checkCameraRays(p.width, p.height, job.samples > 0 ? job.samples : look.image.spp);
  p.frame = job.frame ? *job.frame : model.frameBox();
  checkFrameBox(model.species(), p.frame);
  p.fixedCamera = job.camera || look.closeUp;
  p.camera = job.camera ? *job.camera : speciesCamera(model, look, p.frame, p.width, p.height);
  if (std::string why = render::cameraProblem(p.camera); !why.empty())
    throw InputError(model.species().loc(), "render.camera: " + why);
  return p;
}

}  // namespace

/// A stage built into a committed scene for one camera (renderModel's second step).
struct BuiltScene {
  render::Scene scene;
  ModelFigures figures;
};

namespace {

std::unique_ptr<BuiltScene> buildScene(SpeciesModel& model, const SpeciesRender& look, const RenderJob& job,
                                       const FramePlan& plan) {
  auto built = std::make_unique<BuiltScene>();
  render::Scene& scene = built->scene;
  scene.setPixelFootprint(plan.camera, plan.width, plan.height, look.image.thinMinPixels);
  if (job.cellCamera) scene.setCellFootprint(*job.cellCamera, job.cellHeight);
  scene.setExpectedSamples(plan.camera, plan.width, plan.height, job.samples > 0 ? job.samples : look.image.spp);
  SpeciesRender seen = look;
  // The mesh mode polygonizes at the cells' pixel too.
  seen.pixels = job.cellCamera ? job.cellCamera->pixelScale(job.cellHeight) : plan.camera.pixelScale(plan.height);
  ModelFigures& fig = built->figures;
  fig = model.addToScene(scene, job.stage, job.mode, seen);
  const auto t0 = std::chrono::steady_clock::now();
  {
    const Phase phase("scene");
    scene.commit();
  }
  fig.buildSeconds += secondsSince(t0);
  fig.cells = scene.stats().implicitCells;
  return built;
}

/// The picture of a built scene (renderModel's last step): the camera moved to the resting
/// frame unless fixed, then rendered.
Image renderScene(const BuiltScene& built, const SpeciesRender& look, const RenderJob& job, const FramePlan& plan,
                  render::RenderStats* stats) {
  render::RenderSettings rs = look.settings(plan.width, plan.height);
  if (job.samples > 0) rs.spp = job.samples;
  rs.progress = job.progress;
  rs.progressLabel = job.progressLabel;
  const Box3 resting = restingFrame(plan.frame, built.scene.bounds(), rs.groundAtModelBase);
  render::Camera camera = plan.camera;
  if (!plan.fixedCamera && resting.lo.y != plan.frame.lo.y) camera = modelCamera(look, resting, plan.width, plan.height);
  rs.groundFrame = resting;
  const Phase phase("render");
  return render::renderImage(built.scene, camera, rs, stats);
}

bool sameStage(const Stage& a, const Stage& b) {
  return a.step == b.step && a.fraction == b.fraction && a.age == b.age && a.time == b.time &&
         a.windSpeed == b.windSpeed && a.windDirectionDeg == b.windDirectionDeg && a.windSeconds == b.windSeconds;
}

bool sameCamera(const render::Camera& a, const render::Camera& b) {
  return a.position == b.position && a.target == b.target && a.up == b.up && a.fovYDeg == b.fovYDeg;
}

}  // namespace

Image renderModel(SpeciesModel& model, const SpeciesRender& look, const RenderJob& job, ModelFigures* figures,
                  render::RenderStats* stats) {
  const FramePlan plan = planFrame(model, look, job);
  const std::unique_ptr<BuiltScene> built = buildScene(model, look, job, plan);
  Image image = renderScene(*built, look, job, plan, stats);
  if (figures) *figures = built->figures;
  return image;
}

FrameSequence::FrameSequence(SpeciesModel& model) : model_(model) {}

FrameSequence::~FrameSequence() = default;

Image FrameSequence::render(const SpeciesRender& look, const RenderJob& job) {
  const FramePlan plan = planFrame(model_, look, job);
  const bool sameScene = built_ && sameStage(job.stage, stage_) && job.mode == mode_ && plan.width == width_ &&
                         plan.height == height_;
  if (sameScene && sameCamera(plan.camera, camera_) && job.samples == samples_ && plan.frame.lo == frame_.lo &&
      plan.frame.hi == frame_.hi) {
    ++reusedImages_;  // the same scene, camera and settings: the same bytes
    return image_;
  }
  const bool serves = sameScene && job.mode != GeometryMode::Mesh && !look.wireframe &&
                      built_->scene.servesCamera(plan.camera, plan.width, plan.height);
  if (serves) {
    ++reusedScenes_;
  } else {
    built_ = buildScene(model_, look, job, plan);
    ++builtScenes_;
  }
  stage_ = job.stage;
  mode_ = job.mode;
  width_ = plan.width;
  height_ = plan.height;
  camera_ = plan.camera;
  frame_ = plan.frame;
  samples_ = job.samples;
  image_ = renderScene(*built_, look, job, plan, nullptr);
  return image_;
}

namespace {

/// The box both panels of a pair frame: the union of the two species' frame boxes.
Box3 pairFrame(SpeciesModel& model, SpeciesModel& other) {
  Box3 frame = model.frameBox();
  frame.extend(other.frameBox());
  checkFrameBox(model.species(), frame);
  return frame;
}

/// The white rule between a pair's panels: pairDividerHalfWidth(panel) columns on each side
/// of the seam. Both panels show the same sky and ground, so without it a shadow or an
/// object reaching past the left panel's edge reads as cut off inside one picture.
void drawPanelDivider(Image& out, int panel) {
  const int half = pairDividerHalfWidth(panel);
  for (int y = 0; y < out.height; ++y)
    for (int x = panel - half; x < panel + half; ++x) out.set(x, y, Vec4(1.0f));
}

}  // namespace

int pairDividerHalfWidth(int panel) { return 1 + panel / 512; }

render::Camera pairCamera(SpeciesModel& model, SpeciesModel& other, const SpeciesRender& look, int width, int height) {
  return speciesCamera(model, look, pairFrame(model, other), std::max(16, width / 2), height);
}

Image renderPair(SpeciesModel& model, SpeciesModel& other, const SpeciesRender& look, const RenderJob& job,
                 ModelFigures* figures, render::RenderStats* stats) {
  const auto [width, height] = imageSize(look, job);
  const int panel = std::max(16, width / 2);
  RenderJob panelJob = job;
  panelJob.width = panel;
  panelJob.height = height;
  panelJob.camera = job.camera ? *job.camera : pairCamera(model, other, look, width, height);
  if (!job.frame) panelJob.frame = pairFrame(model, other);  // one ground fade for both panels
  render::RenderStats left, right;
  const Image a = renderModel(model, look, panelJob, figures, &left);
  panelJob.stage = other.finalStage();
  const Image b = renderModel(other, look, panelJob, nullptr, &right);
  Image out(2 * panel, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < panel; ++x) {
      out.set(x, y, a.at(x, y));
      out.set(panel + x, y, b.at(x, y));
    }
  drawPanelDivider(out, panel);
  if (stats) {
    *stats = left;
    addStats(*stats, right);
  }
  return out;
}

InsetPlace insetPlace(const InsetSpec& inset, int width, int height) {
  InsetPlace p;
  p.width = std::max(16, int(std::lround(inset.fraction * width)));
  p.height = std::max(16, int(std::lround(inset.fraction * height)));
  p.x = width - p.width;
  p.y = height - p.height;
  p.rule = 2 * pairDividerHalfWidth(p.width);
  return p;
}

Image renderInset(SpeciesModel& model, const SpeciesRender& look, const RenderJob& job, int width, int height,
                  render::RenderStats* stats) {
  const InsetSpec& inset = *look.inset;
  const InsetPlace place = insetPlace(inset, width, height);
  RenderJob insetJob = job;
  insetJob.width = place.width;
  insetJob.height = place.height;
  insetJob.camera.reset();  // the inset's own close-up or camera
  insetJob.frame.reset();
  insetJob.progressLabel = job.progressLabel + " (inset)";
  // Cells for the whole picture's camera: a close-up's own pixel would ask for the finest
  // cells over the whole model (the nearest corner of its box is near the close-up's eye).
  RenderJob whole = job;
  whole.width = width;
  whole.height = height;
  insetJob.cellCamera = planFrame(model, look, whole).camera;
  insetJob.cellHeight = height;
  return renderModel(model, inset.look, insetJob, nullptr, stats);
}

Image renderPicture(SpeciesModel& model, const SpeciesRender& look, const RenderJob& job, ModelFigures* figures,
                    render::RenderStats* stats) {
  Image out;
  if (!look.pair) {
    out = renderModel(model, look, job, figures, stats);
  } else {
    SpeciesModel other(loadSpecies(*look.pair, model.species().policy));
    out = renderPair(model, other, look, job, figures, stats);
  }
  if (!look.inset) return out;
  render::RenderStats insetStats;
  const Image detail = renderInset(model, look, job, out.width, out.height, &insetStats);
  // The detail over the corner, a white rule along its top and left edges so it reads as
  // its own picture.
  const InsetPlace p = insetPlace(*look.inset, out.width, out.height);
  for (int y = 0; y < p.height; ++y)
    for (int x = 0; x < p.width; ++x)
      out.set(p.x + x, p.y + y, (x < p.rule || y < p.rule) ? Vec4(1.0f) : detail.at(x, y));
  if (stats) addStats(*stats, insetStats);
  return out;
}

}  // namespace sprig
