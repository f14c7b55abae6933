#include "render/renderer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

#include "core/parallel.h"
#include "core/progress.h"
#include "core/rng.h"
#include "render/labels.h"
#include "render/sampler.h"
#include "render/sky_filter.h"

namespace sprig::render {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

/// Orthonormal basis around unit n (Duff et al. 2017, "Building an orthonormal basis, revisited").
void basisAround(const Vec3& n, Vec3& a, Vec3& b) {
  float sign = std::copysign(1.0f, n.z);
  float p = -1.0f / (sign + n.z);
  float q = n.x * n.y * p;
  a = Vec3(1.0f + sign * n.x * n.x * p, sign * q, -sign * n.x);
  b = Vec3(q, sign + n.y * n.y * p, -n.y);
}

float next(Rng& rng) { return static_cast<float>(rng.uniform()); }

/// A 2D point in stratum j of an n-point near-square jittered grid.
Vec2 stratified(int j, int n, Rng& rng) {
  int gx = std::max(1, static_cast<int>(std::floor(std::sqrt(static_cast<double>(n)))));
  int gy = (n + gx - 1) / gx;
  float jx = next(rng), jy = next(rng);
  return {(static_cast<float>(j % gx) + jx) / static_cast<float>(gx), (static_cast<float>(j / gx) + jy) / static_cast<float>(gy)};
}

/// Uniform direction within a cone of half-angle with cosine cosMax around axis.
Vec3 sampleCone(const Vec3& axis, float cosMax, Vec2 u) {
  float u1 = u.x, u2 = u.y;
  float cosT = 1.0f - u1 * (1.0f - cosMax);
  float sinT = std::sqrt(std::max(0.0f, 1.0f - cosT * cosT));
  float phi = static_cast<float>(2.0 * kPi) * u2;
  Vec3 a, b;
  basisAround(axis, a, b);
  return glm::normalize(cosT * axis + sinT * (std::cos(phi) * a + std::sin(phi) * b));
}

/// Cosine-weighted direction in the hemisphere around n.
Vec3 sampleCosine(const Vec3& n, Vec2 u) {
  float u1 = u.x, u2 = u.y;
  float r = std::sqrt(u1), phi = static_cast<float>(2.0 * kPi) * u2;
  Vec3 a, b;
  basisAround(n, a, b);
  return glm::normalize(r * std::cos(phi) * a + r * std::sin(phi) * b + std::sqrt(std::max(0.0f, 1.0f - u1)) * n);
}

/// Sky radiance arriving from unit direction d at a point above the ground (below the
/// horizon: the sun's and the sky's light bounced by the ground) or below it (no bounce).
/// sunHeight is the y of the direction toward the sun.
Vec3 skyRadiance(const RenderSettings& s, float sunHeight, const Vec3& d, bool aboveGround) {
  if (d.y < 0.0f && s.ground && aboveGround) {
    Vec3 avgSky = 0.5f * (s.skyZenith + s.skyHorizon);
    float sunOnGround = s.sun ? std::max(0.0f, sunHeight) * s.sunStrength / s.skyStrength : 0.0f;
    return s.groundColor * avgSky * (0.5f + 0.5f * sunOnGround);
  }
  float t = std::sqrt(std::max(0.0f, d.y));
  return glm::mix(s.skyHorizon, s.skyZenith, t);
}

/// The sky's light on a point above the ground facing unit n with nothing in the way: the
/// cosine-weighted mean of skyRadiance over the hemisphere around n, tabulated over n.y
/// (the sky and the ground are the same all around) and interpolated linearly.
class OpenSkyTable {
 public:
  OpenSkyTable() = default;
  OpenSkyTable(const RenderSettings& s, float sunHeight) : entries_(kEntries) {
    // The midpoint rule on a kGrid x kGrid grid of cosine-weighted directions: within 0.3 %
    // of the zenith-horizon difference (the sky's sqrt(d.y) blend is steep at the horizon).
    // The filter divides and multiplies a pixel by the same value, so that error cancels.
    // 0.28 ms a table.
    constexpr int kGrid = 16;
    for (int t = 0; t < kEntries; ++t) {
      const float ny = -1.0f + 2.0f * static_cast<float>(t) / (kEntries - 1);
      const Vec3 n(std::sqrt(std::max(0.0f, 1.0f - ny * ny)), ny, 0.0f);
      Vec3 sum(0);
      for (int i = 0; i < kGrid; ++i)
        for (int j = 0; j < kGrid; ++j) {
          const Vec2 u((static_cast<float>(i) + 0.5f) / kGrid, (static_cast<float>(j) + 0.5f) / kGrid);
          sum += skyRadiance(s, sunHeight, sampleCosine(n, u), true);
        }
      entries_[t] = sum / static_cast<float>(kGrid * kGrid);
    }
  }
  bool empty() const { return entries_.empty(); }
  Vec3 operator()(const Vec3& n) const {
    const float f = std::clamp(0.5f * (n.y + 1.0f), 0.0f, 1.0f) * (kEntries - 1);
    const int i = std::min(static_cast<int>(f), kEntries - 2);
    return glm::mix(entries_[i], entries_[i + 1], f - static_cast<float>(i));
  }

