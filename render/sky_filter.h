#pragma once
/// The edge-avoiding filter of the renderer's sky term.
///
/// At a few samples per pixel the sky light (cosine-weighted ambient-occlusion rays) is
/// the renderer's noise: where the sun is blocked, a pixel's brightness is the visibility
/// of a handful of rays. This filter smooths that term alone, after Dammertz et al. 2010
/// ("Edge-Avoiding À-Trous Wavelet Transform for fast Global Illumination Filtering") with
/// the variance-guided luminance weight of Schied et al. 2017 ("Spatiotemporal
/// Variance-Guided Filtering", SVGF):
/// - the sky radiance of a pixel is divided by what multiplied it (demodulated): the
///   albedo, so texture, bark and shell colour never blur, and the renderer's sky light with
///   nothing in the way for the pixel's normal (render::openSkyIrradiance). What is filtered
///   is then the sky's visibility, the fraction of that light the scene lets through, which
///   varies far less from one surface to the next than the light itself: neighbouring
///   leaves of a crown, turned every way, see about as much sky. This is the ratio estimator
///   of Heitz et al. 2018 ("Combining Analytic Direct Illumination and Stochastic Shadows")
///   with the unshadowed term analytic: the filtered fraction is multiplied back by the
///   pixel's own albedo and open sky;
/// - four à-trous passes (the kernel 1/4, 1/2, 1/4 in x and y, or the B3 spline 1/16, 1/4,
///   3/8, 1/4, 1/16, at steps 1, 2, 4, 8 pixels) weight each tap by three edge-stopping
///   functions:
///   normals  w_n = max(0, n_p . n_q)^4 (SVGF's 128 was for the irradiance itself; the
///            visibility needs only a guard against creases),
///   planes   w_x = exp(-|n_p . (X_q - X_p)| / (sigmaPlane * f_p * |p - q|)), the distance
///            of the tap's surface point from the pixel's tangent plane against the pixel's
///            footprint f_p (the least distance to a 4-neighbour's point),
///   light    w_l = exp(-|l_p - l_q| / (sigmaLuminance * sqrt(var_p) + eps)), the difference
///            of the demodulated luminances against their estimated standard deviation;
/// - a pixel's variance starts as the per-sample variance of that luminance pooled over its
///   3x3 neighbours that pass the normal and plane tests, divided by its sample count, and
///   each pass carries it on as sum(w^2 var) / (sum w)^2. The per-sample variance is at
///   least a binomial visibility's, p (1 - p) per sky ray with the rule of succession's
///   p = (k + 1) / (n + 2) from the pixel's own mean: a pixel whose four sky rays were all
///   blocked by chance is not taken for a noiseless one (that left black specks in crowns).
/// Edges are kept by construction: a tap on a surface turned away by 90 degrees or more,
/// on a pixel with no surface, or on an albedo of zero has weight 0, and the output of a
/// pixel is a convex combination of demodulated values, so a constant one stays constant
/// and no value leaves the range of its neighbourhood. Everything is a function of the
/// layers alone: the same bytes at any thread count.

#include <vector>

#include "core/image.h"
#include "core/types.h"

namespace sprig::render {

/// Per-pixel inputs of the filter, reconstructed with the same filter as the image.
struct SkyLayers {
  int width = 0, height = 0;
  std::vector<Vec3> sky;       ///< sky radiance in the image (albedo * irradiance), after exposure
  std::vector<Vec3> albedo;    ///< what multiplied the filtered term: the albedo, times the open sky's light when the renderer filters (0 where no sky term)
  std::vector<Vec3> normal;    ///< summed shading normals of the pixel's surface samples
  std::vector<Vec3> position;  ///< mean surface point of the pixel's surface samples
  std::vector<float> lumSum;   ///< sum over the pixel's own surface samples of the demodulated luminance (sky / albedo)
  std::vector<float> lumSquares;  ///< sum of its squares
  std::vector<float> count;    ///< number of the pixel's own samples that met a surface
  /// Sum over the pixel's own surface samples of the sky rays each cast (more where the sun
  /// is blocked, RenderSettings::unlitSkySamples); the variance floor of a pixel's
  /// visibility divides by their mean (at least 1).
  std::vector<float> raySum;
  /// The reconstruction filter's total weight of the pixel's samples (its own and its
  /// neighbours'; a pixel's own samples weigh spp in all): what the renderer's second pass
  /// (RenderSettings::refineSamples) adds its samples' weights to.
  std::vector<float> weight;

  SkyLayers() = default;
  SkyLayers(int w, int h);
  size_t index(int x, int y) const { return static_cast<size_t>(y) * width + x; }
};

/// Strengths of the edge-stopping functions (see the file comment).
/// The defaults were chosen on bench_noise's four scenes at 320x240 and 4 samples (docs/
/// PERFORMANCE.md, "The sky's visibility filtered").
struct SkyFilterSettings {
  int passes = 4;
  /// 1: the 3x3 kernel (1/4, 1/2, 1/4), the default; 2: the 5x5 B3-spline kernel, which
  /// lowered the error of bench_noise's scenes by 1-4 % more at about twice the filter's cost.
  int kernelRadius = 1;
  int normalPowerLog2 = 2;  ///< the normal weight's power: 2^normalPowerLog2 (0..8)
  float sigmaPlane = 2.0f;
  float sigmaLuminance = 3.0f;
};

/// Luminance (Rec. 709) of linear RGB.
inline float luminance(const Vec3& c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }

/// The filter's output: per pixel, the filtered irradiance E (sky / albedo per channel; 0
/// where a pixel has no sky term) and the estimated variance of its luminance, carried
/// through the passes as sum(w^2 var) / (sum w)^2 (what smoothing left of the noise).
struct FilteredSky {
  std::vector<Vec3> irradiance;
  std::vector<float> variance;
};

/// Runs the filter on layers.
FilteredSky filterSky(const SkyLayers& layers, const SkyFilterSettings& settings = {});

/// Whether pixel i has a sky term the filter replaces (surface samples, an albedo, a normal).
bool hasSkyTerm(const SkyLayers& layers, size_t i);

/// The sky term of pixel i (radiance in the image) for filtered irradiance e: albedo * e per
/// channel, the raw sky term where a channel's albedo is 0.
Vec3 filteredSkyTerm(const SkyLayers& layers, size_t i, const Vec3& e);

/// Replaces the sky term of image by filteredSkyTerm(layers, i, e[i]) where hasSkyTerm.
void applySkyTerm(Image& image, const SkyLayers& layers, const std::vector<Vec3>& e);

/// Replaces the sky term of image by its filtered version: image += albedo * filtered(E) - sky.
void filterSkyTerm(Image& image, const SkyLayers& layers, const SkyFilterSettings& settings = {});

/// The filtered irradiance alone (sky / albedo per channel, filtered), 0 where a pixel has
/// no sky term; exposed for tests.
std::vector<Vec3> filteredIrradiance(const SkyLayers& layers, const SkyFilterSettings& settings = {});

}  // namespace sprig::render
