// Camera and settings of the benches' exact renders (bench_tree, bench_shell).
#pragma once

#include "render/camera.h"
#include "render/renderer.h"

namespace sprig::bench {

/// The camera framing box from azimuth/elevation degrees (render::ViewSpec's other defaults)
/// for a width x height image.
inline render::Camera benchCamera(const Box3& box, double azimuthDeg, double elevationDeg, int width, int height) {
  render::ViewSpec view;
  view.azimuthDeg = azimuthDeg;
  view.elevationDeg = elevationDeg;
  return render::frameBounds(box, view, double(width) / height);
}

/// Render settings of width x height at spp samples, without a progress bar.
inline render::RenderSettings benchSettings(int width, int height, int spp) {
  render::RenderSettings rs;
  rs.width = width;
  rs.height = height;
  rs.spp = spp;
  rs.progress = false;
  return rs;
}

}  // namespace sprig::bench
