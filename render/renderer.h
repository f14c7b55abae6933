#pragma once
/// The tile renderer: camera rays, sun with soft shadows, sky light, ground, film.
///
/// Each pixel draws `spp` samples whose points depend only on (seed, x, y, sample,
/// dimension): Owen-scrambled Sobol' points in Morton order (Sampling::ZSobol, the default;
/// render/sampler.h) or stratified jittered samples from a generator seeded with
/// deriveSeed(seed, {x, y}) (Sampling::Stratified); so the image bytes do not depend on
/// the thread count, the tile size or the tile order. Tiles of 32x32 pixels run in parallel, each pixel
/// traced once; a tent filter's pixels on a tile's border are reconstructed from the
/// neighbouring tiles' samples once those are traced, so it crosses tile borders seamlessly.
/// Shading is in linear light: Lambert diffuse plus a normalized Blinn-Phong highlight
/// under a sun (a disc of angular radius `sunAngleDeg`, sampled for soft shadows), a sky
/// dome (ambient occlusion by cosine-weighted hemisphere rays) and an optional fill
/// light from the camera; the ground is an analytic horizontal plane under the model.

#include <cstdint>
#include <optional>
#include <string>

#include "core/image.h"
#include "render/camera.h"
#include "render/scene.h"

namespace sprig::render {

/// What the film shows where a camera ray hits nothing.
enum class Background {
  Color,        ///< RenderSettings::backgroundColor
  Gradient,     ///< backgroundTop at the top row to backgroundBottom at the bottom
  Transparent,  ///< alpha 0 (color 0) where nothing is hit
};

/// Where a pixel's sample points come from.
enum class Sampling {
  /// Morton-ordered Owen-scrambled Sobol' points (render/sampler.h): stratified within a
  /// pixel and across neighbouring pixels, for the film, the sun disc and every sky ray.
  ZSobol,
  /// The earlier sampler, kept as a baseline: a jittered near-square grid on the film and
  /// jittered strata of the sun disc and the sky hemisphere with a per-pixel cyclic shift,
  /// drawn from a per-pixel PCG32 stream.
  Stratified,
};

/// Pixel reconstruction filter.
enum class Filter {
  Box,   ///< average of the pixel's own samples
  Tent,  ///< separable tent of radius filterRadius over the samples of neighbouring pixels too
};

/// Everything that controls one render. Defaults give a clean daylight preview.
struct RenderSettings {
  int width = 800;      ///< pixels
  int height = 600;     ///< pixels
  int spp = 4;          ///< camera samples per pixel
  Sampling sampler = Sampling::ZSobol;  ///< how the samples are placed
  int threads = 0;      ///< 0 = all cores
  uint64_t seed = 0;    ///< base seed of every per-pixel generator
  int tileSize = 32;    ///< tile edge in pixels (the unit of parallel work; the image does not depend on it)

  Filter filter = Filter::Tent;
  float filterRadius = 1.0f;  ///< tent radius in pixels (Box always averages the pixel's own samples)

  Background background = Background::Gradient;
  Vec3 backgroundColor{0.80f, 0.85f, 0.90f};  ///< Color background, linear RGB
  Vec3 backgroundTop{0.42f, 0.58f, 0.80f};    ///< Gradient background at the top row
  Vec3 backgroundBottom{0.85f, 0.88f, 0.92f}; ///< Gradient background at the bottom row

  bool sun = true;                ///< light from a sun disc
  double sunAzimuthDeg = -50.0;   ///< direction toward the sun, same convention as ViewSpec
  double sunElevationDeg = 50.0;  ///< sun height above the horizon
  double sunAngleDeg = 0.6;       ///< angular radius of the sun disc (0 = hard shadows)
  Vec3 sunColor{1.0f, 0.95f, 0.88f};  ///< linear RGB tint of the sun
  float sunStrength = 1.6f;       ///< irradiance scale of the sun
  bool shadows = true;            ///< cast shadow rays toward the sun

