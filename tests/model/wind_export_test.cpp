#include <catch2/catch.hpp>

#include <tiny_gltf.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>

#include "core/mesh_io.h"
#include "model/wind_export.h"
#include "organisms/wind.h"
#include "tests/model/read_glb.h"
#include "tests/organisms/internode.h"

using namespace sprig;
using test::readGlb;
using lsystem::Skeleton;
using test::seg;
namespace fs = std::filesystem;

namespace {

/// The wind tests' tree (a trunk, three laterals of order 1 with a leaf each) with an
/// order-2 twig on the last lateral's outer internode.
Skeleton windTree() {
  Skeleton sk = test::windTree();
  const lsystem::Internode& last = sk.internodes.back();
  const DVec3 fork = last.start + 0.2 * (last.end - last.start);  // away from the probes
  sk.internodes.push_back(seg(fork, fork + DVec3(0.3, 0.1, -0.2), 0.02, 0.015, int(sk.internodes.size()) - 1, 2));
  for (auto& in : sk.internodes) {  // an up vector across each internode, as the turtle's
    const DVec3 dir = glm::normalize(in.end - in.start);
    in.up = glm::normalize(glm::cross(dir, std::abs(dir.x) < 0.9 ? DVec3(1, 0, 0) : DVec3(0, 0, 1)));
  }
  return sk;
}

/// A point of the test parts: where it is still, and where swayInWind puts it (from the
/// swayed skeleton alone: a point kAt along an internode and its up vector, or a leaf's
/// corner). Three quarters along, a lateral's surface is clear of the trunk's.
constexpr double kAt = 0.75;
struct Probe {
  DVec3 still;
  int32_t internode = -1, organ = -1, corner = 0;
  double across = 0;  ///< distance along the internode's up (or up × direction when side)
  bool side = false;
  DVec3 swayed(const Skeleton& s) const {
    if (organ >= 0) return s.organs[size_t(organ)].points[size_t(corner)];
    const lsystem::Internode& in = s.internodes[size_t(internode)];
    const DVec3 dir = glm::normalize(in.end - in.start);
    return in.start + kAt * (in.end - in.start) + across * (side ? glm::cross(dir, in.up) : in.up);
  }
};

/// Wood: a triangle around each internode kAt along it, on its surface; leaves: the leaf
/// polygons as fans. The probes in vertex order per part.
std::vector<ExportPart> testParts(const Skeleton& sk, std::vector<Probe>& wood, std::vector<Probe>& leaves) {
  ExportPart w{"wood", Mesh{}, PartMaterial{"wood", Vec3(0.3f, 0.2f, 0.1f), 0.7f, false}};
  for (size_t i = 0; i < sk.internodes.size(); ++i) {
    const lsystem::Internode& in = sk.internodes[i];
    const double r = in.baseRadius + kAt * (in.tipRadius - in.baseRadius);
    for (auto [across, side] : {std::pair{r, false}, std::pair{r, true}, std::pair{-r, false}}) {
      Probe p{DVec3(0), int32_t(i), -1, 0, across, side};
      p.still = p.swayed(sk);
      wood.push_back(p);
      w.mesh.positions.push_back(Vec3(p.still));
    }
    const auto b = uint32_t(3 * i);
    w.mesh.triangles.push_back({b, b + 1, b + 2});
  }
  ExportPart l{"leaves", Mesh{}, PartMaterial{"leaves", Vec3(0.1f, 0.4f, 0.05f), 0.5f, true}, true};
  for (size_t o = 0; o < sk.organs.size(); ++o) {
    const auto b = uint32_t(l.mesh.positions.size());
    for (size_t k = 0; k < sk.organs[o].points.size(); ++k) {
      leaves.push_back(Probe{sk.organs[o].points[k], -1, int32_t(o), int32_t(k)});
      l.mesh.positions.push_back(Vec3(sk.organs[o].points[k]));
    }
    l.mesh.triangles.push_back({b, b + 1, b + 2});
    l.mesh.triangles.push_back({b, b + 2, b + 3});
  }
  return {w, l};
}

organisms::WindOptions wind(double speed) {
  organisms::WindOptions w;
  w.speed = speed;
  w.directionDeg = 90;  // toward +X
  w.seed = 3;
  return w;
}

/// A float accessor's values (tightly packed, as Sprig writes them; sparse: zeros and the
/// listed elements, uint32 indices).
std::vector<float> floats(const tinygltf::Model& m, int accessor) {
  const tinygltf::Accessor& a = m.accessors[size_t(accessor)];
  REQUIRE(a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT);
  const size_t width = size_t(tinygltf::GetNumComponentsInType(uint32_t(a.type)));
  std::vector<float> out(a.count * width, 0.0f);
  auto bytes = [&](int view, size_t offset) {
    const tinygltf::BufferView& v = m.bufferViews[size_t(view)];
    return m.buffers[size_t(v.buffer)].data.data() + v.byteOffset + offset;
  };
  if (a.bufferView >= 0) std::memcpy(out.data(), bytes(a.bufferView, a.byteOffset), out.size() * sizeof(float));
  if (a.sparse.isSparse) {
    REQUIRE(a.sparse.indices.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT);
    std::vector<uint32_t> index(size_t(a.sparse.count));
    std::memcpy(index.data(), bytes(a.sparse.indices.bufferView, size_t(a.sparse.indices.byteOffset)), index.size() * 4);
    const auto* values = reinterpret_cast<const float*>(bytes(a.sparse.values.bufferView, size_t(a.sparse.values.byteOffset)));
    for (size_t k = 0; k < index.size(); ++k)
      for (size_t c = 0; c < width; ++c) out[index[k] * width + c] = values[k * width + c];
  }
  return out;
}

const tinygltf::Node& nodeNamed(const tinygltf::Model& m, const std::string& name) {
  for (const tinygltf::Node& n : m.nodes)
    if (n.name == name) return n;
  FAIL("no node " << name);
  return m.nodes.front();
}

}  // namespace

