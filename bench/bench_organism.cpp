// Benchmark of multiresolution synthesis (Velho et al. 2002): a cube-sphere refined to level 7
// (6 x 4^7 = 98,304 quads) with rock detail at every level.
//
// Baseline in the same process: bare OpenSubdiv, the same control mesh refined uniformly to
// level 7 and its positions interpolated level by level (Far::PrimvarRefiner::Interpolate) —
// what any multiresolution synthesis must at least do. Then Sprig's synthesis of the same
// levels with the rock (frames, noise, detail), the limit mesh, the whole species file to a
// mesh, and the species file to a preview image (mesh mode, 400 x 300, 1 sample).
//
// Prints the best of --repeat runs of each and the ratio synthesis / bare refinement.
//
// Usage: bench_organism [--repeat 5] [--levels 7] [--image OUT.png]

#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "bench/bench_clock.h"
#include "core/image.h"
#include "model/model.h"
#include "model/organism_kind.h"
#include "model/species.h"
#include "organisms/base_mesh.h"
#include "organisms/detail.h"
#include "organisms/multires.h"

using namespace sprig;
using namespace sprig::organisms;

namespace {

namespace Far = OpenSubdiv::Far;

struct Var {
  Vec3 p;
  void Clear(void* = nullptr) { p = Vec3(0.0f); }
  void AddWithWeight(const Var& s, float w) { p += w * s.p; }
};

/// Bare OpenSubdiv: refine to levels and interpolate positions through every level.
size_t bareRefinement(const ControlMesh& m, int levels) {
  std::vector<int> sizes(m.faceSizes.begin(), m.faceSizes.end()), verts(m.faceVertices.begin(), m.faceVertices.end());
  Far::TopologyDescriptor desc;
  desc.numVertices = int(m.positions.size());
  desc.numFaces = int(sizes.size());
  desc.numVertsPerFace = sizes.data();
  desc.vertIndicesPerFace = verts.data();
  OpenSubdiv::Sdc::Options sdc;
  sdc.SetVtxBoundaryInterpolation(OpenSubdiv::Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
  using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
  std::unique_ptr<Far::TopologyRefiner> refiner(
      Factory::Create(desc, Factory::Options(OpenSubdiv::Sdc::SCHEME_CATMARK, sdc)));
  refiner->RefineUniform(Far::TopologyRefiner::UniformOptions(levels));
  std::vector<Var> a(m.positions.size()), b;
  for (size_t i = 0; i < a.size(); ++i) a[i].p = m.positions[i];
  Far::PrimvarRefiner primvar(*refiner);
  for (int l = 1; l <= levels; ++l) {
    b.resize(size_t(refiner->GetLevel(l).GetNumVertices()));
    const Var* src = a.data();
    Var* dst = b.data();
    primvar.Interpolate(l, src, dst);
    a.swap(b);
  }
  return size_t(refiner->GetLevel(levels).GetNumFaces());
}

/// Best wall time of f over repeat runs.
double best(int repeat, const std::function<void()>& f) {
  double t = 1e30;
  for (int i = 0; i < repeat; ++i) {
    const auto t0 = bench::Clock::now();
    f();
    t = std::min(t, bench::seconds(t0));
  }
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  int repeat = 5, levels = 7;
  std::string image;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--repeat")) repeat = std::max(1, std::atoi(argv[i + 1]));
    else if (!std::strcmp(argv[i], "--levels")) levels = std::clamp(std::atoi(argv[i + 1]), 1, 8);
    else if (!std::strcmp(argv[i], "--image")) image = argv[i + 1];
  }
  const ControlMesh cube = cubeSphere(1.0f, 1);
  RockOptions ro;
  ro.amplitude = 0.12f;
  ro.frequency = 1.5f;
  ro.levels = {1, levels};
  const SynthesisInput input{{makeRock(ro)}, {}, nullptr, {}};

  size_t faces = 0;
  const double tBare = best(repeat, [&] { faces = bareRefinement(cube, levels); });
  const double tSynth = best(repeat, [&] {
    const Subdivision sub(cube, levels);
    synthesize(sub, cube.positions, input);
  });
  const double tMesh = best(repeat, [&] {
    const Subdivision sub(cube, levels);
    limitMesh(sub, synthesize(sub, cube.positions, input).positions);
  });

  // The same organism as a species file.
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "sprig_bench_organism";
  std::filesystem::create_directories(dir);
  const std::filesystem::path file = dir / "rock.yaml";
  std::ofstream(file) << "kind: organism\norganism:\n  base: {cube_sphere: {radius: 1, quads: 1}}\n  levels: " << levels
                      << "\n  detail:\n    - rock: {amplitude: 0.12, frequency: 1.5, levels: [1, " << levels << "]}\n";
  size_t triangles = 0;
  const double tSpecies = best(repeat, [&] {
    const Species s = loadSpecies(file, PathPolicy{dir, false});
    triangles = buildOrganismMesh(dynamic_cast<const OrganismSpec&>(*s.spec), 1.0, Vec3(0.6f)).triangleCount();
  });
  Image preview;
  const double tPreview = best(repeat, [&] {
    const Species s = loadSpecies(file, PathPolicy{dir, false});
    SpeciesModel model(s);
    RenderJob job;
    job.width = 400;
    job.height = 300;
    job.samples = 1;
    job.mode = GeometryMode::Mesh;
    job.progress = false;
    preview = renderModel(model, s.render, job);
  });
  if (!image.empty()) writeImage(preview, image);

  std::printf("cube-sphere to level %d: %zu quads, %zu triangles\n", levels, faces, triangles);
  std::printf("bare OpenSubdiv refine + interpolate   %8.1f ms  %6.2f Mquads/s\n", 1e3 * tBare, double(faces) / tBare * 1e-6);
  std::printf("Sprig synthesis with rock               %8.1f ms  %6.2f Mquads/s   ratio %.2f\n", 1e3 * tSynth,
              double(faces) / tSynth * 1e-6, tSynth / tBare);
  std::printf("  + limit mesh                          %8.1f ms  ratio %.2f\n", 1e3 * tMesh, tMesh / tBare);
  std::printf("species file to mesh                    %8.1f ms\n", 1e3 * tSpecies);
  std::printf("species file to preview (400x300, 1spp) %8.1f ms\n", 1e3 * tPreview);
  return 0;
}