 private:
  static constexpr int kEntries = 65;
  std::vector<Vec3> entries_;
};

/// Whether a render filters its sky term (render/sky_filter.h): where the sky is sampled by
/// rays, its only noise.
bool filtersSky(const RenderSettings& s) { return s.skyFilter && s.skyStrength > 0.0f && s.skySamples > 0; }

struct Counters {
  uint64_t camera = 0, shadow = 0, sky = 0;
  /// Adds these counts to the render's totals (camera, shadow, sky).
  void addTo(std::atomic<uint64_t> (&totals)[3]) const {
    totals[0] += camera;
    totals[1] += shadow;
    totals[2] += sky;
  }
};

/// The sky term of one shaded point, for the sky filter (render/sky_filter.h) and the
/// adaptive samples' test: zero where the sky was not sampled by rays (no noise to filter).
struct ShadeParts {
  Vec3 sky{0};          ///< albedo * sky irradiance: the part of the radiance from the sky
  /// What sky is a fraction of: the albedo times, when the sky is filtered, the sky's light
  /// with nothing in the way (OpenSkyTable), so that the filter smooths the sky's visibility.
  Vec3 albedo{0};
  Vec3 normal{0};       ///< shading normal, facing the viewer (zero: no sky term)
  float irradianceLum = 0;
  float rays = 0;       ///< sky rays cast
};

/// What one camera sample sees: its radiance and alpha, and the sky term with the guides of
/// its first surface.
struct SampleValue {
  Vec4 value{0};
  Vec3 sky{0}, albedo{0};
  Vec3 normal{0}, position{0};  ///< of the first surface with a sky term (normal zero: none)
  float irradianceLum = 0;      ///< of that surface: the luminance of sky / albedo
  float skyRays = 0;            ///< of that surface: the sky rays cast there
  /// Adds the sky term of a surface seen with the given weight (its share of the sample).
  void add(const ShadeParts& p, const Vec3& at, float weight) {
    sky += weight * p.sky;
    albedo += weight * p.albedo;
    if (normal == Vec3(0) && p.normal != Vec3(0)) {
      normal = p.normal;
      position = at;
      irradianceLum = p.irradianceLum;
      skyRays = p.rays;
    }
  }
};

/// Where one camera sample's light samples come from. With a Sobol' sampler, its next
/// dimensions. Otherwise (Sampling::Stratified) the sun disc and the sky hemisphere are
/// stratified over all samples of a pixel, with a per-pixel cyclic shift so light strata
/// do not follow the film strata, jittered by the pixel's generator.
struct Strata {
  int sample = 0;     ///< camera sample index k in [0, spp)
  int spp = 1;
  int sunShift = 0;   ///< per-pixel shift of the sun stratum
  int skyShift = 0;   ///< per-pixel shift of the sky strata
  ZSobolSampler* sobol = nullptr;  ///< the low-discrepancy source, positioned at this sample
};

/// The sun-disc sample of camera sample st.
Vec2 sunSample(const Strata& st, Rng& rng) {
  if (st.sobol) return st.sobol->get2D();
  return stratified((st.sample + st.sunShift) % st.spp, st.spp, rng);
}

/// Sky ray k (of perSample) of camera sample st.
Vec2 skySample(const Strata& st, int k, int perSample, Rng& rng) {
  if (st.sobol) return st.sobol->get2D();
  const int total = st.spp * perSample;
  return stratified((st.sample * perSample + k + st.skyShift) % total, total, rng);
}

/// Per-render constants and the shading of one camera sample.
class Integrator {
 public:
  Integrator(const Scene& scene, const Camera& camera, const RenderSettings& s)
      : scene_(scene), s_(s), film_(camera.filmRays(s.width, s.height)) {
    Box3 b = scene.bounds();
    if (b.empty()) b = Box3{Vec3(-0.5f), Vec3(0.5f)};
    center_ = b.center();
    radius_ = std::max(0.5f * glm::length(b.size()), 1e-6f);
    eps_ = 2e-4f * radius_ + 1e-6f * glm::length(center_);
    // The ground rests under the ground frame (default: the scene) and fades out around it.
    const Box3 g = s.groundFrame && !s.groundFrame->empty() ? *s.groundFrame : b;
    groundY_ = s.groundAtModelBase ? g.lo.y : s.groundHeight;
    fadeCenter_ = g.center();
    fadeRadius_ = std::max(0.5f * glm::length(g.size()), 1e-6f);
    sunDir_ = directionFromAngles(s.sunAzimuthDeg, s.sunElevationDeg);
    sunCos_ = static_cast<float>(std::cos(radians(std::max(0.0, s.sunAngleDeg))));
    const Vec3 toViewer = camera.position - camera.target;
    const double cameraAzimuthDeg = std::atan2(double(toViewer.x), double(toViewer.z)) * (180.0 / kPi);
    rimDir_ = directionFromAngles(cameraAzimuthDeg + s.rimAzimuthDeg, s.rimElevationDeg);
    groundMaterial_.roughness = 1.0f;
    groundMaterial_.specular = 0.0f;
    if (filtersSky(s)) openSky_ = OpenSkyTable(s, sunDir_.y);
  }

  /// Radiance and alpha seen through film point (fx, fy), with the sky term and guides.
  SampleValue sample(float fx, float fy, const Strata& st, Rng& rng, Counters& c) const {
    Ray ray = film_.ray(fx, fy);
    ++c.camera;
    Vec3 bg = background(fy);
    float bgAlpha = s_.background == Background::Transparent ? 0.0f : 1.0f;

    float tGround = groundHit(ray.origin, ray.direction);
    // Widened thin curves (opacity < 1) are blended over what lies behind them, front to
    // back, for at most kLayers of them.
    constexpr int kLayers = 8;
    SampleValue out;
    float through = 1.0f;
    float tnear = 0.0f;
    for (int layer = 0;; ++layer) {
      std::optional<SurfaceHit> hit = scene_.intersect(ray.origin, ray.direction, tnear, kInf);
      if (!hit || hit->t > tGround) break;
      const Material& m = scene_.material(hit->material);
      ShadeParts parts;
      const Vec4 lit(shade(*hit, m, ray.direction, st, rng, c, parts), 1.0f);
      const bool last = hit->opacity >= 1.0f || layer + 1 == kLayers;
      out.add(parts, hit->position, last ? through : through * hit->opacity);
      if (last) {
        out.value += through * lit;
        return out;
      }
      out.value += through * hit->opacity * lit;
      through *= 1.0f - hit->opacity;
      tnear = hit->behind;
    }
    out.value += through * behindSurfaces(ray, tGround, bg, bgAlpha, st, rng, c, out, through);
    return out;
  }

