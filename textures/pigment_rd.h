#pragma once
/// Shell pigmentation by an activator-inhibitor reaction along the growing edge.
///
/// Meinhardt, "The Algorithmic Beauty of Sea Shells" (1995), Eq. 2.1 with the activator
/// saturation of Eq. 2.5: a shell adds material only at its growing edge, so the pattern
/// on the finished shell is the space-time plot of a one-dimensional reaction-diffusion
/// system. Each row of the result is one moment of growth (v, from apex to aperture); each
/// column one cell along the periodic generating curve (u).
///
///   ∂a/∂t = s·(a²/b + bₐ)/(1 + κ·a²) − rₐ·a + Dₐ·∂²a/∂x²
///   ∂b/∂t = s·a² − r_b·b + D_b·∂²b/∂x² + b_b
///
/// s is the source density, fluctuating from cell to cell by ±sourceNoise (seeded). The
/// explicit scheme is deterministic and single-threaded per simulation: same options, same
/// bytes.

#include <cstdint>
#include <vector>

namespace sprig::textures {

/// Parameters of the activator-inhibitor simulation; the defaults give stable stripes along
/// the growth direction (Meinhardt Fig. 2.3); r_b < rₐ gives travelling waves (oblique lines).
struct PigmentRdOptions {
  int cells = 160;            ///< cells around the growing edge (periodic); ≥ 3
  int rows = 256;             ///< rows of output (growth stages); ≥ 1
  int stepsPerRow = 12;       ///< integration steps between output rows; ≥ 1
  double dt = 0.5;            ///< time step; explicit stability needs dt·max(Dₐ, D_b) < 0.5
  double diffusionA = 0.01;   ///< Dₐ, activator diffusion (cells²/time)
  double diffusionB = 0.4;    ///< D_b, inhibitor diffusion (cells²/time)
  double decayA = 0.05;       ///< rₐ
  double decayB = 0.08;       ///< r_b
  double baseA = 0.005;       ///< bₐ, basic activator production
  double baseB = 0.0;         ///< b_b, basic inhibitor production
  double saturation = 0.0;    ///< κ, activator saturation
  double sourceNoise = 0.05;  ///< relative fluctuation of s between cells, uniform in ±sourceNoise
  int warmupRows = 40;        ///< rows simulated before output starts (the larval shell)
  uint64_t seed = 1;          ///< seed of the source-density fluctuation
};

/// A simulated pattern: `rows` × `cells` activator values normalized to [0, 1].
struct PigmentPattern {
  int width = 0;              ///< cells around the edge (u)
  int height = 0;             ///< rows along growth (v)
  std::vector<float> values;  ///< row-major, values[v * width + u]
  float rawMin = 0, rawMax = 0;  ///< activator range before normalization

  /// Bilinear lookup; u wraps (the edge is closed), v clamps. u, v in [0, 1].
  float sample(double u, double v) const;
};

/// Runs the simulation. Throws std::invalid_argument on options outside their documented
/// ranges (callers validate user input first). Cost O(rows·stepsPerRow·cells).
PigmentPattern simulatePigment(const PigmentRdOptions& options);

/// The homogeneous steady state (a*, b*) of the noise-free system (s = 1): b* = (a*² + b_b)/r_b
/// and a* the positive root of the activator equation, found by bisection; for κ = 0 and
/// b_b = 0 it is a* = (r_b + bₐ)/rₐ. The simulation starts from it.
void pigmentSteadyState(const PigmentRdOptions& options, double& a, double& b);

}  // namespace sprig::textures
