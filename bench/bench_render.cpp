/// Renderer benchmark: the skeleton preview of ABOP figure 2.6, and a branching model of
/// more than 2,000 cones rendered at 1536x2048 with 9 samples per pixel, exact implicit
/// mode and mesh mode, with shadows. Prints time and rays/s for each, and the exact render's
/// cost with a rim light against without it (a quarter of the pixels).
///
///   build/bench/bench_render [--quick] [--out DIR] [--images DIR]
///
/// --quick renders at a quarter of the size in each direction (a smoke run); --out writes
/// the images as PNG into DIR. --images DIR only renders the inspection images (a textured
/// blend of two cones in exact and mesh mode, a sphere on the ground) into DIR and exits.

#include <chrono>
#include <cmath>
#include <ctime>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "blobtree/blobtree.h"
#include "blobtree/compiled.h"
#include "blobtree/polygonize.h"
#include "core/image.h"
#include "core/parallel.h"
#include "core/timer.h"
#include "lsystem/skeleton.h"
#include "model/tree_kind.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "render/scene.h"
#include "textures/procedural.h"
#include "textures/registry.h"

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

/// A branching model of cones: each branch ends in three children (lengths x0.78,
/// radii x0.68), spread 120 degrees apart around a golden-angle roll. depth 7: 3,280 cones.
struct ConeTree {
  blobtree::BlobTree tree;
  std::vector<blobtree::NodeId> cones;

  void branch(DVec3 a, DVec3 dir, double len, double r, int depth, double rollDeg) {
    DVec3 b = a + dir * len;
    double rTip = r * 0.82;
    cones.push_back(tree.cone(Vec3(a), Vec3(b), static_cast<float>(r), static_cast<float>(rTip)));
    if (depth == 0) return;
    DVec3 side = glm::normalize(glm::cross(dir, std::abs(dir.y) < 0.9 ? DVec3(0, 1, 0) : DVec3(1, 0, 0)));
    side = rotate(side, dir, radians(rollDeg));
    for (int k = 0; k < 3; ++k) {
      DVec3 s = rotate(side, dir, radians(120.0 * k));
      double spread = k == 0 ? 18.0 : 38.0;
      DVec3 d = glm::normalize(rotate(dir, glm::normalize(glm::cross(dir, s)), radians(spread)) + DVec3(0, 0.15, 0));
      branch(b, d, len * 0.78, rTip * 0.83, depth - 1, rollDeg + 137.5);
    }
  }
  blobtree::CompiledBlob build(int depth) {
    branch(DVec3(0), DVec3(0, 1, 0), 3.0, 0.32, depth, 0.0);
    return blobtree::compile(tree, tree.blend(cones));
  }
};

void report(const char* name, const render::RenderSettings& s, const render::RenderStats& st) {
  std::printf("%-28s %5dx%-5d spp %2d  %7.2f s  %8.2f Mrays  %6.2f Mrays/s  (%.2f Mrays/s/thread, %d threads)\n", name,
              s.width, s.height, s.spp, st.seconds, st.rays() * 1e-6, st.raysPerSecond() * 1e-6,
              st.raysPerSecond() * 1e-6 / threadCount(), threadCount());
}

