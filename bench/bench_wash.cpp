/// Wash benchmark: the paper's gargoyle script washes with 200,000 particles (Cutler et al.
/// §5.3). Built in process: a stone ball of radius 0.5 m on a stone slab (one volume, the
/// union), meshed by meshSolid at cell 0.03 (about the statue species' size), an even layer
/// of dirt, then:
///   - the baseline: a wash of 10,000 particles (the paper's WASH default), and
///   - the wash of 200,000 particles (life 1 s, speed 1 m/s, radius 0.1 m: the defaults),
/// each on its own copy of the dirty mesh, on all threads; then the 200,000 again on one
/// thread (its tints must be the same bytes). Prints wall and CPU seconds, particle steps per
/// CPU second, and the process peak memory after each.
///
/// Usage: bench_wash [--quick]   (--quick: 20,000 particles instead of 200,000)

#include "bench/bench_clock.h"
#include "core/parallel.h"
#include "solids/distance_field.h"
#include "solids/particles.h"
#include "solids/solid.h"

#include <cstdio>
#include <cstring>

using namespace sprig;
using namespace sprig::solids;
using namespace sprig::bench;

namespace {

struct Run {
  double wall, cpu;
  ParticleStats st;
};

Run wash(TetMesh& m, const std::vector<Material>& mats, int particles) {
  ParticleOptions o = particleDefaults(ParticleTool::Wash);
  o.particles = particles;
  o.seed = 1;
  const auto t0 = Clock::now();
  const double c0 = processCpuSeconds();
  Run r;
  r.st = runParticles(m, mats, o);
  r.wall = seconds(t0);
  r.cpu = processCpuSeconds() - c0;
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  int big = 200000;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) big = 20000;
    else {
      std::fprintf(stderr, "usage: bench_wash [--quick]\n");
      return 2;
    }
  }
  Solid solid;
  Layer stone;
  stone.fill = true;
  stone.material = *solid.materials.concrete("stone");
  solid.volumes.push_back(makeVolume(unionField({sphereField(DVec3(0, 0.7, 0), 0.5), boxField(DVec3(0, 0.1, 0), DVec3(1.4, 0.2, 1.0))}), {stone}));
  Grid g;
  g.cell = 0.03;
  g.origin = DVec3(-0.75, -0.05, -0.55);
  g.cells = {50, 44, 37};
  const auto t0 = Clock::now();
  TetMesh base = meshSolid(solid, g);
  const auto& mats = solid.materials.materials;
  DirtOptions d;
  dirt(base, mats, d);
  const size_t visible = visibleInterface(base).size();
  std::printf("mesh: %zu tetrahedra, %zu vertices, %zu visible triangles (%.2f s)\n", base.tets.size(), base.positions.size(),
              visible, seconds(t0));
  std::printf("threads: %d; peak memory after meshing %.0f MB\n", threadCount(), peakMB());

  TetMesh a = base;
  const Run r0 = wash(a, mats, 10000);
  std::printf("baseline wash 10,000: %.2f s wall, %.2f s CPU, %zu steps (%.0f steps per CPU s), peak %.0f MB\n", r0.wall, r0.cpu,
              r0.st.steps, double(r0.st.steps) / r0.cpu, peakMB());
  TetMesh b = base;
  const Run r1 = wash(b, mats, big);
  std::printf("wash %d: %.2f s wall, %.2f s CPU, %zu landed, %zu steps, %zu drips, %zu lost (%.0f steps per CPU s), peak %.0f MB\n", big,
              r1.wall, r1.cpu, r1.st.landed, r1.st.steps, r1.st.drips, r1.st.lost, double(r1.st.steps) / r1.cpu, peakMB());
  TetMesh c = base;
  Run r2;
  {
    ThreadLimit one(1);
    r2 = wash(c, mats, big);
  }
  const bool same = b.tints.size() == c.tints.size() && std::memcmp(b.tints.data(), c.tints.data(), b.tints.size() * sizeof(Vec4)) == 0;
  std::printf("wash %d on 1 thread: %.2f s wall, %.2f s CPU (%s bytes)\n", big, r2.wall, r2.cpu, same ? "same" : "DIFFERENT");
  std::printf("ratio wash %d / baseline: %.1f x wall, %.1f x CPU (particles %.0f x)\n", big, r1.wall / r0.wall, r1.cpu / r0.cpu,
              double(big) / 10000.0);
  return same ? 0 : 1;
}
