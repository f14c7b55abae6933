/// FEM benchmark: a static linear-elastic solve on a layered solid of about 300,000
/// tetrahedra (the paper replayed its sculpting on 300,000, Cutler et al. §5.1), built in
/// process: a slab 1 × 0.4 × 1 m (y up) of dirt under 0.075 m of brick paving, meshed by
/// meshSolid; the base held, gravity and a hammer blow of 10 kN on the paving.
///
/// Usage: bench_fem [--quick] [--tets N]
/// Prints the mesh, then for each preconditioner (Jacobi, Sprig's default, and
/// IncompleteCholesky, the alternative) assembly, preconditioner and CG seconds, iterations and residual;
/// Sprig's parallel assembly against a plain sequential triplet assembly (Eigen's
/// setFromTriplets, all degrees of freedom); the Jacobi solve again on one thread (the
/// parallel product's gain; its displacements must be the same bytes); the process peak
/// memory; and the ratios.

#include "bench/bench_clock.h"
#include "core/parallel.h"
#include "solids/distance_field.h"
#include "solids/fem.h"
#include "solids/operators.h"
#include "solids/solid.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

using namespace sprig;
using namespace sprig::solids;
using namespace sprig::bench;

namespace {

}  // namespace

int main(int argc, char** argv) {
  double target = 300000;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) target = 50000;
    else if (!std::strcmp(argv[i], "--tets") && i + 1 < argc) target = std::atof(argv[++i]);
    else {
      std::fprintf(stderr, "usage: bench_fem [--quick] [--tets N]\n");
      return 2;
    }
  }

  // The slab: brick paving 0.075 m thick over dirt (§5.2's URBAN_TREE ground), as one
  // volume with two interior layers.
  Solid solid;
  Layer brick, dirt;
  brick.thickness = 0.075;
  brick.material = *solid.materials.concrete("brick");
  dirt.fill = true;
  dirt.material = *solid.materials.concrete("dirt");
  solid.volumes.push_back(makeVolume(boxField(DVec3(0.5, 0.2, 0.5), DVec3(1.0, 0.4, 1.0)), {brick, dirt}));
  // The cell: first guessed from 5 tetrahedra per cubic cell, then corrected once by the
  // count the guess gave, twice (interface splits add more at coarse cells).
  auto gridOf = [](double cell) {
    Grid g;
    g.cell = cell;
    g.origin = DVec3(-0.5 * cell);
    for (int a = 0; a < 3; ++a) g.cells[size_t(a)] = int(std::ceil(((a == 1 ? 0.4 : 1.0) + cell) / cell));
    return g;
  };
  double cell = std::cbrt(5 * 0.4 / target);
  for (int pass = 0; pass < 2; ++pass) cell *= std::cbrt(double(meshSolid(solid, gridOf(cell)).tets.size()) / target);
  const Grid grid = gridOf(cell);
  const auto m0 = Clock::now();
  const TetMesh mesh = meshSolid(solid, grid);
  const double meshSeconds = seconds(m0);
  const double meshPeak = peakMB();

  // Base held (every vertex within half a cell of the bottom), gravity, a blow on the paving.
  double ymin = INFINITY;
  for (const DVec3& p : mesh.positions) ymin = std::min(ymin, p.y);
  FemProblem pb;
  pb.fixed.assign(mesh.positions.size(), 0);
  size_t held = 0;
  for (size_t v = 0; v < mesh.positions.size(); ++v)
    if (mesh.positions[v].y < ymin + 0.5 * cell) pb.fixed[v] = 7, ++held;
  pb.acceleration = DVec3(0, -9.81, 0);
  HammerOptions blow;
  blow.position = DVec3(0.5, 0.4, 0.5);
  blow.orientation = DVec3(0, -1, 0);
  blow.magnitude = 1e4;
  blow.size = 0.05;
  pb.forces = hammerForces(mesh, blow, pb.fixed);
  std::printf("== bench_fem: brick-paved dirt slab, cell %.4f m, %zu tetrahedra, %zu vertices (%zu held), "
              "meshing %.2f s, %d threads\n",
              cell, mesh.tets.size(), mesh.positions.size(), held, meshSeconds, threadCount());

  FemResult results[2];
  const Preconditioner pre[2] = {Preconditioner::Jacobi, Preconditioner::IncompleteCholesky};
  const char* names[2] = {"Jacobi", "IncompleteCholesky"};
  double peaks[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    FemOptions opt;
    opt.preconditioner = pre[k];
    const double c0 = processCpuSeconds();
    const auto t0 = Clock::now();
    results[k] = solveElastic(mesh, solid.materials.materials, pb, opt);
    const double wall = seconds(t0), cpu = processCpuSeconds() - c0;
    const FemStats& s = results[k].stats;
    peaks[k] = peakMB();
    std::printf("%-18s %zu free dofs, %zu non-zeros: assembly %.2f s, preconditioner %.2f s, CG %.2f s (%d iterations, "
                "residual %.1e), stress %.2f s; total %.2f s wall, %.2f s CPU; peak memory %.0f MB\n",
                names[k], s.freeDofs, s.nonZeros, s.assemblySeconds, s.preconditionerSeconds, s.solveSeconds, s.iterations,
                s.residual, s.stressSeconds, wall, cpu, peaks[k]);
  }
  const FemStats& jac = results[0].stats;
  const FemStats& ic = results[1].stats;
  // The Jacobi solve again on one thread: the parallel product's gain, and the same bytes.
  FemResult single;
  const int threads = threadCount();
  {
    ThreadLimit limit(1);
    const auto t0 = Clock::now();
    single = solveElastic(mesh, solid.materials.materials, pb);
    std::printf("Jacobi, 1 thread: assembly %.2f s, CG %.2f s (%d iterations); total %.2f s wall; displacements %s "
                "those at %d threads\n",
                single.stats.assemblySeconds, single.stats.solveSeconds, single.stats.iterations, seconds(t0),
                std::memcmp(single.displacement.data(), results[0].displacement.data(),
                            single.displacement.size() * sizeof(DVec3)) == 0
                    ? "are the same bytes as"
                    : "DIFFER from",
                threads);
  }
  double diff = 0, size = 0;
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    diff = std::max(diff, glm::length(results[0].displacement[v] - results[1].displacement[v]));
    size = std::max(size, glm::length(results[0].displacement[v]));
  }
  std::printf("largest displacement %.3e m; Jacobi and IncompleteCholesky solutions differ by at most %.1e m\n", size, diff);

  const auto s0 = Clock::now();
  const auto [nnz, sum] = assembleStiffnessSequential(mesh, solid.materials.materials);
  const double seq = seconds(s0);
  std::printf("sequential triplet assembly (all %zu dofs, %zu non-zeros, sum %.3e): %.2f s; peak memory %.0f MB\n",
              3 * mesh.positions.size(), nnz, sum, seq, peakMB());
  std::printf("ratios: IncompleteCholesky / Jacobi solve time (preconditioner + CG) = %.2f, iterations %.2f; "
              "sequential triplet / Sprig assembly time = %.2f; Jacobi CG 1 thread / %d threads = %.2f\n",
              (ic.preconditionerSeconds + ic.solveSeconds) / (jac.preconditionerSeconds + jac.solveSeconds),
              double(ic.iterations) / double(jac.iterations), seq / jac.assemblySeconds, threadCount(),
              single.stats.solveSeconds / jac.solveSeconds);
  std::printf("peak memory: after meshing %.0f MB, after the Jacobi solve %.0f MB, after the IncompleteCholesky solve %.0f MB\n",
              meshPeak, peaks[0], peaks[1]);
  return 0;
}
