/// Texture evaluation throughput (one thread): lookups per second for each procedural
/// texture and for an image texture through OpenImageIO's TextureSystem, against a
/// baseline that only generates the (u, v) coordinates; rates are per thread CPU-second.
/// Usage (from the repository root): bench_textures [lookups] [image]

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>

#include "bench/bench_clock.h"
#include "core/parallel.h"
#include "textures/registry.h"

using namespace sprig;
using namespace sprig::textures;
using sprig::bench::threadCpuSeconds;

int main(int argc, char** argv) {
  const long n = argc > 1 ? std::max(1000L, std::atol(argv[1])) : 2'000'000L;
  ThreadLimit one(1);
  TextureRegistry reg;
  struct Entry {
    const char* name;
    TextureId id;
  };
  std::vector<Entry> entries{{"constant", reg.add(ConstantTexture{})},
                             {"noise fBm 5 octaves", reg.add(NoiseTexture())},
                             {"bark", reg.add(BarkTexture())},
                             {"stripes", reg.add(StripesTexture())},
                             {"spots", reg.add(SpotsTexture())},
                             {"leaf", reg.add(LeafTexture())}};
  std::string map = argc > 2 ? argv[2] : "textures/maps/bark.png";  // run from the repository root
  if (std::filesystem::exists(map)) entries.push_back({"image (bark.png, bilinear)", reg.addImage(map, {"bench", 1, 1})});

  auto uvAt = [](long i) { return Vec2(static_cast<float>((i * 7919) % 100003) / 100003.0f, static_cast<float>(i) * 1e-6f); };
  double baseline = 0;
  {
    auto t0 = threadCpuSeconds();
    float acc = 0;
    for (long i = 0; i < n; ++i) acc += uvAt(i).x;
    auto t1 = threadCpuSeconds();
    baseline = t1 - t0;
    std::printf("baseline (uv only)            %8.1f M/s  [%g]\n", n / baseline * 1e-6, acc > -1 ? 0.0 : 1.0);
  }
  for (const Entry& e : entries) {
    auto t0 = threadCpuSeconds();
    float acc = 0;
    for (long i = 0; i < n; ++i) acc += reg.color(e.id, uvAt(i)).x;
    auto t1 = threadCpuSeconds();
    double s = t1 - t0;
    std::printf("%-29s %8.2f M lookups/s  (%.1fx the baseline time)  [%g]\n", e.name, n / s * 1e-6, s / baseline,
                acc > -1 ? 0.0 : 1.0);
  }
  return 0;
}
