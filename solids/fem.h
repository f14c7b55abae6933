#pragma once
/// Linear-elastic finite elements on a tetrahedral mesh (the simulation behind the hammer
/// and displace operators of Cutler et al., "A procedural approach to authoring solid
/// models", §3.1 and §5.2).
///
/// Elements are constant-strain (linear, 4-node) tetrahedra (Zienkiewicz and Taylor, "The
/// Finite Element Method", vol. 1, ch. 6; Hughes, "The Finite Element Method", §3.7): the
/// displacement is linear in each tetrahedron, so strain and stress are constant there.
/// With g_a = ∇N_a the gradient of node a's shape function (rows of J⁻¹, J = [x1−x0, x2−x0,
/// x3−x0], g_0 = −g_1 − g_2 − g_3) and V the volume, the 3×3 block of the element stiffness
/// coupling nodes a and b is
///     K_ab = V·(λ·g_a g_bᵀ + μ·g_b g_aᵀ + μ·(g_a·g_b)·I),
/// λ = Eν/((1+ν)(1−2ν)), μ = E/(2(1+ν)) (the Lamé constants of the tetrahedron's material),
/// which equals V·Bᵀ D B with the usual 6×12 strain matrix B and isotropic D.
///
/// Units are SI: positions are read as metres, Young's modulus and stress Pa, forces N,
/// displacements m, densities kg/m³ (the units of solids/material.h).
///
/// Fixed degrees of freedom are eliminated (their columns move to the right-hand side with
/// their prescribed values), not penalized; the free system is solved by conjugate
/// gradients. Assembly is parallel over vertices, each row summed over the vertex's
/// tetrahedra in index order, and CG's products (with Jacobi) over columns, each summed by
/// one thread, so the matrix and every result are the same bytes at any thread count.

#include <array>
#include <cstdint>
#include <vector>

#include "solids/material.h"
#include "solids/solid.h"

namespace sprig::solids {

/// Preconditioner of the conjugate-gradient solve.
enum class Preconditioner {
  Jacobi,             ///< the inverse diagonal
  IncompleteCholesky  ///< Eigen's IncompleteCholesky (zero fill, AMD ordering, diagonal shift)
};

/// Options of solveElastic.
struct FemOptions {
  /// Jacobi: IncompleteCholesky takes fewer iterations (2.2× fewer on bench_fem's slab of
  /// 300,000 tetrahedra, 7% fewer on the cantilever test) but each costs more: it took
  /// 1.1-1.2× the CPU time on the slab and 2-3× the time on the cantilever
  /// (docs/PERFORMANCE.md). With Jacobi, CG's sparse products run in parallel.
  Preconditioner preconditioner = Preconditioner::Jacobi;
  /// Stop when ‖b − K·u‖ / ‖b‖ falls below this (Eigen's ConjugateGradient criterion).
  double tolerance = 1e-8;
  /// Iteration cap; 0 = twice the number of free degrees of freedom (Eigen's default).
  int maxIterations = 0;
  /// Throw std::runtime_error when the tolerance is not reached within the cap (otherwise
  /// the result carries converged = false).
  bool requireConvergence = true;
};

/// Loads and supports of one static solve. Vectors indexed by vertex are empty or hold one
/// entry per mesh vertex.
struct FemProblem {
  std::vector<DVec3> forces;      ///< point forces at vertices, N
  DVec3 acceleration{0.0};        ///< body force per unit mass (gravity: (0, −9.81, 0)), m/s²; each
                                  ///< tetrahedron's ρ·V·a goes a quarter to each of its vertices
  /// Per vertex, which displacement components are prescribed: bit a (1, 2, 4) fixes
  /// component a (x, y, z); 7 fixes the vertex. Vertices no tetrahedron uses are fixed at zero.
  std::vector<uint8_t> fixed;
  std::vector<DVec3> prescribed;  ///< displacement of the fixed components, m (empty = zero)
  std::vector<DVec3> initialGuess;  ///< warm start for the free components, m (empty = zero)
  /// Per tetrahedron, a factor on its material's Young's modulus (empty = 1 everywhere): the
  /// displace operator stiffens crushed soft tetrahedra with it so they do not invert. Finite
  /// and > 0; stresses are reported with the scaled modulus.
  std::vector<double> stiffnessScale;
};

/// Strain and stress of one tetrahedron (constant inside it). Voigt order xx, yy, zz, yz,
/// xz, xy; strain shear components are tensor components ε_ij (not engineering γ = 2ε_ij).
struct TetStress {
  std::array<double, 6> strain{};
  std::array<double, 6> stress{};  ///< Pa
  double vonMises = 0;             ///< Pa
  double maxPrincipal = 0;         ///< largest principal stress (tension positive), Pa
};

/// Sizes, times and convergence of one solve.
struct FemStats {
  size_t dofs = 0, freeDofs = 0;
  size_t nonZeros = 0;        ///< stored entries of the free stiffness matrix (both triangles)
  int iterations = 0;
  double residual = 0;        ///< ‖b − K·u‖ / ‖b‖ at the end (0 when b = 0)
  bool converged = true;
  double assemblySeconds = 0, preconditionerSeconds = 0, solveSeconds = 0, stressSeconds = 0;
};

/// Displacement of every vertex and the state of every tetrahedron.
struct FemResult {
  std::vector<DVec3> displacement;  ///< m, per vertex
  std::vector<TetStress> tets;      ///< per tetrahedron
  FemStats stats;
};

/// The static equilibrium K·u = f of mesh under problem (constant-strain tetrahedra, E and ν
/// of each tetrahedron's material in `materials`). Throws std::invalid_argument for a
/// non-finite force, acceleration or prescribed value, a vector of the wrong size, a
/// material id outside `materials`, a material with E <= 0 or ν outside (−1, 0.5), a
/// tetrahedron of non-positive volume, or a singular system: a face-connected part of the
/// mesh whose fixed components do not hold all six rigid motions (nothing fixed, or only
/// points on one line). Throws std::runtime_error when CG does not converge and
/// options.requireConvergence. With Jacobi, each CG iteration advances a progress bar and a
/// cancellation request throws sprig::Cancelled (core/progress.h). Cost: assembly O(tets); CG
/// about O(dofs^1.3) on 3-D meshes (300,000 tetrahedra: about 15 s of CPU).
FemResult solveElastic(const TetMesh& mesh, const std::vector<Material>& materials, const FemProblem& problem,
                       const FemOptions& options = {});

/// The mesh's tetrahedra split into face-connected components: component id per
/// tetrahedron (0, 1, ... in order of their lowest tetrahedron) and the count.
std::pair<std::vector<uint32_t>, uint32_t> faceComponents(const TetMesh& mesh);

/// For each face-connected component, whether the fixed components of `fixed` (bits as in
/// FemProblem::fixed) hold its six rigid motions.
std::vector<bool> componentsHeld(const TetMesh& mesh, const std::vector<uint32_t>& component, uint32_t count,
                                 const std::vector<uint8_t>& fixed);

/// The stiffness matrix assembled the plain way, for the benchmark's baseline: every
/// tetrahedron's 12×12 block as triplets, one thread, Eigen's setFromTriplets; all degrees
/// of freedom, none eliminated. Returns the non-zero count and the sum of all entries.
std::pair<size_t, double> assembleStiffnessSequential(const TetMesh& mesh, const std::vector<Material>& materials);

}  // namespace sprig::solids