 private:
  /// The ground or the background seen along ray; the ground's sky term goes into out
  /// with the given weight.
  Vec4 behindSurfaces(const Ray& ray, float tGround, const Vec3& bg, float bgAlpha, const Strata& st, Rng& rng,
                      Counters& c, SampleValue& out, float weight) const {
    if (tGround < kInf) {
      SurfaceHit g;
      g.t = tGround;
      g.position = ray.origin + tGround * ray.direction;
      g.position.y = groundY_;
      g.normal = g.geometricNormal = Vec3(0, 1, 0);
      g.color = s_.groundColor;
      ShadeParts parts;
      Vec3 lit = shade(g, groundMaterial_, ray.direction, st, rng, c, parts);
      // Fade the far ground into the background so the horizon is soft.
      float dist = glm::length(Vec3(g.position.x - fadeCenter_.x, 0, g.position.z - fadeCenter_.z)) / fadeRadius_;
      float f = std::clamp((dist - s_.groundFade) / (3.0f * s_.groundFade), 0.0f, 1.0f);
      f = f * f * (3.0f - 2.0f * f);
      out.add(parts, g.position, weight * (1.0f - f));
      return Vec4(glm::mix(lit, bg, f), bgAlpha + (1.0f - bgAlpha) * (1.0f - f));
    }
    return Vec4(bg, bgAlpha);
  }

  Vec3 background(float fy) const {
    switch (s_.background) {
      case Background::Color: return s_.backgroundColor;
      case Background::Gradient: return glm::mix(s_.backgroundTop, s_.backgroundBottom, std::clamp(fy / s_.height, 0.0f, 1.0f));
      case Background::Transparent: return Vec3(0);
    }
    return Vec3(0);
  }

  float groundHit(const Vec3& o, const Vec3& d) const {
    if (!s_.ground || o.y <= groundY_ || d.y >= 0.0f) return kInf;
    return (groundY_ - o.y) / d.y;
  }

  /// Sky radiance arriving from unit direction d at point from.
  Vec3 sky(const Vec3& d, const Vec3& from) const { return skyRadiance(s_, sunDir_.y, d, from.y > groundY_ - eps_); }

  /// Light leaving hit h toward -dir; its sky term and guides go into parts.
  Vec3 shade(SurfaceHit h, const Material& m, const Vec3& dir, const Strata& st, Rng& rng, Counters& c,
             ShadeParts& parts) const {
    // Face both normals toward the viewer: leaves and thin parts are two-sided.
    if (glm::dot(h.geometricNormal, dir) > 0.0f) h.geometricNormal = -h.geometricNormal;
    const bool backSide = glm::dot(h.normal, dir) > 0.0f;
    if (backSide) h.normal = -h.normal;
    const Vec3 n = h.normal, ng = h.geometricNormal, v = -dir;
    // A smooth coarse mesh's rays leave from above the smooth surface its normals describe.
    const Vec3 origin = h.position + (m.smoothTerminator ? h.terminatorLift[backSide ? 1 : 0] : Vec3(0)) + eps_ * ng;
    const Vec3 albedo = glm::clamp(h.color, Vec3(0), Vec3(1));
    // The hit's own surface (a mesh's per-vertex values) or the material's.
    const float roughness = h.ownSurface ? h.surface.x : m.roughness;
    const float specular = h.ownSurface ? h.surface.y : m.specular;
    const float metallic = std::clamp(h.ownSurface ? h.surface.z : m.metallic, 0.0f, 1.0f);
    // The metallic mix: the diffuse lobe scaled by 1 − metallic, the highlight's reflectance
    // tinted toward the base colour. Dielectrics (metallic 0) skip the mix, so their pixels
    // are the same as before metals existed.
    const bool metal = metallic > 0.0f;
    const Vec3 diffuse = metal ? (1.0f - metallic) * albedo : albedo;
    const Vec3 f0 = metal ? glm::mix(Vec3(specular), albedo, metallic) : Vec3(specular);
    Vec3 radiance(0);
    bool sunLit = false;

    if (s_.sun) {
      Vec2 u = sunSample(st, rng);
      Vec3 l = sunCos_ < 1.0f ? sampleCone(sunDir_, sunCos_, u) : sunDir_;
      float cosL = glm::dot(n, l);
      if (cosL > 0.0f && (m.smoothTerminator || glm::dot(ng, l) > -0.05f)) {
        bool lit = true;
        if (s_.shadows) {
          ++c.shadow;
          lit = !scene_.occluded(origin, l, 0.0f, kInf);
        }
        if (lit) {
          // Normalized Blinn-Phong; exponent from roughness (Walter et al. 2007 mapping).
          float r4 = std::max(std::pow(std::clamp(roughness, 0.02f, 1.0f), 4.0f), 1e-4f);
          float e = 2.0f / r4 - 2.0f;
          Vec3 hv = glm::normalize(l + v);
          Vec3 spec = e > 0.0f ? f0 * (e + 8.0f) / 8.0f * std::pow(std::max(0.0f, glm::dot(n, hv)), e) : Vec3(0);
          sunLit = true;
          radiance += s_.sunColor * s_.sunStrength * cosL * (diffuse + spec);
        }
      }
    }
    if (s_.skyStrength > 0.0f) {
      Vec3 skyLight(0);
      if (s_.skySamples <= 0) {
        skyLight = sky(n, h.position);
      } else {
        const int rays = sunLit ? s_.skySamples : std::max(s_.skySamples, s_.unlitSkySamples);
        for (int k = 0; k < rays; ++k) {
          Vec3 d = sampleCosine(n, skySample(st, k, rays, rng));
          if (glm::dot(d, ng) <= 0.0f) continue;
          ++c.sky;
          if (!scene_.occluded(origin, d, 0.0f, kInf)) skyLight += sky(d, h.position);
        }
        skyLight /= static_cast<float>(rays);
        parts.normal = n;
        parts.rays = static_cast<float>(rays);
        parts.sky = diffuse * skyLight * s_.skyStrength;
        // What the sky term is demodulated by besides the albedo: the open sky when filtered.
        const Vec3 open = openSky_.empty() ? Vec3(1) : openSky_(n) * s_.skyStrength;
        parts.albedo = diffuse * open;
        parts.irradianceLum = luminance(skyLight * s_.skyStrength / glm::max(open, Vec3(1e-6f)));
      }
      radiance += diffuse * skyLight * s_.skyStrength;
      if (metal) radiance += metallic * f0 * metalSky(n, ng, v, origin, h.position, roughness, skyLight, c) * s_.skyStrength;
    }
    if (s_.fillStrength > 0.0f) radiance += diffuse * s_.fillStrength * std::max(0.0f, glm::dot(n, v));
    if (s_.rimStrength > 0.0f) radiance += diffuse * rimLight(n, ng, origin, c);
    return radiance;
  }