TEST_CASE("bindToSkeleton: wood on its internode, leaves on their organ", "[model][wind]") {
  const Skeleton sk = windTree();
  std::vector<Probe> wood, leaves;
  const std::vector<ExportPart> parts = testParts(sk, wood, leaves);
  std::vector<DVec3> wp, lp;
  for (const Probe& p : wood) wp.push_back(p.still);
  for (const Probe& p : leaves) lp.push_back(p.still);
  const std::vector<WindBinding> wb = bindToSkeleton(wp, sk, false), lb = bindToSkeleton(lp, sk, true);
  for (size_t v = 0; v < wood.size(); ++v) {
    CHECK(wb[v].internode == wood[v].internode);
    CHECK(wb[v].organ == -1);
    CHECK(wb[v].along == Approx(kAt).margin(1e-9));
  }
  for (size_t v = 0; v < leaves.size(); ++v) {
    CHECK(lb[v].organ == leaves[v].organ);
    CHECK(lb[v].internode == sk.organs[size_t(leaves[v].organ)].internode);
  }
  SECTION("_WIND: level, the branch's sway phase, the share of its turn, its frequency") {
    organisms::WindOptions w = wind(5);
    w.loopSeconds = kWindLoopSeconds;
    const organisms::WindRig rig = organisms::windRig(sk, w);
    const glm::vec4 trunk = windAttribute(rig, sk, wb[3 * 1]);  // on the second trunk internode
    CHECK(trunk == glm::vec4(0.0f, float(rig.gustPhase[0]), 0.4375f, 0.25f));  // 1.75 of 4 units; 0.25 Hz: 5 cycles in 20 s
    const glm::vec4 lateral = windAttribute(rig, sk, wb[3 * 5]);  // the first lateral's outer internode
    CHECK(lateral.x == 1.0f);
    CHECK(lateral.y == float(rig.internodes[4].phase1));  // one phase per branch axis
    CHECK(lateral.z == Approx(0.875f));  // half the branch, then 3/4 of its other half
    CHECK(lateral.w == 0.6f);
    const glm::vec4 twig = windAttribute(rig, sk, wb.back());
    CHECK(twig.x == 2.0f);
    CHECK(twig.w == Approx(0.9f));  // 0.6 · 1.5
    const glm::vec4 leaf = windAttribute(rig, sk, lb[2]);  // the first leaf's farthest corner
    CHECK(leaf == glm::vec4(2.0f, float(rig.organs[0].phase), 1.0f, 1.5f));
  }
}