/// Inspection images: a Y of two blended cones whose textures meet in the blend (stripes
/// on both, the branch's v continuing the trunk's; then stripes against spots), in exact
/// and mesh mode, and a sphere resting on the ground (soft shadow, no acne).
void inspectionImages(const fs::path& dir) {
  fs::create_directories(dir);
  render::RenderSettings s;
  s.width = 640;
  s.height = 640;
  s.spp = 16;
  s.progress = false;
  auto registry = std::make_shared<textures::TextureRegistry>();
  textures::StripesOptions so;
  so.frequency = 4.0;
  registry->add(textures::StripesTexture(so));
  textures::SpotsOptions sp;
  registry->add(textures::SpotsTexture(sp));
  for (int variant = 0; variant < 2; ++variant) {
    blobtree::BlobTree t;
    blobtree::TextureAttr trunk, branch;
    trunk.uvScale = Vec2(1.0f, 1.0f);
    branch.textureId = uint16_t(variant);
    branch.vOffset = 1.2f;  // the branch starts 1.2 units up the trunk
    std::vector<blobtree::NodeId> parts{t.cone(Vec3(0, 0, 0), Vec3(0, 2.4f, 0), 0.32f, 0.2f, trunk),
                                        t.cone(Vec3(0, 1.2f, 0), Vec3(1.1f, 2.3f, 0.2f), 0.2f, 0.12f, branch)};
    blobtree::CompiledBlob blob = blobtree::compile(t, t.blend(parts));
    for (int mode = 0; mode < 2; ++mode) {
      render::Scene scene;
      scene.addTextures(registry);
      uint32_t m = scene.addMaterial(render::Material{Vec3(0.6f), 0.5f, 0.04f});
      blobtree::PolygonizeOptions po;
      po.cellSize = 0.01f;
      po.vertexData = blobtree::PolygonizeOptions::VertexData::Blend;  // textured
      if (mode == 0) scene.addImplicit(blob, m);
      else scene.addPolygonized(blobtree::polygonizeDetailed(blob, po), m);
      scene.commit();
      render::ViewSpec view;
      view.azimuthDeg = 10.0;
      render::Camera cam = render::frameBounds(scene.bounds(), view, 1.0);
      render::RenderStats st;
      Image img = render::renderImage(scene, cam, s, &st);
      std::string name = std::string(variant == 0 ? "blend_stripes" : "blend_stripes_spots") + (mode == 0 ? "_exact" : "_mesh") + ".png";
      writeImage(img, dir / name);
      report(name.c_str(), s, st);
    }
  }
  {
    blobtree::BlobTree t;
    blobtree::CompiledBlob blob = blobtree::compile(t, t.point(Vec3(0, 1, 0), 1.0f));
    render::Scene scene;
    scene.addImplicit(blob, scene.addMaterial(render::Material{Vec3(0.7f, 0.3f, 0.2f), 0.3f, 0.06f}));
    scene.commit();
    render::RenderSettings g = s;
    g.width = 800;
    g.height = 600;
    render::ViewSpec view;
    view.elevationDeg = 25.0;
    view.margin = 0.3;
    render::Camera cam = render::frameBounds(scene.bounds(), view, 800.0 / 600.0);
    render::RenderStats st;
    Image img = render::renderImage(scene, cam, g, &st);
    writeImage(img, dir / "sphere_ground.png");
    report("sphere_ground.png", g, st);
  }
}

