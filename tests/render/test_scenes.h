#pragma once
/// Small scenes and settings shared by the render tests.

#include <cmath>

#include "core/image.h"
#include "render/renderer.h"
#include "render/scene.h"

namespace sprig::render::test {

/// Render settings of w x h pixels without a progress bar (other fields: defaults).
inline RenderSettings quietSettings(int w, int h) {
  RenderSettings rs;
  rs.width = w;
  rs.height = h;
  rs.progress = false;
  return rs;
}

/// quietSettings with spp samples per pixel and no more (no edge or second-pass samples), a
/// transparent background and no ground: alpha is then the coverage of the geometry alone,
/// point-sampled spp times.
inline RenderSettings silhouetteSettings(int w, int h, int spp) {
  RenderSettings rs = quietSettings(w, h);
  rs.spp = spp;
  rs.edgeSamples = 0;
  rs.refineSamples = 0;
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

/// Two spheres on the ground lit by sun and sky: soft shadows, contact shadows, sky-only regions.
inline void addSpheres(Scene& scene) {
  SphereSet s;
  s.spheres = {Vec4(0, 1, 0, 1), Vec4(1.6f, 0.45f, 0.6f, 0.45f)};
  s.colors = {Vec3(0.7f), Vec3(0.6f, 0.5f, 0.4f)};
  scene.addSpheres(s, scene.addMaterial(Material{}));
  scene.commit();
}

/// Root-mean-square difference of all channels (alpha too) of two images of one size.
inline double rmse(const Image& a, const Image& b) {
  double sum = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    const double d = a.pixels[i] - b.pixels[i];
    sum += d * d;
  }
  return std::sqrt(sum / static_cast<double>(a.pixels.size()));
}

}  // namespace sprig::render::test