  /// The sky a metal mirrors toward v: the sky along the reflected direction (occluded by the
  /// scene when the sky is sampled), blurred toward the diffuse sky irradiance as roughness
  /// rises (a rough metal reflects the whole hemisphere).
  Vec3 metalSky(const Vec3& n, const Vec3& ng, const Vec3& v, const Vec3& origin, const Vec3& at, float roughness,
                const Vec3& skyLight, Counters& c) const {
    const Vec3 r = glm::reflect(-v, n);
    Vec3 mirrored(0);
    if (glm::dot(r, ng) > 0.0f) {
      bool open = true;
      if (s_.skySamples > 0) {
        ++c.sky;
        open = !scene_.occluded(origin, r, 0.0f, kInf);
      }
      if (open) mirrored = sky(r, at);
    }
    return glm::mix(mirrored, skyLight, std::clamp(roughness, 0.0f, 1.0f));
  }

  /// Irradiance of the rim light at a point with shading normal n and geometric normal ng
  /// (Lambert, hard shadow from origin).
  Vec3 rimLight(const Vec3& n, const Vec3& ng, const Vec3& origin, Counters& c) const {
    const float cosL = glm::dot(n, rimDir_);
    if (cosL <= 0.0f || glm::dot(ng, rimDir_) <= -0.05f) return Vec3(0);
    if (s_.shadows) {
      ++c.shadow;
      if (scene_.occluded(origin, rimDir_, 0.0f, kInf)) return Vec3(0);
    }
    return s_.rimColor * s_.rimStrength * cosL;
  }

  const Scene& scene_;
  const RenderSettings& s_;
  const FilmRays film_;  ///< the camera's primary rays, set up once
  Vec3 center_{0};
  float radius_ = 1;
  Vec3 fadeCenter_{0};
  float fadeRadius_ = 1;
  float eps_ = 1e-4f;
  float groundY_ = 0;
  Vec3 sunDir_{0, 1, 0};
  float sunCos_ = 1;
  Vec3 rimDir_{0, 0, -1};  ///< toward the rim light (RenderSettings::rimAzimuthDeg from the camera's azimuth)
  /// The ground's material, made once: a Material holds a seeded RidgeShade, whose noise
  /// table costs a 256-entry shuffle to build (once per ground hit, it was 15 % of a tree's
  /// exact render).
  Material groundMaterial_;
  OpenSkyTable openSky_;  ///< when the sky is filtered
};

struct FilmSample {
  float x, y;
  SampleValue value;
};

/// Adds one of pixel i's own samples to the sky filter's variance sums, if it met a surface.
void addOwnSample(SkyLayers& layers, size_t i, const SampleValue& v) {
  if (v.normal == Vec3(0)) return;
  layers.lumSum[i] += v.irradianceLum;
  layers.lumSquares[i] += v.irradianceLum * v.irradianceLum;
  layers.raySum[i] += v.skyRays;
  layers.count[i] += 1.0f;
}

/// The traced samples of one tile's own pixels [x0, x1) x [y0, y1). Pixels hold spp
/// samples each, or more where adaptive sampling added some (RenderSettings::edgeSamples):
/// samples of pixel i are [first[i], first[i + 1]).
struct TileFilm {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  std::vector<FilmSample> samples;
  std::vector<uint32_t> first;

  TileFilm() = default;
  TileFilm(int x0_, int y0_, int x1_, int y1_, int spp) : x0(x0_), y0(y0_), x1(x1_), y1(y1_) {
    const size_t pixels = static_cast<size_t>(x1 - x0) * (y1 - y0);
    samples.reserve(pixels * spp);
    first.reserve(pixels + 1);
    first.push_back(0);
  }

  size_t index(int x, int y) const { return static_cast<size_t>(y - y0) * (x1 - x0) + (x - x0); }
  const FilmSample* pixel(int x, int y) const { return samples.data() + first[index(x, y)]; }
  int count(int x, int y) const {
    const size_t i = index(x, y);
    return static_cast<int>(first[i + 1] - first[i]);
  }

  /// Keeps the samples of the pixels `keep` says yes to (in pixel order); the others'
  /// ranges become empty. Frees the rest.
  template <class Keep>
  void keepOnly(Keep&& keep) {
    std::vector<FilmSample> kept;
    std::vector<uint32_t> starts{0};
    starts.reserve(first.size());
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) {
        if (keep(x, y)) kept.insert(kept.end(), pixel(x, y), pixel(x, y) + count(x, y));
        starts.push_back(static_cast<uint32_t>(kept.size()));
      }
    samples = std::move(kept);
    first = std::move(starts);
  }

  void release() {
    std::vector<FilmSample>().swap(samples);
    std::vector<uint32_t>().swap(first);
  }
};

