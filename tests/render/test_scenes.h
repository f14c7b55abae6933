#pragma once
/// Small scenes and settings shared by the render tests.

#include <cmath>

#include "core/image.h"
#include "render/renderer.h"

namespace sprig::render::test {

/// Render settings of w x h pixels without a progress bar (other fields: defaults).
inline RenderSettings quietSettings(int w, int h) {
  RenderSettings rs;
  rs.width = w;
  rs.height = h;
  rs.progress = false;
  return rs;
}

/// quietSettings with spp samples, a transparent background and no ground: alpha is then
/// the coverage of the geometry alone.
inline RenderSettings silhouetteSettings(int w, int h, int spp) {
  RenderSettings rs = quietSettings(w, h);
  rs.spp = spp;
  rs.background = Background::Transparent;
  rs.ground = false;
  return rs;
}

/// Sum of alpha over all pixels: the covered area in pixels.
inline double alphaArea(const Image& img) {
  double area = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) area += img.at(x, y).a;
  return area;
}

}  // namespace sprig::render::test