/// Creates an output folder (and its parents); false, with a message, when it cannot.
bool makeFolder(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) std::fprintf(stderr, "bench_render: error: cannot create folder '%s': %s\n", dir.c_str(), ec.message().c_str());
  return !ec;
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  bool quick = false;
  fs::path out;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) quick = true;
    else if (!std::strcmp(argv[i], "--out") && i + 1 < argc) out = argv[++i];
    else if (!std::strcmp(argv[i], "--images") && i + 1 < argc) {
      fs::path dir = argv[++i];
      if (!makeFolder(dir)) return 2;
      inspectionImages(dir);
      return 0;
    } else {
      std::fprintf(stderr, "bench_render: error: unknown argument '%s' (use --quick, --out DIR, --images DIR)\n", argv[i]);
      return 2;
    }
  }
  if (!out.empty() && !makeFolder(out)) return 2;
  // 1. Skeleton preview of ABOP 2.6.
  {
    lsystem::Skeleton sk = Abop26{}.build();
    render::Scene scene;
    scene.add(skeletonPreview(sk, SkeletonStyle{}));
    scene.commit();
    render::RenderSettings s;
    s.width = 800;
    s.height = 800;
    s.spp = 4;
    s.progress = false;
    render::ViewSpec view;
    render::Camera cam = render::frameBounds(scene.bounds(), view, 1.0);
    render::RenderStats st;
    Image img = render::renderImage(scene, cam, s, &st);
    std::printf("ABOP 2.6 skeleton: %zu internodes, %zu curve segments\n", sk.internodes.size(),
                scene.stats().curveSegments);
    report("preview abop 2.6", s, st);
    if (!out.empty()) writeImage(img, out / "abop_2_6_preview.png");
  }
  // 2. A branching model of more than 2,000 cones, 1536x2048, 9 spp, shadows: exact and mesh.
  {
    auto t0 = std::chrono::steady_clock::now();
    ConeTree model;
    blobtree::CompiledBlob blob = model.build(7);
    std::printf("cone tree: %zu cones, compiled in %.2f s\n", model.cones.size(), secondsSince(t0));
    render::RenderSettings s;
    s.width = quick ? 384 : 1536;
    s.height = quick ? 512 : 2048;
    s.spp = 9;
    s.progress = false;
    render::Material bark{Vec3(0.36f, 0.25f, 0.16f), 0.6f, 0.04f};

    t0 = std::chrono::steady_clock::now();
    render::Scene exact;
    exact.addImplicit(blob, exact.addMaterial(bark));
    exact.commit();
    std::printf("exact scene: %zu surface cells, built in %.2f s\n", exact.stats().implicitCells, secondsSince(t0));
    render::Camera cam = render::frameBounds(exact.bounds(), render::ViewSpec{}, double(s.width) / s.height);
    render::RenderStats st;
    std::clock_t c0 = std::clock();
    Image img = render::renderImage(exact, cam, s, &st);
    report("cone tree exact", s, st);
    std::printf("  cpu %.1f s (%.2f Mrays per cpu-second)\n", double(std::clock() - c0) / CLOCKS_PER_SEC,
                st.rays() * 1e-6 / (double(std::clock() - c0) / CLOCKS_PER_SEC));
    if (!out.empty()) writeImage(img, out / "cone_tree_exact.png");

    // The rim light (render.rim) costs one shadow ray per lit camera hit: the same scene at a
    // quarter of the pixels, without and with it, in this process.
    {
      render::RenderSettings q = s;
      q.width /= 2;
      q.height /= 2;
      render::RenderStats plain, rim;
      render::renderImage(exact, cam, q, &plain);
      q.rimStrength = 0.6f;
      render::renderImage(exact, cam, q, &rim);
      report("cone tree exact, no rim", q, plain);
      report("cone tree exact, rim 0.6", q, rim);
      std::printf("rim / no rim time ratio: %.2f\n", rim.seconds / plain.seconds);
    }

    t0 = std::chrono::steady_clock::now();
    // Mesh mode at 1.4 cells per thinnest twig radius (the default half-radius cell gives
    // tens of millions of triangles for this model; at one cell per twig diameter the grid
    // samples miss parts of the thinnest twigs, which then render beaded).
    blobtree::PolygonizeOptions po;
    po.cellSize = 1.4f * blob.smallestFeature();
    blobtree::PolygonizeResult poly = blobtree::polygonizeDetailed(blob, po);
    double tPoly = secondsSince(t0);
    render::Scene meshScene;
    meshScene.addPolygonized(poly, meshScene.addMaterial(bark));
    meshScene.commit();
    std::printf("mesh scene: %zu triangles (cell %.4f), polygonized in %.2f s, built in %.2f s\n",
                meshScene.stats().triangles, poly.cellSize, tPoly, secondsSince(t0));
    render::RenderStats sm;
    c0 = std::clock();
    Image imgMesh = render::renderImage(meshScene, cam, s, &sm);
    report("cone tree mesh", s, sm);
    std::printf("  cpu %.1f s (%.2f Mrays per cpu-second)\n", double(std::clock() - c0) / CLOCKS_PER_SEC,
                sm.rays() * 1e-6 / (double(std::clock() - c0) / CLOCKS_PER_SEC));
    if (!out.empty()) writeImage(imgMesh, out / "cone_tree_mesh.png");
    std::printf("exact / mesh time ratio: %.2f\n", st.seconds / sm.seconds);
  }
  return 0;
}