/// The films of all tiles and the reconstruction of pixels from them: a pixel's filter
/// reads the samples of its neighbours up to `apron` pixels away, which may lie in
/// neighbouring tiles (each pixel is traced once, by its own tile).
class FilmGrid {
 public:
  FilmGrid(int width, int height, int spp, float radius, bool tent, int tile)
      : width_(width), height_(height), spp_(spp), tile_(tile), tent_(tent), radius_(radius),
        apron_(tent ? static_cast<int>(std::ceil(radius - 0.5f)) : 0),
        tilesX_((width + tile - 1) / tile), tilesY_((height + tile - 1) / tile),
        films_(static_cast<size_t>(tilesX_) * tilesY_) {}

  size_t tileCount() const { return films_.size(); }
  /// How many tiles around a tile its pixels' filters reach, per axis.
  int tileReach() const { return (apron_ + tile_ - 1) / tile_; }

  /// A new, empty film for tile t's own pixels.
  TileFilm& start(size_t t) {
    const int x0 = static_cast<int>(t % tilesX_) * tile_, y0 = static_cast<int>(t / tilesX_) * tile_;
    films_[t] = TileFilm(x0, y0, std::min(x0 + tile_, width_), std::min(y0 + tile_, height_), spp_);
    return films_[t];
  }
  TileFilm& film(size_t t) { return films_[t]; }

  /// Calls f(u) for every tile u within tileReach() of tile t (t included), in row order.
  template <class F>
  void forNeighbours(size_t t, F&& f) const {
    const int r = tileReach(), tx = static_cast<int>(t % tilesX_), ty = static_cast<int>(t / tilesX_);
    for (int y = std::max(0, ty - r); y <= std::min(tilesY_ - 1, ty + r); ++y)
      for (int x = std::max(0, tx - r); x <= std::min(tilesX_ - 1, tx + r); ++x) f(static_cast<size_t>(y) * tilesX_ + x);
  }

  /// Whether pixel (x, y)'s filter reads only pixels of its own tile film f.
  bool readsOwnTile(const TileFilm& f, int x, int y) const { return staysInTile(f, x, y, apron_); }

  /// Whether only pixels of f itself read pixel (x, y): the pixels a border pixel of f reads
  /// lie within twice the filter's reach of f's edges.
  bool readByOwnTileOnly(const TileFilm& f, int x, int y) const { return staysInTile(f, x, y, 2 * apron_); }

  /// Writes pixel (x, y) of image (scaled by exposure) and, when layers is given, its sky
  /// term and guides, reconstructed with the filter over the samples of the pixels around
  /// it, whichever tile holds them. A pixel with more samples than spp weighs each of them
  /// spp/count, so every pixel's samples weigh alike in total.
  void reconstruct(int x, int y, float exposure, Image& image, SkyLayers* layers) const {
    Vec4 sum(0);
    Vec3 sky(0), albedo(0), normal(0), position(0);
    float wsum = 0, wsurface = 0;
    const float cx = static_cast<float>(x) + 0.5f, cy = static_cast<float>(y) + 0.5f;
    for (int ny = std::max(0, y - apron_); ny <= std::min(height_ - 1, y + apron_); ++ny) {
      for (int nx = std::max(0, x - apron_); nx <= std::min(width_ - 1, x + apron_); ++nx) {
        const TileFilm& f = filmOf(nx, ny);
        const FilmSample* in = f.pixel(nx, ny);
        const int n = f.count(nx, ny);
        const float share = n == spp_ ? 1.0f : static_cast<float>(spp_) / static_cast<float>(n);
        for (int k = 0; k < n; ++k) {
          const float w = share * weight(in[k], cx, cy);
          const SampleValue& v = in[k].value;
          sum += w * v.value;
          wsum += w;
          if (!layers || v.normal == Vec3(0)) continue;
          sky += w * v.sky;
          albedo += w * v.albedo;
          normal += w * v.normal;
          position += w * v.position;
          wsurface += w;
        }
      }
    }
    const Vec4 value = wsum > 0 ? sum / wsum : Vec4(0);
    image.set(x, y, Vec4(Vec3(value) * exposure, value.a));
    if (!layers || !(wsum > 0)) return;
    const size_t i = layers->index(x, y);
    layers->weight[i] = wsum;
    layers->sky[i] = sky * (exposure / wsum);
    layers->albedo[i] = albedo / wsum;
    layers->normal[i] = normal;
    if (wsurface > 0) layers->position[i] = position / wsurface;
    const TileFilm& f = filmOf(x, y);
    const FilmSample* own = f.pixel(x, y);
    for (int k = 0, n = f.count(x, y); k < n; ++k) addOwnSample(*layers, i, own[k].value);
  }

  /// How many pixels from its own a sample's weight reaches (0 for the box filter).
  int apron() const { return apron_; }

  /// The filter's weight of sample f for the pixel centred at (cx, cy).
  float weight(const FilmSample& f, float cx, float cy) const {
    if (!tent_) return 1.0f;
    return std::max(0.0f, 1.0f - std::abs(f.x - cx) / radius_) * std::max(0.0f, 1.0f - std::abs(f.y - cy) / radius_);
  }

 private:
  /// Whether the pixels within `reach` of (x, y) (clamped to the image) all lie in f.
  bool staysInTile(const TileFilm& f, int x, int y, int reach) const {
    return std::max(0, x - reach) >= f.x0 && std::min(width_ - 1, x + reach) < f.x1 &&
           std::max(0, y - reach) >= f.y0 && std::min(height_ - 1, y + reach) < f.y1;
  }

  const TileFilm& filmOf(int x, int y) const {
    return films_[static_cast<size_t>(y / tile_) * tilesX_ + static_cast<size_t>(x / tile_)];
  }

  int width_, height_, spp_, tile_;
  bool tent_;
  float radius_;
  int apron_;
  int tilesX_, tilesY_;
  std::vector<TileFilm> films_;
};

