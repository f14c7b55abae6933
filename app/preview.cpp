#include "app/preview.h"

#include "render/camera.h"
#include "render/renderer.h"
#include "render/scene.h"

namespace sprig {

DBox3 framingBox(const lsystem::Skeleton& skeleton) {
  DBox3 b = skeleton.bounds();
  if (b.empty()) return DBox3{DVec3(-0.5), DVec3(0.5)};
  return b;
}

Image renderSkeletonImage(const lsystem::Skeleton& skeleton, const SpeciesRender& look, const DBox3& frameBox,
                                  int width, int height, const std::string& label) {
  render::Scene scene;
  scene.addSkeleton(skeleton, look.style);
  scene.commit();
  Box3 box{Vec3(frameBox.lo), Vec3(frameBox.hi)};
  render::Camera camera = render::frameBounds(box, look.view, static_cast<double>(width) / height);
  render::RenderSettings rs = look.settings(width, height);
  rs.progressLabel = label;
  return render::renderImage(scene, camera, rs);
}

Image renderGrowthStrip(const std::vector<const lsystem::Skeleton*>& stages, const SpeciesRender& look,
                                const DBox3& frameBox, int cellWidth, int height, const std::string& label) {
  const int count = static_cast<int>(stages.size());
  Image strip(cellWidth * std::max(count, 1), height);
  for (int i = 0; i < count; ++i) {
    Image cell = renderSkeletonImage(*stages[i], look, frameBox, cellWidth, height,
                                             label + " " + std::to_string(i + 1) + "/" + std::to_string(count));
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < cellWidth; ++x) strip.set(i * cellWidth + x, y, cell.at(x, y));
  }
  return strip;
}

}  // namespace sprig
