#pragma once
// Test helper: a growth frame rendered directly from the growth engine (skeleton preview,
// camera framed on the engine's frame box), the path animations and renderModel must match.

#include "model/growth.h"
#include "model/model.h"
#include "model/species.h"
#include "model/tree_kind.h"
#include "render/camera.h"
#include "core/image.h"
#include "render/renderer.h"
#include "render/scene.h"

namespace sprig::test {

inline Image growthFrameImage(GrowthEngine& engine, const SpeciesRender& look, const GrowthFrame& frame,
                                      int width, int height) {
  lsystem::Skeleton sk = engine.skeletonAt(frame.stage, frame.fraction);
  const DBox3& fb = engine.frameBox();
  const Box3 box{Vec3(fb.lo), Vec3(fb.hi)};
  const double aspect = static_cast<double>(width) / height;
  render::Camera camera = render::frameBounds(box, look.view, aspect);
  render::Scene scene;
  scene.setPixelFootprint(camera, width, height, look.image.thinMinPixels);
  scene.add(skeletonPreview(sk, look.style));
  scene.commit();
  render::RenderSettings rs = look.settings(width, height);
  rs.progress = false;
  // Staged as renderModel stages a stage: resting on the ground of the frame.
  rs.groundFrame = restingFrame(box, scene.bounds(), rs.groundAtModelBase);
  if (rs.groundFrame->lo.y != box.lo.y) camera = render::frameBounds(*rs.groundFrame, look.view, aspect);
  return render::renderImage(scene, camera, rs);
}

}  // namespace sprig::test