/// The first pass's sample sequences, made in one place so that the second pass traces a
/// pixel's first pass again exactly: the base samples, and the edge samples' own Sobol'
/// sequence (the base pass's next samples would break its per-pixel blocks; another seed
/// gives independent, equally stratified points). Each thread traces with its own copy.
struct FirstPassSamplers {
  ZSobolSampler base, extra;
  bool sobol;  ///< RenderSettings::sampler is ZSobol; else stratified samples, no sequence
  explicit FirstPassSamplers(const RenderSettings& s)
      : base(s.width, s.height, s.spp, s.seed),
        extra(s.width, s.height, std::max(1, s.edgeSamples), deriveSeed(s.seed, {0xed9e})),
        sobol(s.sampler == Sampling::ZSobol) {}
};

/// Appends n camera samples of pixel (x, y) to out: their film points from sobol when
/// given (else a jittered grid from the pixel's generator, seeded by (x, y, pass)) and the
/// values seen there.
void traceSamples(const Integrator& integrator, const RenderSettings& s, int x, int y, int n, uint64_t pass,
                  ZSobolSampler* sobol, std::vector<FilmSample>& out, Counters& c) {
  const std::initializer_list<uint64_t> key = {static_cast<uint64_t>(x), static_cast<uint64_t>(y)};
  const std::initializer_list<uint64_t> passKey = {static_cast<uint64_t>(x), static_cast<uint64_t>(y), pass};
  Rng rng(deriveSeed(s.seed, pass == 0 ? key : passKey));
  Strata st;
  st.spp = n;
  st.sobol = sobol;
  if (!sobol) {
    st.sunShift = static_cast<int>(rng.below(static_cast<uint32_t>(n)));
    st.skyShift = static_cast<int>(rng.below(static_cast<uint32_t>(n * std::max(1, s.skySamples))));
  }
  const int gx = std::max(1, static_cast<int>(std::floor(std::sqrt(static_cast<double>(n)))));
  const int gy = (n + gx - 1) / gx;
  for (int k = 0; k < n; ++k) {
    Vec2 f;
    if (sobol) {
      sobol->startPixelSample(x, y, k);
      f = sobol->get2D();
    } else {
      float jx = next(rng), jy = next(rng);
      f = Vec2((static_cast<float>(k % gx) + jx) / static_cast<float>(gx), (static_cast<float>(k / gx) + jy) / static_cast<float>(gy));
    }
    const float fx = static_cast<float>(x) + f.x, fy = static_cast<float>(y) + f.y;
    st.sample = k;
    out.push_back({fx, fy, integrator.sample(fx, fy, st, rng, c)});
  }
}

/// Whether the n samples at f disagree by more than threshold in display luminance
/// (about gamma 2, after exposure), with their sky terms' noise taken out: each sample's sky
/// term is replaced by its albedo times the samples' mean sky irradiance. What is left to
/// differ is geometry, texture and the sun's visibility.
bool samplesDisagree(const FilmSample* f, int n, float exposure, float threshold) {
  Vec3 skySum(0), albedoSum(0);
  for (int k = 0; k < n; ++k) {
    skySum += f[k].value.sky;
    albedoSum += f[k].value.albedo;
  }
  Vec3 irradiance(0);
  for (int ch = 0; ch < 3; ++ch)
    if (albedoSum[ch] > 0) irradiance[ch] = skySum[ch] / albedoSum[ch];
  float lo = std::numeric_limits<float>::infinity(), hi = -lo;
  for (int k = 0; k < n; ++k) {
    const SampleValue& v = f[k].value;
    const Vec3 c = (Vec3(v.value) - v.sky + v.albedo * irradiance) * exposure;
    const float l = std::sqrt(std::max(0.0f, 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b));
    lo = std::min(lo, l);
    hi = std::max(hi, l);
  }
  return hi - lo > threshold;
}

/// Traces pixel (x, y) into the film: s.spp samples, and s.edgeSamples more where those
/// disagree. Every decision reads the pixel's own samples only, so the image does not
/// depend on which thread traces which tile.
void tracePixel(const Integrator& integrator, const RenderSettings& s, int x, int y, FirstPassSamplers& samplers,
                float exposure, std::vector<FilmSample>& out, Counters& c) {
  const size_t begin = out.size();
  traceSamples(integrator, s, x, y, s.spp, 0, samplers.sobol ? &samplers.base : nullptr, out, c);
  if (s.edgeSamples > 0 && samplesDisagree(out.data() + begin, s.spp, exposure, s.edgeThreshold))
    traceSamples(integrator, s, x, y, s.edgeSamples, 1, samplers.sobol ? &samplers.extra : nullptr, out, c);
}

/// Tiles are traced in row order by whichever thread is free, each pixel once, by its own
/// tile. A pixel is reconstructed as soon as every pixel its filter reads is traced: one
/// that reads only its own tile right after that tile, the rest (the tile's border,
/// `apron` pixels wide) once every neighbouring tile is traced, by the thread that traced
/// the last of them. Until then a tile keeps the samples its border and its neighbours'
/// read (2 x apron wide) and frees the rest; it frees those when the last tile reading
/// them is reconstructed, so the borders alive are about two rows of tiles.
class TileSchedule {
 public:
  explicit TileSchedule(FilmGrid& grid) : grid_(grid), pending_(grid.tileCount()), readers_(grid.tileCount()) {
    for (size_t t = 0; t < grid.tileCount(); ++t) {
      int n = 0;
      grid.forNeighbours(t, [&](size_t) { ++n; });
      pending_[t].store(n, std::memory_order_relaxed);
      readers_[t].store(n, std::memory_order_relaxed);
    }
  }

  /// The next tile to trace, in row order.
  size_t claim() { return next_.fetch_add(1, std::memory_order_relaxed); }

  /// Tile t is traced and holds only its border: calls border(u) for every tile u whose
  /// neighbours are now all traced, then frees the borders no tile reads any more.
  template <class F>
  void traced(size_t t, F&& border) {
    grid_.forNeighbours(t, [&](size_t u) {
      if (pending_[u].fetch_sub(1, std::memory_order_acq_rel) != 1) return;
      border(grid_.film(u));
      grid_.forNeighbours(u, [&](size_t v) {
        if (readers_[v].fetch_sub(1, std::memory_order_acq_rel) == 1) grid_.film(v).release();
      });
    });
  }