  Vec3 skyZenith{0.50f, 0.65f, 0.95f};   ///< sky radiance overhead (before skyStrength)
  Vec3 skyHorizon{0.90f, 0.93f, 1.00f};  ///< sky radiance at the horizon
  float skyStrength = 0.5f;      ///< scale of the sky light
  int skySamples = 1;             ///< ambient-occlusion rays per camera sample (0 = unoccluded sky)
  /// Ambient-occlusion rays per camera sample where the sun adds nothing (the point is in
  /// its shadow or faces away from it), when more than skySamples: there the sky is the
  /// only light and its rays the only noise. 0 = skySamples everywhere.
  int unlitSkySamples = 0;
  float fillStrength = 0.0f;      ///< unshadowed light from the camera direction (0 = off)
  /// Rim light: a distant light from behind the model, placed relative to the camera, that
  /// outlines silhouettes and lights the edges of ridges and cuts; it casts hard shadows
  /// (one occlusion ray where it reaches a surface). 0 = off.
  float rimStrength = 0.0f;
  double rimAzimuthDeg = 150.0;   ///< around +Y from the camera's azimuth (180 = straight behind the model; 150 behind and to the camera's right)
  double rimElevationDeg = 25.0;  ///< above the horizon
  Vec3 rimColor{0.92f, 0.95f, 1.0f};  ///< linear RGB tint of the rim light
  /// Filter the sky term with the edge-avoiding à-trous filter (render/sky_filter.h): the
  /// sky's irradiance is smoothed across pixels of the same surface, never across normals,
  /// depth steps or albedo edges.
  bool skyFilter = true;
  /// Adaptive camera samples: a pixel whose spp samples disagree (their display
  /// luminances, with the sky's noise taken out, spread by more than edgeThreshold: a
  /// silhouette, a texture or shadow edge, a twig or spine narrower than the pixel, the
  /// sun's penumbra) gets edgeSamples more. The sky's own noise is the sky filter's.
  /// 0 = off. The default and refineSamples' were chosen on bench_noise's four scenes
  /// (docs/PERFORMANCE.md, "A second pass where the filter leaves noise").
  int edgeSamples = 12;
  float edgeThreshold = 0.08f;  ///< in display units (0..1, about gamma 2 luminance)
  /// Samples spent where the sky filter leaves noise: a shadowed leaf in a crown, a fold,
  /// where no neighbour alike lends its samples. After the first pass the filter runs once
  /// to estimate the noise it leaves in each pixel (render::FilteredSky::variance); a
  /// pixel where that noise's standard deviation exceeds refineThreshold traces its first
  /// pass again and refineSamples more camera samples, all of them weighing spp / count as
  /// an edge-sampled pixel's do, and the filter runs again. 0 = off; needs skyFilter (no
  /// effect without it).
  int refineSamples = 8;
  float refineThreshold = 0.007f;  ///< in display units (0..1, about gamma 2 luminance)

  bool ground = true;             ///< analytic ground plane under the model
  bool groundAtModelBase = true;  ///< put the plane at the scene's lowest y (else at groundHeight)
  float groundHeight = 0.0f;      ///< plane height when groundAtModelBase is false
  Vec3 groundColor{0.45f, 0.42f, 0.37f};  ///< linear albedo of the ground
  float groundFade = 6.0f;        ///< ground fades into the background beyond this many model radii
  /// The box the ground rests under (its lowest y, with groundAtModelBase) and fades around
  /// (its centre and radius); unset: the scene's bounds. Stages of one model rendered with
  /// one ground frame share one horizon.
  std::optional<Box3> groundFrame;

  /// Minimum drawn width of thin curves and twigs, in pixels (Scene::setPixelFootprint;
  /// the callers that build the scene pass it on). 0 = draw them as they are.
  float thinMinPixels = 2.0f;

  float exposure = 0.0f;          ///< stops; linear values are multiplied by 2^exposure
  bool progress = true;           ///< show a progress bar over tiles (silent when not a terminal)
  std::string progressLabel = "render";  ///< text before the progress bar
};

/// Counts and time of one render.
struct RenderStats {
  uint64_t cameraRays = 0;  ///< primary rays (spp per pixel, and the edge and refine samples)
  uint64_t shadowRays = 0;  ///< occlusion rays toward the sun
  uint64_t skyRays = 0;     ///< ambient-occlusion rays
  double seconds = 0;       ///< wall time of renderImage
  /// All rays cast.
  uint64_t rays() const { return cameraRays + shadowRays + skyRays; }
  /// Rays per wall-clock second.
  double raysPerSecond() const { return seconds > 0 ? static_cast<double>(rays()) / seconds : 0.0; }
};

/// The sky's light on a point above the ground facing unit n with nothing in the way: the
/// cosine-weighted mean radiance of the sky dome and, below the horizon, of the ground's
/// bounce (the irradiance over pi, before skyStrength), within 0.3 % of the zenith-horizon
/// difference. The filtered sky term is divided by it times the albedo (render/sky_filter.h).
/// Builds the renderer's 65-entry table on each call (0.28 ms).
Vec3 openSkyIrradiance(const RenderSettings& settings, const Vec3& n);

/// Renders scene (committed) through camera. Throws std::invalid_argument for a size or
/// sample count below 1, a camera that cannot make valid rays (cameraProblem) or a scene
/// whose bounds are not finite or beyond kMaxRenderCoordinate, Cancelled when cancellation
/// was requested. Cost: about width*height*spp*(1 + shadows + skySamples) rays (up to
/// unlitSkySamples sky rays where the sun is blocked).
Image renderImage(const Scene& scene, const Camera& camera, const RenderSettings& settings, RenderStats* stats = nullptr);

}  // namespace sprig::render