TEST_CASE("addWind: _WIND on every level, a looping sway that is swayInWind linearized", "[model][wind]") {
  const Skeleton sk = windTree();
  std::vector<Probe> wood, leaves;
  std::vector<LodLevel> levels(2);
  levels[0].parts = testParts(sk, wood, leaves);
  levels[1].parts = levels[0].parts;
  levels[1].parts[0].mesh.triangles.resize(2);  // a smaller level
  const Vec3 offset(0.5f, 0.0f, -0.25f);  // as placing the parts on the ground moves them
  for (LodLevel& l : levels)
    for (ExportPart& p : l.parts)
      for (Vec3& x : p.mesh.positions) x += offset;
  const fs::path dir = fs::temp_directory_path() / ("sprig_wind_test_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const double speed = 3;
  addWind(levels, sk, wind(speed), offset);
  writePartLevels(levels, dir / "tree.glb");
  const tinygltf::Model m = readGlb(dir / "tree.glb");

  SECTION("every primitive of every level has _WIND, one VEC4 per vertex") {
    size_t primitives = 0;
    for (const tinygltf::Mesh& mesh : m.meshes)
      for (const tinygltf::Primitive& p : mesh.primitives) {
        REQUIRE(p.attributes.count("_WIND") == 1);
        const tinygltf::Accessor& a = m.accessors[size_t(p.attributes.at("_WIND"))];
        CHECK(a.type == TINYGLTF_TYPE_VEC4);
        CHECK(a.count == m.accessors[size_t(p.attributes.at("POSITION"))].count);
        ++primitives;
      }
    CHECK(primitives == 4);  // wood, leaves at LOD0 and LOD1
    size_t sparse = 0;  // the wood's sway targets: the trunk's vertices do not move
    for (const auto& target : m.meshes[size_t(nodeNamed(m, "wood").mesh)].primitives[0].targets)
      sparse += m.accessors[size_t(target.at("POSITION"))].sparse.isSparse;
    CHECK(sparse > 0);
  }

  SECTION("one animation 'wind' over LOD0's nodes; it loops") {
    REQUIRE(m.animations.size() == 1);
    const tinygltf::Animation& anim = m.animations[0];
    CHECK(anim.name == "wind");
    REQUIRE(anim.channels.size() == 2);
    for (const tinygltf::AnimationChannel& c : anim.channels) {
      CHECK(c.target_path == "weights");
      const tinygltf::AnimationSampler& s = anim.samplers[size_t(c.sampler)];
      CHECK(s.interpolation == "LINEAR");
      const std::vector<float> t = floats(m, s.input), w = floats(m, s.output);
      REQUIRE(t.size() == size_t(kWindLoopSeconds * kWindFps) + 1);
      CHECK(t.front() == 0.0f);
      CHECK(t.back() == float(kWindLoopSeconds));
      const size_t targets = m.meshes[size_t(m.nodes[size_t(c.target_node)].mesh)].primitives[0].targets.size();
      REQUIRE(w.size() == t.size() * targets);
      for (size_t k = 0; k < targets; ++k) CHECK(w[k] == w[w.size() - targets + k]);  // first keyframe = last
    }
    CHECK(m.meshes[size_t(nodeNamed(m, "wood_lod1").mesh)].primitives[0].targets.empty());  // LOD0 alone sways
  }

  SECTION("the morph at a keyframe is swayInWind's displacement within 4% of the largest") {
    organisms::WindOptions w = wind(speed);
    w.loopSeconds = kWindLoopSeconds;
    const tinygltf::Animation& anim = m.animations[0];
    for (int frame : {0, 37, 150, 251}) {
      const double t = kWindLoopSeconds * frame / (kWindLoopSeconds * kWindFps);
      const Skeleton swayed = organisms::swayInWind(sk, w, t);
      for (const tinygltf::AnimationChannel& c : anim.channels) {
        const tinygltf::Node& node = m.nodes[size_t(c.target_node)];
        const tinygltf::Primitive& prim = m.meshes[size_t(node.mesh)].primitives[0];
        const std::vector<float> weights = floats(m, anim.samplers[size_t(c.sampler)].output);
        const std::vector<float> pos = floats(m, prim.attributes.at("POSITION"));
        const std::vector<Probe>& probes = node.name == "wood" ? wood : leaves;
        std::vector<DVec3> morph(probes.size(), DVec3(0)), exact(probes.size());
        double largest = 0, worst = 0;
        for (size_t k = 0; k < prim.targets.size(); ++k) {
          const std::vector<float> d = floats(m, prim.targets[k].at("POSITION"));
          const float wk = weights[size_t(frame) * prim.targets.size() + k];
          for (size_t v = 0; v < probes.size(); ++v) morph[v] += double(wk) * DVec3(d[3 * v], d[3 * v + 1], d[3 * v + 2]);
        }
        for (size_t v = 0; v < probes.size(); ++v) {
          REQUIRE(glm::length(DVec3(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]) - DVec3(offset) - probes[v].still) < 1e-5);
          exact[v] = probes[v].swayed(swayed) - probes[v].still;
          largest = std::max(largest, glm::length(exact[v]));
        }
        for (size_t v = 0; v < probes.size(); ++v) worst = std::max(worst, glm::length(morph[v] - exact[v]));
        INFO(node.name << " frame " << frame << ": largest displacement " << largest << ", worst error " << worst);
        CHECK(largest > 0.01);
        CHECK(worst <= 0.04 * largest);
      }
    }
  }

  SECTION("no wind: _WIND alone, no morph targets, no animation") {
    std::vector<LodLevel> still(1);
    std::vector<Probe> a, b;
    still[0].parts = testParts(sk, a, b);
    addWind(still, sk, wind(0), Vec3(0.0f));
    writePartLevels(still, dir / "still.glb");
    const tinygltf::Model s = readGlb(dir / "still.glb");
    CHECK(s.animations.empty());
    for (const tinygltf::Mesh& mesh : s.meshes) {
      CHECK(mesh.primitives[0].targets.empty());
      CHECK(mesh.primitives[0].attributes.count("_WIND") == 1);
    }
  }
  fs::remove_all(dir);
}