 private:
  FilmGrid& grid_;
  std::vector<std::atomic<int>> pending_;  ///< per tile: neighbours (itself included) not yet traced
  std::vector<std::atomic<int>> readers_;  ///< per tile: neighbours whose border is not yet reconstructed
  std::atomic<size_t> next_{0};
};

/// Reconstructs the pixels of film f that `own` says read only their own tile (true) or
/// not (false).
void reconstructTile(const FilmGrid& grid, const TileFilm& f, bool own, float exposure, Image& image,
                     SkyLayers* layers) {
  for (int y = f.y0; y < f.y1; ++y)
    for (int x = f.x0; x < f.x1; ++x)
      if (grid.readsOwnTile(f, x, y) == own) grid.reconstruct(x, y, exposure, image, layers);
}

/// The pixels whose sky term the filter leaves noisy: those where the standard deviation
/// of the filtered term (its luminance, through the filter's variance estimate) exceeds
/// threshold in display units (about gamma 2: d sqrt(L) = dL / (2 sqrt(L)), with L the
/// filtered pixel's luminance, at least 1e-3 so that black pixels do not all qualify).
std::vector<uint8_t> noisyPixels(const Image& image, const SkyLayers& layers, float threshold) {
  const FilteredSky f = filterSky(layers);
  std::vector<uint8_t> noisy(layers.sky.size(), 0);
  for (int y = 0; y < layers.height; ++y) {
    for (int x = 0; x < layers.width; ++x) {
      const size_t i = layers.index(x, y);
      if (!hasSkyTerm(layers, i)) continue;
      const float sd = luminance(layers.albedo[i]) * std::sqrt(std::max(f.variance[i], 0.0f));
      const Vec3 c = Vec3(image.at(x, y)) - layers.sky[i] + filteredSkyTerm(layers, i, f.irradiance[i]);
      noisy[i] = sd > 2.0f * threshold * std::sqrt(std::max(luminance(c), 1e-3f));
    }
  }
  return noisy;
}

/// The second pass's samples (RenderSettings::refineSamples) of one row: for each marked
/// pixel, its first pass's samples traced again (the same points and values: every sample
/// is a function of (seed, x, y, k)) followed by its new ones; samples of pixel x are
/// [first[x], first[x + 1]), the first old[x] of them the first pass's.
struct RefineRow {
  std::vector<FilmSample> samples;
  std::vector<uint32_t> first;
  std::vector<uint32_t> old;
};

/// The second pass's samples of every row: marked pixels get their first pass again and
/// s.refineSamples more from a Sobol' sequence of their own; rows in parallel, each
/// advancing progress by one.
std::vector<RefineRow> traceRefineSamples(const Integrator& integrator, const RenderSettings& s,
                                          const std::vector<uint8_t>& marked, float exposure,
                                          std::atomic<uint64_t> (&rays)[3], Progress* progress) {
  std::vector<RefineRow> rows(static_cast<size_t>(s.height));
  const FirstPassSamplers firstPass(s);
  const ZSobolSampler sobolRefine(s.width, s.height, s.refineSamples, deriveSeed(s.seed, {0x5e1f}));
  parallelFor(0, rows.size(), [&](size_t row) {
    const int y = static_cast<int>(row);
    FirstPassSamplers first = firstPass;
    ZSobolSampler refine = sobolRefine;
    RefineRow& r = rows[row];
    r.first.assign(1, 0);
    r.old.assign(static_cast<size_t>(s.width), 0);
    Counters c;
    for (int x = 0; x < s.width; ++x) {
      if (marked[row * static_cast<size_t>(s.width) + static_cast<size_t>(x)]) {
        tracePixel(integrator, s, x, y, first, exposure, r.samples, c);
        r.old[static_cast<size_t>(x)] = static_cast<uint32_t>(r.samples.size() - r.first.back());
        traceSamples(integrator, s, x, y, s.refineSamples, 2, first.sobol ? &refine : nullptr, r.samples, c);
      }
      r.first.push_back(static_cast<uint32_t>(r.samples.size()));
    }
    c.addTo(rays);
    if (progress) progress->advance();
  });
  return rows;
}

/// Adds the second pass to pixel (x, y). The first pass weighed each sample of a pixel with
/// n samples spp / n times the filter's weight; a marked pixel now has n + refineSamples,
/// so its old samples' share changes to spp / (n + refineSamples) and its new ones come in
/// at that share: every pixel's samples still weigh spp in all, and a pixel's neighbours
/// are not pulled toward it. Its sky term and albedo change likewise; its variance sums gain
/// its own new samples that met a surface.
void addRefineSamples(const FilmGrid& grid, const std::vector<RefineRow>& rows, int spp, int x, int y, float exposure,
                      Image& image, SkyLayers& layers) {
  const int r = grid.apron();
  const float cx = static_cast<float>(x) + 0.5f, cy = static_cast<float>(y) + 0.5f;
  Vec4 value(0);
  Vec3 sky(0), albedo(0);
  float wsum = 0;
  bool any = false;
  for (int ny = std::max(0, y - r); ny <= std::min(layers.height - 1, y + r); ++ny) {
    const RefineRow& row = rows[static_cast<size_t>(ny)];
    for (int nx = std::max(0, x - r); nx <= std::min(layers.width - 1, x + r); ++nx) {
      const uint32_t begin = row.first[static_cast<size_t>(nx)], end = row.first[static_cast<size_t>(nx) + 1];
      if (begin == end) continue;
      any = true;
      const uint32_t old = row.old[static_cast<size_t>(nx)];
      const float share = static_cast<float>(spp) / static_cast<float>(end - begin);
      const float oldShare = static_cast<float>(spp) / static_cast<float>(old);
      for (uint32_t k = begin; k < end; ++k) {
        const FilmSample& f = row.samples[k];
        const float w = (k - begin < old ? share - oldShare : share) * grid.weight(f, cx, cy);
        value += w * f.value.value;
        sky += w * f.value.sky;
        albedo += w * f.value.albedo;
        wsum += w;
      }
    }
  }
  const size_t i = layers.index(x, y);
  if (!any) return;
  const float w0 = layers.weight[i], total = w0 + wsum;
  if (!(total > 0)) return;
  const Vec4 before = image.at(x, y);
  image.set(x, y, Vec4(glm::max((w0 * Vec3(before) + exposure * Vec3(value)) / total, Vec3(0)),
                       std::clamp((w0 * before.a + value.a) / total, 0.0f, 1.0f)));
  layers.sky[i] = glm::max((w0 * layers.sky[i] + exposure * sky) / total, Vec3(0));
  layers.albedo[i] = glm::max((w0 * layers.albedo[i] + albedo) / total, Vec3(0));
  layers.weight[i] = total;
  const RefineRow& own = rows[static_cast<size_t>(y)];
  const uint32_t begin = own.first[static_cast<size_t>(x)] + own.old[static_cast<size_t>(x)];
  for (uint32_t k = begin; k < own.first[static_cast<size_t>(x) + 1]; ++k) addOwnSample(layers, i, own.samples[k].value);
}

