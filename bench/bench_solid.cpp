/// Solid meshing benchmark: the almond candy of Cutler et al. Fig. 2a from its species file
/// to a tetrahedral mesh of about a million tetrahedra (the paper's models ran to 500,000),
/// with time and peak memory; beside it in the same run, TetGen (Debian package `tetgen`,
/// run as an external program, never linked: it is AGPL) meshing the same interfaces, the
/// visible and the material interfaces Sprig produced, as a piecewise linear complex with
/// its boundary preserved (-pY), so both make a conforming mesh of the same surfaces.
///
/// Usage: bench_solid [--quick] [--cell H] [--species FILE] [--no-peer]
/// Prints species → mesh seconds (load, fields, meshing), tetrahedra per second, the process
/// peak memory, and TetGen's seconds, tetrahedra and peak memory with the ratio of times.

#include "bench/bench_clock.h"
#include "model/solid_kind.h"
#include "model/species.h"
#include "solids/improve.h"
#include "solids/solid.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

using namespace sprig;
using namespace sprig::bench;

namespace {

/// Every interface triangle once (visible and between materials) as an OFF file for TetGen.
size_t writeInterfaces(const solids::TetMesh& m, const std::filesystem::path& path) {
  std::map<std::array<uint32_t, 3>, std::array<uint32_t, 3>> unique;  // sorted key -> oriented
  auto add = [&](const solids::InterfaceTriangle& t) {
    std::array<uint32_t, 3> k = t.v;
    std::sort(k.begin(), k.end());
    unique.emplace(k, t.v);
  };
  for (const auto& t : solids::visibleInterface(m)) add(t);
  for (const auto& t : solids::materialInterfaces(m)) add(t);
  std::map<uint32_t, uint32_t> remap;
  for (const auto& [k, t] : unique)
    for (uint32_t v : t) remap.emplace(v, 0);
  uint32_t next = 0;
  for (auto& [v, id] : remap) id = next++;
  std::ofstream f(path);
  f << "OFF\n" << remap.size() << " " << unique.size() << " 0\n";
  f.precision(9);
  for (const auto& [v, id] : remap) f << m.positions[v].x << " " << m.positions[v].y << " " << m.positions[v].z << "\n";
  for (const auto& [k, t] : unique) f << "3 " << remap[t[0]] << " " << remap[t[1]] << " " << remap[t[2]] << "\n";
  return unique.size();
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false, peer = true;
  double cell = 0;
  std::string file = std::string(SPRIG_BENCH_SOURCE_DIR) + "/species/fig_solid_02a_almond_candy.yaml";
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) quick = true;
    else if (!std::strcmp(argv[i], "--no-peer")) peer = false;
    else if (!std::strcmp(argv[i], "--cell") && i + 1 < argc) cell = std::atof(argv[++i]);
    else if (!std::strcmp(argv[i], "--species") && i + 1 < argc) file = argv[++i];
    else {
      std::fprintf(stderr, "usage: bench_solid [--quick] [--cell H] [--species FILE] [--no-peer]\n");
      return 2;
    }
  }
  // About a million tetrahedra for the almond candy at cell 0.03 (0.06 with --quick).
  if (cell <= 0) cell = quick ? 0.06 : 0.03;

  const auto t0 = Clock::now();
  const double c0 = processCpuSeconds();
  Species species = loadSpecies(file);
  const double load = seconds(t0);
  auto& spec = const_cast<SolidSpec&>(dynamic_cast<const SolidSpec&>(*species.spec));
  // The same box at the requested cell.
  const DVec3 hi = spec.grid.origin + spec.grid.cell * DVec3(spec.grid.cells[0], spec.grid.cells[1], spec.grid.cells[2]);
  for (int a = 0; a < 3; ++a) spec.grid.cells[a] = int(std::ceil((hi[a] - spec.grid.origin[a]) / cell));
  spec.grid.cell = cell;
  solids::MeshStats st;
  const solids::TetMesh m = solids::meshSolid(spec.solid, spec.grid, {}, &st);
  const double total = seconds(t0), cpu = processCpuSeconds() - c0;
  const solids::QualityStats q = solids::measureQuality(m);
  std::printf("== %s, grid %dx%dx%d of cell %g\n", species.name.c_str(), spec.grid.cells[0], spec.grid.cells[1],
              spec.grid.cells[2], cell);
  std::printf("sprig: species file to mesh %.2f s wall (load %.2f s, fields %.2f s, meshing %.2f s), %.2f s CPU; "
              "%zu tetrahedra, %zu vertices (%.2f M tetrahedra/s wall); peak memory %.0f MB; quality min %.2f mean %.2f\n",
              total, load, st.fieldSeconds, st.meshSeconds, cpu, m.tets.size(), m.positions.size(),
              double(m.tets.size()) / total * 1e-6, peakMB(RUSAGE_SELF), q.minQuality, q.meanQuality);
  // Beside the uniform grid: the coarsened octree (§4.4, Fig. 4) and the quality improvement.
  {
    solids::MeshOptions coarse;
    coarse.coarsenLevels = 3;
    coarse.coarsenTolerance = 0.1;
    solids::MeshStats cs;
    const auto c1 = Clock::now();
    const solids::TetMesh cm = solids::meshSolid(spec.solid, spec.grid, coarse, &cs);
    const double cseconds = seconds(c1);
    const solids::QualityStats cq = solids::measureQuality(cm);
    std::printf("sprig coarsen 3, tolerance 0.1 cells: meshing %.2f s, %zu tetrahedra (%.2f of the uniform grid's), "
                "quality min %.2f mean %.2f\n",
                cseconds, cm.tets.size(), double(cm.tets.size()) / double(m.tets.size()), cq.minQuality, cq.meanQuality);
    solids::TetMesh im = m;
    solids::ImproveOptions io;
    io.qualityBelow = 3;
    io.interfaceTolerance = 0.1 * cell;
    const auto i0 = Clock::now();
    const solids::ImproveStats is = solids::improveQuality(im, io);
    std::printf("sprig improve (quality_below 3, tolerance 0.1 cells): %.2f s, %zu -> %zu tetrahedra, quality min %.2f -> %.2f, "
                "mean %.2f -> %.2f (%.0f k tetrahedra/s)\n",
                seconds(i0), is.tetsBefore, is.tetsAfter, is.before.minQuality, is.after.minQuality, is.before.meanQuality,
                is.after.meanQuality, double(is.tetsBefore) / seconds(i0) * 1e-3);
  }
  if (!peer) return 0;
  if (std::system("command -v tetgen > /dev/null 2>&1") != 0) {
    std::printf("tetgen: not installed (apt-get install tetgen), no peer run\n");
    return 0;
  }
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("sprig-bench-solid-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::filesystem::path off = dir / "interfaces.off";
  const size_t tris = writeInterfaces(m, off);
  // -p: a piecewise linear complex, -Y: keep its triangles (no Steiner points on them), -Q: quiet.
  const std::string cmd = "cd '" + dir.string() + "' && tetgen -pYQ interfaces.off > tetgen.log 2>&1";
  const auto p0 = Clock::now();
  const int rc = std::system(cmd.c_str());
  const double peerSeconds = seconds(p0);
  size_t peerTets = 0;
  std::ifstream ele(dir / "interfaces.1.ele");
  if (ele) ele >> peerTets;
  if (rc != 0 || !peerTets) {
    std::printf("tetgen: failed on %zu interface triangles (exit %d, see %s/tetgen.log)\n", tris, rc, dir.string().c_str());
    return 0;
  }
  std::printf("tetgen -pYQ on the same %zu interface triangles: %.2f s wall, %zu tetrahedra (%.2f M tetrahedra/s), "
              "peak memory %.0f MB\n",
              tris, peerSeconds, peerTets, double(peerTets) / peerSeconds * 1e-6, peakMB(RUSAGE_CHILDREN));
  std::printf("ratio: sprig species-to-mesh time / tetgen interfaces-to-mesh time = %.2f\n", total / peerSeconds);
  std::filesystem::remove_all(dir);
  return 0;
}
