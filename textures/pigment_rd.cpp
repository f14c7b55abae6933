#include "textures/pigment_rd.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/rng.h"

namespace sprig::textures {

namespace {

// Activator production minus decay at a homogeneous state with source density s.
double activatorRate(const PigmentRdOptions& o, double s, double a) {
  const double b = (s * a * a + o.baseB) / o.decayB;
  return s * (a * a / b + o.baseA) / (1.0 + o.saturation * a * a) - o.decayA * a;
}

}  // namespace

void pigmentSteadyState(const PigmentRdOptions& o, double& a, double& b) {
  // The rate is positive for small a (production bₐ dominates) and negative for large a
  // (linear decay beats the saturating production), so bisection brackets the root.
  double lo = 1e-9, hi = 1.0;
  while (activatorRate(o, 1.0, hi) > 0.0 && hi < 1e12) hi *= 2.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (activatorRate(o, 1.0, mid) > 0.0 ? lo : hi) = mid;
  }
  a = 0.5 * (lo + hi);
  b = (a * a + o.baseB) / o.decayB;
}

float PigmentPattern::sample(double u, double v) const {
  if (width <= 0 || height <= 0) return 0.0f;
  const double x = (u - std::floor(u)) * width - 0.5;
  const double y = std::clamp(v, 0.0, 1.0) * (height - 1);
  const int x0 = static_cast<int>(std::floor(x));
  const int y0 = std::min(static_cast<int>(y), height - 1);
  const int y1 = std::min(y0 + 1, height - 1);
  const double fx = x - x0, fy = y - y0;
  auto at = [&](int xi, int yi) { return values[static_cast<size_t>(yi) * width + ((xi % width) + width) % width]; };
  const double top = at(x0, y0) * (1 - fx) + at(x0 + 1, y0) * fx;
  const double bot = at(x0, y1) * (1 - fx) + at(x0 + 1, y1) * fx;
  return static_cast<float>(top * (1 - fy) + bot * fy);
}

PigmentPattern simulatePigment(const PigmentRdOptions& o) {
  if (o.cells < 3 || o.rows < 1 || o.stepsPerRow < 1 || o.warmupRows < 0 || !(o.dt > 0))
    throw std::invalid_argument("simulatePigment: cells >= 3, rows >= 1, stepsPerRow >= 1, dt > 0 required");
  if (o.dt * std::max(o.diffusionA, o.diffusionB) >= 0.5)
    throw std::invalid_argument("simulatePigment: dt * diffusion must stay below 0.5 for stability");
  if (!(o.decayA > 0) || !(o.decayB > 0)) throw std::invalid_argument("simulatePigment: decay rates must be > 0");

  const int n = o.cells;
  std::vector<double> a(n), b(n), s(n), na(n), nb(n);
  double a0, b0;
  pigmentSteadyState(o, a0, b0);
  Rng rng(deriveSeed(o.seed, {0x5e11ull}));
  for (int i = 0; i < n; ++i) {
    s[i] = 1.0 + o.sourceNoise * (2.0 * rng.uniform() - 1.0);
    a[i] = a0;
    b[i] = b0;
  }

  PigmentPattern out;
  out.width = n;
  out.height = o.rows;
  out.values.resize(static_cast<size_t>(n) * o.rows);
  std::vector<double> raw(out.values.size());

  const int totalRows = o.warmupRows + o.rows;
  for (int row = 0; row < totalRows; ++row) {
    for (int step = 0; step < o.stepsPerRow; ++step) {
      for (int i = 0; i < n; ++i) {
        const int l = (i + n - 1) % n, r = (i + 1) % n;
        const double lapA = a[l] - 2.0 * a[i] + a[r];
        const double lapB = b[l] - 2.0 * b[i] + b[r];
        const double prod = s[i] * (a[i] * a[i] / b[i] + o.baseA) / (1.0 + o.saturation * a[i] * a[i]);
        na[i] = a[i] + o.dt * (prod - o.decayA * a[i] + o.diffusionA * lapA);
        nb[i] = b[i] + o.dt * (s[i] * a[i] * a[i] - o.decayB * b[i] + o.diffusionB * lapB + o.baseB);
        nb[i] = std::max(nb[i], 1e-9);
        na[i] = std::max(na[i], 0.0);
      }
      a.swap(na);
      b.swap(nb);
    }
    if (row >= o.warmupRows) std::copy(a.begin(), a.end(), raw.begin() + static_cast<size_t>(row - o.warmupRows) * n);
  }

  const auto [mn, mx] = std::minmax_element(raw.begin(), raw.end());
  out.rawMin = static_cast<float>(*mn);
  out.rawMax = static_cast<float>(*mx);
  const double span = *mx - *mn;
  for (size_t i = 0; i < raw.size(); ++i)
    out.values[i] = span > 1e-12 ? static_cast<float>((raw[i] - *mn) / span) : 0.0f;
  return out;
}

}  // namespace sprig::textures