/// The second pass (RenderSettings::refineSamples): more samples for every pixel
/// noisyPixels marks, added to the image and the layers of every pixel whose filter reaches
/// them. Deterministic: the marks read the whole first pass, each pixel gathers.
void refinePixels(const Integrator& integrator, const RenderSettings& s, const FilmGrid& grid, float exposure,
                  Image& image, SkyLayers& layers, std::atomic<uint64_t> (&rays)[3], Progress* progress) {
  const std::vector<RefineRow> rows =
      traceRefineSamples(integrator, s, noisyPixels(image, layers, s.refineThreshold), exposure, rays, progress);
  parallelFor(0, static_cast<size_t>(s.height), [&](size_t row) {
    for (int x = 0; x < s.width; ++x) addRefineSamples(grid, rows, s.spp, x, static_cast<int>(row), exposure, image, layers);
  });
}

}  // namespace

Image renderImage(const Scene& scene, const Camera& camera, const RenderSettings& s, RenderStats* stats) {
  if (s.width < 1 || s.height < 1) throw std::invalid_argument("render: image size must be at least 1x1");
  if (s.spp < 1) throw std::invalid_argument("render: samples per pixel must be at least 1");
  if (s.tileSize < 1) throw std::invalid_argument("render: the tile size must be at least 1 pixel");
  // Every ray starts at the camera or on the scene: both must lie where Embree traces.
  if (std::string why = cameraProblem(camera); !why.empty()) throw std::invalid_argument("render: " + why);
  if (!boxInRenderRange(scene.bounds()))
    throw std::invalid_argument("render: the scene's bounds are not finite or lie beyond 1e15");
  auto start = std::chrono::steady_clock::now();
  std::unique_ptr<ThreadLimit> limit;
  if (s.threads > 0) limit = std::make_unique<ThreadLimit>(s.threads);

  Integrator integrator(scene, camera, s);
  const bool tent = s.filter == Filter::Tent && s.filterRadius > 0.5f;
  const float radius = tent ? s.filterRadius : 0.5f;
  const int spp = s.spp;
  const FirstPassSamplers firstPass(s);

  FilmGrid grid(s.width, s.height, spp, radius, tent, s.tileSize);
  TileSchedule schedule(grid);
  Image image(s.width, s.height);
  std::atomic<uint64_t> rays[3] = {0, 0, 0};  // camera, shadow, sky
  const float scale = std::exp2(s.exposure);
  // The sky filter's layers, where the sky is sampled by rays (its only noise).
  std::optional<SkyLayers> layers;
  if (filtersSky(s)) layers.emplace(s.width, s.height);
  const bool refining = layers && s.refineSamples > 0;
  // One bar: the tiles, then the second pass's rows.
  std::optional<Progress> progress;
  if (s.progress) progress.emplace(s.progressLabel, grid.tileCount() + (refining ? static_cast<size_t>(s.height) : 0));
  SkyLayers* out = layers ? &*layers : nullptr;

  parallelFor(0, grid.tileCount(), [&](size_t) {
    const size_t tile = schedule.claim();
    TileFilm& film = grid.start(tile);
    FirstPassSamplers samplers = firstPass;
    Counters c;
    for (int y = film.y0; y < film.y1; ++y)
      for (int x = film.x0; x < film.x1; ++x) {
        tracePixel(integrator, s, x, y, samplers, scale, film.samples, c);
        film.first.push_back(static_cast<uint32_t>(film.samples.size()));
      }
    reconstructTile(grid, film, true, scale, image, out);
    film.keepOnly([&](int x, int y) { return !grid.readByOwnTileOnly(film, x, y); });
    schedule.traced(tile, [&](const TileFilm& ready) { reconstructTile(grid, ready, false, scale, image, out); });
    c.addTo(rays);
    if (progress) progress->advance();
  });
  if (refining) refinePixels(integrator, s, grid, scale, image, *layers, rays, progress ? &*progress : nullptr);
  if (progress) progress->finish();
  if (layers) filterSkyTerm(image, *layers);
  drawLabels(image, scene.labels(), camera);

  if (stats) {
    stats->cameraRays = rays[0];
    stats->shadowRays = rays[1];
    stats->skyRays = rays[2];
    stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return image;
}

Vec3 openSkyIrradiance(const RenderSettings& s, const Vec3& n) {
  const Vec3 sunDir = directionFromAngles(s.sunAzimuthDeg, s.sunElevationDeg);
  return OpenSkyTable(s, sunDir.y)(n);
}

}  // namespace sprig::render
