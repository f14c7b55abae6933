#include "model/blob_kind.h"
#include "core/timer.h"

#include "blobtree/polygonize.h"
#include "model/bark_keys.h"
#include "organisms/tree_builder.h"
#include "model/detail/key_recorder.h"
#include "model/mesh_parts.h"
#include "render/scene.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <map>
#include <utility>

namespace sprig {

namespace {

using blobtree::BlobTree;
using blobtree::NodeId;

constexpr int kMaxDepth = 200;

const std::vector<std::string> kKinds = {
    "point",  "segment",   "cone",      "torus",    "halfspace", "box",       "spiral_points",
    "blend",  "ricci",     "union",     "intersect", "difference", "controlled", "pcm",
    "negative", "translate", "scale",   "rotate",   "bend",      "twist",     "taper"};


// Reads nested blob nodes into one tree, collecting diagnostics.
class NodeReader {
 public:
  NodeReader(BlobTree& tree, DiagnosticList& diags, int textureCount)
      : tree_(tree), diags_(diags), textureCount_(textureCount) {}

  std::optional<NodeId> read(const YNode& node) {
    if (depth_ >= kMaxDepth) {
      node.error(diags_, "blob nodes are nested more than " + std::to_string(kMaxDepth) + " deep");
      return std::nullopt;
    }
    if (auto described = describeOneKey(node, kKinds, "blob_node")) {  // `sprig schema`: one kind's keys
      ++depth_;
      std::optional<NodeId> id = dispatch(described->first.scalar(), described->first, described->second);
      --depth_;
      return id;
    }
    if (!node.isMap() || node.pairs().size() != 1 || !node.pairs()[0].first.isScalar()) {
      node.error(diags_, "a blob node must be a map with one key naming its kind, e.g. {point: {radius: 1}}");
      return std::nullopt;
    }
    auto [keyNode, value] = node.pairs()[0];
    std::string kind = keyNode.scalar();
    ++depth_;
    std::optional<NodeId> id = dispatch(kind, keyNode, value);
    --depth_;
    return id;
  }

 private:
  using Handler = std::optional<NodeId> (NodeReader::*)(const std::string& kind, const YNode& key, const YNode& v);

  /// A node kind's reader and what the kind is (`sprig schema`'s text for its key).
  struct KindEntry {
    Handler read;
    const char* help;
  };

  /// Reads the node of kind `kind` (key) with value v through the kind's handler.
  std::optional<NodeId> dispatch(const std::string& kind, const YNode& key, const YNode& v) {
    static const std::map<std::string, KindEntry, std::less<>> kHandlers = {
        {"point", {&NodeReader::readPoint, "Point primitive: field w·g(d²/R²) around `center`, a sphere of iso radius `radius`."}},
        {"segment", {&NodeReader::readSegment, "Segment primitive: a capsule of constant iso radius `radius` from `a` to `b`."}},
        {"cone", {&NodeReader::readCone, "Cone primitive (the tree paper's internode, Fig. 7): iso radius `radius_a` at `a`, `radius_b` at `b`, linear between, spherical caps."}},
        {"torus", {&NodeReader::readTorus, "Torus primitive: a core circle of radius `major` around `axis` at `center`, tube iso radius `minor`."}},
        {"halfspace", {&NodeReader::readHalfspace, "CSG cutter: the half-space behind the plane through `point`, opposite to `normal` (field 1 inside, 0 outside); no texture."}},
        {"box", {&NodeReader::readBox, "CSG cutter: the box [`lo`, `hi`] (field 1 inside, 0 outside, the surface exactly on the box); no texture."}},
        {"spiral_points", {&NodeReader::readSpiralPoints, "Points on a logarithmic helico-spiral (Murex paper Eq. 1-3), summed: `count` points `step_deg` apart, each of iso radius size·D(θ)."}},
        {"blend", {&NodeReader::readCombination, "Summation blend Σfᵢ of a list of nodes: they melt into each other."}},
        {"union", {&NodeReader::readCombination, "CSG union max fᵢ of a list of nodes: they meet in a crease."}},
        {"intersect", {&NodeReader::readCombination, "CSG intersection min fᵢ of a list of nodes."}},
        {"difference", {&NodeReader::readDifference, "CSG difference [a, b], a minus b: min(f_a, 1 − f_b)."}},
        {"ricci", {&NodeReader::readRicci, "Super-elliptic (Ricci) blend (Σfᵢⁿ)^(1/n) of `children`: n = 1 sums, large n approaches the union."}},
        {"controlled", {&NodeReader::readControlled, "Controlled blending (Murex paper §2.2): `children` blend only within the listed `groups`; groups meet as a union."}},
        {"pcm", {&NodeReader::readPcm, "Precise Contact Modeling (tree paper Eq. 3; Gascuel): `children` deform at their contact with a bulge around it instead of blending."}},
        {"negative", {&NodeReader::readNegative, "Negative field −weight·f of `child`, subtracted where it is blended in (the tree paper's scars)."}},
        {"translate", {&NodeReader::readTranslate, "`child` moved by `offset`."}},
        {"scale", {&NodeReader::readScale, "`child` scaled about the origin by `factors` (the field is not rescaled)."}},
        {"rotate", {&NodeReader::readRotate, "`child` rotated by `angle_deg` about `axis` through the origin."}},
        {"bend", {&NodeReader::readBend, "Endpoint-preserving bend (tree paper §3.6): `child`, modelled straight from `a` to `b`, bent on a circular arc through both."}},
        {"twist", {&NodeReader::readTwist, "`child` twisted about `axis` through `origin` by `rate_deg` per unit of height."}},
        {"taper", {&NodeReader::readTaper, "`child`'s cross-section scaled linearly along `axis`, from `scale0` at `origin` to `scale1` at `length`."}},
    };
    if (auto it = kHandlers.find(kind); it != kHandlers.end()) {
      describeHelp(v, it->second.help);
      return (this->*it->second.read)(kind, key, v);
    }
    key.error(diags_, "unknown blob node " + sprig::quoted(kind) + didYouMean(kind, kKinds));
    return std::nullopt;
  }

  std::optional<NodeId> readPoint(const std::string& kind, const YNode& key, const YNode& v) {
    return primitive(key, v, kind, [&](MapReader& m) -> std::optional<NodeId> {
      Vec3 c = m.vec3({"center", "Centre of the point."}, Vec3(0.0f));
      auto r = required(m, {"radius", "Iso radius: the surface (F = 0.5) of the point alone lies this far from `center`."});
      auto tex = texture(m);
      if (!r) return std::nullopt;
      return build(key, [&] { return tree_.point(c, float(*r), tex); });
    });
  }

  std::optional<NodeId> readSegment(const std::string& kind, const YNode& key, const YNode& v) {
    return primitive(key, v, kind, [&](MapReader& m) -> std::optional<NodeId> {
      auto a = requiredVec3(m, {"a", "First end of the segment."}), b = requiredVec3(m, {"b", "Second end of the segment."});
      auto r = required(m, {"radius", "Iso radius of the capsule around the segment."});
      auto tex = texture(m);
      if (!a || !b || !r) return std::nullopt;
      return build(key, [&] { return tree_.segment(*a, *b, float(*r), tex); });
    });
  }

  std::optional<NodeId> readCone(const std::string& kind, const YNode& key, const YNode& v) {
    return primitive(key, v, kind, [&](MapReader& m) -> std::optional<NodeId> {
      auto a = requiredVec3(m, {"a", "Base of the cone (natural v = 0)."}), b = requiredVec3(m, {"b", "Tip of the cone."});
      std::optional<double> ra, rb;
      if (m.has("radius")) {
        ra = rb = m.number({"radius", "One iso radius for both ends, instead of `radius_a` and `radius_b`; > 0 (default: none)."}, 0.0);
      } else {
        ra = required(m, {"radius_a", "Iso radius at `a` (required without `radius`)."}, 0.0, std::numeric_limits<double>::infinity(), false);
        rb = required(m, {"radius_b", "Iso radius at `b` (required without `radius`)."}, 0.0, std::numeric_limits<double>::infinity(), false);
      }
      // `delta_a` names the factor 1.75 in a tree: section; here the radius r_B had the name.
      if (auto old = m.get({"delta_a", "Not a key here any more: an error naming `offset_radius`, its new name."}))
        old->error(diags_, "a blob cone's 'delta_a' is now 'offset_radius' (r_B of Eq. 4: the cone is shortened "
                           "by 1.75*offset_radius); 'delta_a' is the factor 1.75 of a tree: section");
      double offsetRadius = m.number({"offset_radius", "r_B of the tree paper's Eq. 4: the cone is shortened at `b` by δA = 1.75·offset_radius (0 = not shortened)."}, 0.0, 0.0);
      auto tex = texture(m);
      if (!a || !b || !ra || !rb) return std::nullopt;
      // Tree paper Eq. 4: the basal internode is shortened at its tip by δA = 1.75·r_B.
      Vec3 tip = *b;
      double rTip = *rb;
      if (offsetRadius > 0) {
        float len = glm::length(*b - *a);
        float cut = float(1.75 * offsetRadius);
        if (cut >= len) {
          m.get("offset_radius")->error(diags_, "'offset_radius' shortens the cone by 1.75*" +
                                                    std::to_string(offsetRadius) + ", more than its length " +
                                                    std::to_string(len));
          return std::nullopt;
        }
        float t = 1.0f - cut / len;
        tip = *a + t * (*b - *a);
        rTip = *ra + t * (*rb - *ra);
      }
      return build(key, [&] { return tree_.cone(*a, tip, float(*ra), float(rTip), tex); });
    });
  }

  std::optional<NodeId> readTorus(const std::string& kind, const YNode& key, const YNode& v) {
    return primitive(key, v, kind, [&](MapReader& m) -> std::optional<NodeId> {
      Vec3 c = m.vec3({"center", "Centre of the torus."}, Vec3(0.0f));
      Vec3 axis = m.vec3({"axis", "Axis the torus turns around."}, Vec3(0, 1, 0));
      auto major = required(m, {"major", "Major radius: of the core circle around `axis`."}),
           minor = required(m, {"minor", "Minor radius: iso radius of the tube around the core circle."});
      auto tex = texture(m);
      if (!major || !minor) return std::nullopt;
      return build(key, [&] { return tree_.torus(c, axis, float(*major), float(*minor), tex); });
    });
  }

  std::optional<NodeId> readHalfspace(const std::string& kind, const YNode& key, const YNode& v) {
    return operands(key, v, kind, [&](MapReader& m) -> std::optional<NodeId> {
      Vec3 p = m.vec3({"point", "A point of the cutting plane."}, Vec3(0.0f));
      auto n = requiredVec3(m, {"normal", "Outward normal of the plane: the inside is the side it points away from."});
      double ramp = m.number({"ramp", "Width of the field's linear ramp from 1 to 0 across the plane, in world units."}, 1e-3, 1e-9);
      if (!n) return std::nullopt;
      return build(key, [&] { return tree_.halfspace(p, *n, float(ramp)); });
    });
  }

  std::optional<NodeId> readBox(const std::string& kind, const YNode& key, const YNode& v) {
    return operands(key, v, kind, [&](MapReader& m) -> std::optional<NodeId> {
      auto lo = requiredVec3(m, {"lo", "Lowest corner of the box."}), hi = requiredVec3(m, {"hi", "Highest corner of the box."});
      double ramp = m.number({"ramp", "Width of the field's linear ramp from 1 to 0 across the box's faces, in world units."}, 1e-3, 1e-9);
      if (!lo || !hi) return std::nullopt;
      return build(key, [&] { return tree_.box(*lo, *hi, float(ramp)); });
    });
  }

  std::optional<NodeId> readSpiralPoints(const std::string& kind, const YNode& key, const YNode& v) {
    return operands(key, v, kind, [&](MapReader& m) { return spiral(key, m); });
  }

  std::optional<NodeId> readCombination(const std::string& kind, const YNode& key, const YNode& v) {
      auto kids = childList(v, kind);
      if (!kids) return std::nullopt;
      return build(key, [&] {
        return kind == "blend" ? tree_.blend(*kids) : kind == "union" ? tree_.unite(*kids) : tree_.intersect(*kids);
      });
  }

  std::optional<NodeId> readDifference(const std::string& kind, const YNode& key, const YNode& v) {
      auto kids = childList(v, kind);
      if (!kids) return std::nullopt;
      if (kids->size() != 2) {
        v.error(diags_, "'difference' takes exactly two nodes [a, b] (a minus b), got " +
                            std::to_string(kids->size()));
        return std::nullopt;
      }
      return build(key, [&] { return tree_.difference((*kids)[0], (*kids)[1]); });
  }

  std::optional<NodeId> readRicci(const std::string& kind, const YNode& key, const YNode& v) {
    return operands(key, v, kind, [&](MapReader& m) -> std::optional<NodeId> {
      auto n = required(m, {"n", "Blend exponent n: 1 is the plain sum, 400 keeps the children distinct (the Murex's bumps)."}, 1.0, 1e4);
      auto kids = children(m, kind);
      if (!n || !kids) return std::nullopt;
      return build(key, [&] { return tree_.ricci(*kids, float(*n)); });
    });
  }

  std::optional<NodeId> readControlled(const std::string& kind, const YNode& key, const YNode& v) {
    return operands(key, v, kind, [&](MapReader& m) { return controlled(key, m); });
  }

  std::optional<NodeId> readPcm(const std::string& kind, const YNode& key, const YNode& v) {
    return operands(key, v, kind, [&](MapReader& m) -> std::optional<NodeId> {
      blobtree::PcmParams p;
      p.width = float(m.number({"width", "w, width of the propagation region around the contact, in field units."}, p.width, 1e-6, 1.0));
      p.slope = float(m.number({"slope", "k, slope of the bulge at the contact (1 gives a C¹ field; <= 1 never interpenetrates)."}, p.slope, 0.0, 10.0));
      p.bulgeScale = float(m.number({"bulge", "Height of the bulge: a₀ = bulge · k·w/4 (0 = no bulge)."}, p.bulgeScale, 0.0, 10.0));
      auto kids = children(m, kind);
      if (!kids) return std::nullopt;
      return build(key, [&] { return tree_.pcm(*kids, p); });
    });
  }

  std::optional<NodeId> readNegative(const std::string& kind, const YNode& key, const YNode& v) {
    return operands(key, v, kind, [&](MapReader& m) -> std::optional<NodeId> {
      double w = m.number({"weight", "Multiplier of the child's field before it is negated."}, 1.0, 0.0, 1e3);
      auto c = child(m, kind);
      if (!c) return std::nullopt;
      return build(key, [&] { return tree_.negative(*c, float(w)); });
    });
  }

  std::optional<NodeId> readTranslate(const std::string& kind, const YNode& key, const YNode& v) {
    return operands(key, v, kind, [&](MapReader& m) -> std::optional<NodeId> {
      auto off = requiredVec3(m, {"offset", "Translation of the child, in world units."});
      auto c = child(m, kind);
      if (!off || !c) return std::nullopt;
      return build(key, [&] { return tree_.translate(*c, *off); });
    });
  }

  std::optional<NodeId> readScale(const std::string& kind, const YNode& key, const YNode& v) {
    return operands(key, v, kind, [&](MapReader& m) -> std::optional<NodeId> {
      std::optional<Vec3> f;
      m.markRequired("factors");
      if (auto fv = m.get({"factors", "Scale factors: one number (uniform) or [x, y, z]."})) {
        if (fv->isSequence())
          f = fv->asVec3(diags_, "'factors'", 1e-6, 1e6);
        else if (auto s = fv->asNumber(diags_, "'factors'", 1e-6, 1e6))
          f = Vec3(float(*s));
      } else {
        m.node().error(diags_, "missing required key 'factors' in scale");
      }
      auto c = child(m, kind);
      if (!f || !c) return std::nullopt;
      return build(key, [&] { return tree_.scale(*c, *f); });
    });
  }

  std::optional<NodeId> readRotate(const std::string& kind, const YNode& key, const YNode& v) {
    return operands(key, v, kind, [&](MapReader& m) -> std::optional<NodeId> {
      Vec3 axis = m.vec3({"axis", "Axis of the rotation, through the origin."}, Vec3(0, 1, 0));
      auto deg = required(m, {"angle_deg", "Angle of the rotation, in degrees."}, -3600.0, 3600.0);
      auto c = child(m, kind);
      if (!deg || !c) return std::nullopt;
      return build(key, [&] { return tree_.rotate(*c, axis, float(radians(*deg))); });
    });
  }

  std::optional<NodeId> readBend(const std::string& kind, const YNode& key, const YNode& v) {
    return operands(key, v, kind, [&](MapReader& m) -> std::optional<NodeId> {
      blobtree::Bend bend;
      auto a = requiredVec3(m, {"a", "First end of the bent segment: it stays in place."}),
           b = requiredVec3(m, {"b", "Second end of the bent segment: it stays in place."});
      bend.direction = m.vec3({"direction", "Direction the arc bulges towards (made perpendicular to b − a)."}, bend.direction);
      bool hasAngle = m.has("angle_deg"), hasSagitta = m.has("sagitta");
      double angle = m.number({"angle_deg", "Turning angle of the arc in degrees (exactly one of `angle_deg` and `sagitta`)."}, 0.0, 0.0, 180.0);
      double sagitta = m.number({"sagitta", "Distance of the arc from the chord at its middle, in world units; at most |b − a|/2 (exactly one of `sagitta` and `angle_deg`)."}, 0.0, 0.0);
      if (hasAngle == hasSagitta)
        m.node().error(diags_, "bend needs exactly one of 'sagitta' and 'angle_deg'");
      auto c = child(m, kind);
      if (!a || !b || !c || hasAngle == hasSagitta) return std::nullopt;
      if (hasAngle) bend = blobtree::Bend::fromAngle(*a, *b, bend.direction, float(radians(angle)));
      else bend.a = *a, bend.b = *b, bend.sagitta = float(sagitta);
      return build(key, [&] { return tree_.bend(*c, bend); });
    });
  }

  std::optional<NodeId> readTwist(const std::string& kind, const YNode& key, const YNode& v) {
    return operands(key, v, kind, [&](MapReader& m) -> std::optional<NodeId> {
      blobtree::Twist t;
      t.origin = m.vec3({"origin", "A point of the twist axis (height 0)."}, t.origin);
      t.axis = m.vec3({"axis", "Axis of the twist."}, t.axis);
      auto rate = required(m, {"rate_deg", "Twist in degrees per unit of height along the axis."}, -1e6, 1e6);
      auto c = child(m, kind);
      if (!rate || !c) return std::nullopt;
      t.rateRadPerUnit = float(radians(*rate));
      return build(key, [&] { return tree_.twist(*c, t); });
    });
  }

  std::optional<NodeId> readTaper(const std::string& kind, const YNode& key, const YNode& v) {
    return operands(key, v, kind, [&](MapReader& m) -> std::optional<NodeId> {
      blobtree::Taper t;
      t.origin = m.vec3({"origin", "Where the taper starts (height 0, scale `scale0`)."}, t.origin);
      t.axis = m.vec3({"axis", "Axis of the taper."}, t.axis);
      auto len = required(m, {"length", "Height along the axis at which the scale reaches `scale1`."}, 0.0);
      t.scale0 = float(m.number({"scale0", "Cross-section scale at `origin`; must stay positive over the child."}, 1.0, 0.0));
      t.scale1 = float(m.number({"scale1", "Cross-section scale at height `length` (linear between)."}, 1.0, 0.0));
      auto c = child(m, kind);
      if (!len || !c) return std::nullopt;
      t.length = float(*len);
      return build(key, [&] { return tree_.taper(*c, t); });
    });
  }

  // A node whose value is a parameter map; reads it with f and reports unknown keys.
  template <class F>
  std::optional<NodeId> operands(const YNode& key, const YNode& v, const std::string& kind, F&& f) {
    (void)key;
    if (!v.isMap()) {
      v.error(diags_, sprig::quoted(kind) + " must be a map of its parameters");
      return std::nullopt;
    }
    MapReader m(v, diags_, kind);
    std::string outer = std::exchange(context_, kind);
    std::optional<NodeId> id = f(m);
    context_ = outer;
    m.finish();
    return id;
  }

  // A primitive: as operands, plus the field `weight`.
  template <class F>
  std::optional<NodeId> primitive(const YNode& key, const YNode& v, const std::string& kind, F&& f) {
    return operands(key, v, kind, [&](MapReader& m) -> std::optional<NodeId> {
      double w = m.number({"weight", "Multiplier w of the primitive's field."}, 1.0, 0.0, 1e3);
      auto id = f(m);
      if (id && w != 1.0) return build(key, [&] { return tree_.setWeight(*id, float(w)); });
      return id;
    });
  }

  // Runs a builder call with the key's location attached to its errors.
  template <class F>
  std::optional<NodeId> build(const YNode& at, F&& f) {
    tree_.setSourceLoc(at.loc());
    try {
      return f();
    } catch (const InputError& e) {
      for (Diagnostic d : e.diagnostics()) {
        if (d.loc.file.empty()) d.loc = at.loc();
        if (d.sourceLine.empty() && d.loc.file == at.loc().file) d.sourceLine = at.file().sourceLine(d.loc.line);
        diags_.add(std::move(d));
      }
    } catch (const std::exception& e) {
      at.error(diags_, e.what());
    }
    return std::nullopt;
  }

  // declare: list key in the schema's `required` (not for a key required only when
  // another is absent, as a cone's radius_a without radius).
  std::optional<double> required(MapReader& m, Key key, double min = 0.0,
                                 double max = std::numeric_limits<double>::infinity(), bool declare = true) {
    if (declare) m.markRequired(key.name);
    auto v = m.get(key);
    if (!v) {
      m.node().error(diags_, "missing required key " + quoted(key.name) + " in " + kindOf(m));
      return std::nullopt;
    }
    return v->asNumber(diags_, quoted(key.name), min, max);
  }

  std::optional<Vec3> requiredVec3(MapReader& m, Key key) {
    m.markRequired(key.name);
    auto v = m.get(key);
    if (!v) {
      m.node().error(diags_, "missing required key " + quoted(key.name) + " in " + kindOf(m));
      return std::nullopt;
    }
    return v->asVec3(diags_, quoted(key.name));
  }

  std::string kindOf(MapReader& m) const {
    (void)m;
    return context_;
  }

  // A primitive's `texture: {id, u_scale, ...}`; without it the primitive carries
  // kNoTexture and shows the material color.
  blobtree::TextureAttr texture(MapReader& m) {
    blobtree::TextureAttr t;
    t.textureId = kNoTexture;
    auto tv = m.section({"texture", "The primitive's texture: `id` into the species' `textures:` list and the mapping of its natural (u, v) (default: none, the material colour)."});
    if (!tv) return t;
    MapReader tm(*tv, diags_, "texture");
    if (auto idNode = tm.get({"id", "Index of the texture in the species' `textures:` list (0 = the first); required."})) {
      if (textureCount_ == 0) {
        idNode->error(diags_, "texture id " + idNode->scalar() +
                                  " names no texture: the species has no 'textures:' list");
      } else if (auto id = idNode->asInteger(diags_, "'id'", 0,
                                             // `sprig schema`: the list's length is the file's, not a constant
                                             textureCount_ < 0 || detail::KeyRecorder::active() ? kNoTexture - 1
                                                                                                 : textureCount_ - 1)) {
        t.textureId = uint16_t(*id);
      }
    } else {
      tm.node().error(diags_, "missing required key 'id' in texture (an index into the species' 'textures:' list)");
    }
    t.uvScale = Vec2(float(tm.number({"u_scale", "Multiplier of the natural u (uv = natural · scale + offset)."}, 1.0)),
                     float(tm.number({"v_scale", "Multiplier of the natural v (uv = natural · scale + offset)."}, 1.0)));
    t.uvOffset = Vec2(float(tm.number({"u_offset", "Added to u after `u_scale`."}, 0.0)),
                      float(tm.number({"v_offset", "Added to v after `v_scale`."}, 0.0)));
    t.refDir = tm.vec3({"ref_dir", "Direction of u = 0 around a cone's, segment's or torus's axis ([0, 0, 0]: a fixed perpendicular)."}, t.refDir);
    tm.finish();
    return t;
  }

  // A sequence of nodes (the value itself); nullopt after an error.
  std::optional<std::vector<NodeId>> childList(const YNode& seq, const std::string& kind) {
    if (!seq.isSequence()) {
      seq.error(diags_, sprig::quoted(kind) + " must be a sequence of blob nodes");
      return std::nullopt;
    }
    auto items = seq.items();
    if (items.empty()) {
      seq.error(diags_, sprig::quoted(kind) + " needs at least one node");
      return std::nullopt;
    }
    std::vector<NodeId> ids;
    bool ok = true;
    for (const auto& item : items) {
      auto id = read(item);
      if (id) ids.push_back(*id);
      else ok = false;
    }
    if (!ok) return std::nullopt;
    return ids;
  }

  std::optional<std::vector<NodeId>> children(MapReader& m, const std::string& kind) {
    m.markRequired("children");
    auto v = m.get({"children", "The nodes it combines, a list of blob nodes (at least one)."});
    if (!v) {
      m.node().error(diags_, "missing required key 'children' in " + kind);
      return std::nullopt;
    }
    return childList(*v, kind + " children");
  }

  std::optional<NodeId> child(MapReader& m, const std::string& kind) {
    m.markRequired("child");
    auto v = m.get({"child", "The blob node it acts on."});
    if (!v) {
      m.node().error(diags_, "missing required key 'child' in " + kind);
      return std::nullopt;
    }
    return read(*v);
  }

  // Controlled blending (murex paper Eq. 6): children blend only within the listed groups.
  std::optional<NodeId> controlled(const YNode& key, MapReader& m) {
    auto kids = children(m, "controlled");
    std::vector<std::vector<uint32_t>> groups;
    m.markRequired("groups");
    auto gv = m.get({"groups", "Which children blend: lists of child indices, e.g. [[0, 1], [1, 2]], or `chain` (each child with the next)."});
    if (!gv) {
      m.node().error(diags_, "missing required key 'groups' in controlled (a list of index lists, or chain)");
      return std::nullopt;
    }
    if (!kids) return std::nullopt;
    uint32_t n = uint32_t(kids->size());
    if (gv->isScalar()) {
      if (gv->scalar() != "chain") {
        gv->error(diags_, "'groups' must be a list of index lists or 'chain', got '" + gv->scalar() + "'");
        return std::nullopt;
      }
      for (uint32_t i = 0; i + 1 < n; ++i) groups.push_back({i, i + 1});
      if (n == 1) groups.push_back({0});
    } else if (gv->isSequence()) {
      bool ok = true;
      for (const auto& g : gv->items()) {
        if (!g.isSequence()) {
          g.error(diags_, "each group must be a list of child indices, e.g. [0, 1]");
          ok = false;
          continue;
        }
        std::vector<uint32_t> group;
        for (const auto& i : g.items()) {
          auto idx = i.asInteger(diags_, "a child index", 0, int64_t(n) - 1);
          if (idx) group.push_back(uint32_t(*idx));
          else ok = false;
        }
        groups.push_back(std::move(group));
      }
      if (!ok) return std::nullopt;
    } else {
      gv->error(diags_, "'groups' must be a list of index lists or 'chain'");
      return std::nullopt;
    }
    return build(key, [&] { return tree_.controlledBlend(*kids, groups); });
  }

  // Points on a logarithmic helico-spiral (murex paper Eq. 1-3), blended by summation.
  // R(θ) = r0·λ^(θ/360°), H(θ) = R(θ)·cot β (the shell grows downwards, apex at the
  // origin, axis +Y), and the tangent-circle size D(θ) = R(θ)(λ−1)/((λ+1) sin β) scaled
  // by `size`.
  std::optional<NodeId> spiral(const YNode& key, MapReader& m) {
    double r0 = m.number({"r0", "R₀, the spiral's radius at θ = 0: R(θ) = R₀·λ^(θ/360°)."}, 1.0, 1e-6);
    double lambda = m.number({"lambda", "λ, the ratio of the spiral's radii one turn apart (Murex paper Eq. 1)."}, 1.3, 1.0 + 1e-6, 100.0);
    double beta = radians(m.number({"beta_deg", "β in degrees: the spiral descends H(θ) = R(θ)·cot β (90 = flat)."}, 22.5, 1e-3, 90.0));
    double theta0 = m.number({"theta_deg", "Angle θ of the first point, in degrees."}, 0.0, -1e5, 1e5);
    double step = m.number({"step_deg", "Angle between successive points, in degrees."}, 20.0, -360.0, 360.0);
    int64_t count = m.integer({"count", "Number of points."}, 6, 1, 100000);
    double size = m.number({"size", "Multiplier of each point's iso radius D(θ) = R(θ)(λ−1)/((λ+1) sin β)."}, 1.0, 1e-6, 100.0);
    std::vector<NodeId> ids;
    for (int64_t i = 0; i < count; ++i) {
      double thetaDeg = theta0 + double(i) * step;
      double R = r0 * std::pow(lambda, thetaDeg / 360.0);
      double H = R / std::tan(beta);
      double D = R * (lambda - 1.0) / ((lambda + 1.0) * std::sin(beta));
      double th = radians(thetaDeg);
      Vec3 c(float(R * std::cos(th)), float(-H), float(R * std::sin(th)));
      blobtree::TextureAttr none;
      none.textureId = kNoTexture;
      auto id = build(key, [&] { return tree_.point(c, float(size * D), none); });
      if (!id) return std::nullopt;
      ids.push_back(*id);
    }
    if (ids.size() == 1) return ids[0];
    return build(key, [&] { return tree_.blend(ids); });
  }

  BlobTree& tree_;
  DiagnosticList& diags_;
  int textureCount_ = -1;  // textures the ids may name; -1: any id
  int depth_ = 0;
  std::string context_;  // the kind whose parameter map is being read
};

}  // namespace

std::optional<blobtree::NodeId> readBlobNode(const YNode& node, blobtree::BlobTree& tree, DiagnosticList& diags,
                                             int textureCount) {
  NodeReader reader(tree, diags, textureCount);
  return reader.read(node);
}

namespace {

const std::vector<std::string> kTextureKinds = {"image", "color", "noise", "bark", "stripes", "spots", "leaf"};

/// What each texture kind is (`sprig schema`'s text for its key).
std::string_view textureKindHelp(std::string_view kind) {
  static const HelpTable kHelp = {
      {"image", "An image file (PNG, JPEG, EXR, ...; a path relative to the species file), looked up at (u, v)."},
      {"color", "One constant colour."},
      {"noise", "Two colours mixed by fractal noise (fBm or turbulence)."},
      {"bark", "Procedural bark: ridged furrows along v, with the bark keys of trees' `tree.bark:`."},
      {"stripes", "Bands of `stripe_color` on `base_color`, across v (or along u with `spiral`)."},
      {"spots", "Round spots of `spot_color` on `base_color`, one per cell of a jittered grid."},
      {"leaf", "A leaf blade with a midrib and lateral veins."}};
  return helpIn(kHelp, kind);
}

uint64_t readSeed(MapReader& m) { return uint64_t(m.integer({"seed", "Seed of the texture's noise or random cells."}, 0, 0)); }

// One procedural texture's options map (null reads as all defaults).
std::optional<textures::Texture> readProcedural(const std::string& kind, const YNode& v, DiagnosticList& diags,
                                                std::optional<textures::BarkLook>* ridge) {
  if (!v.isMap() && !v.isNull()) {
    v.error(diags, sprig::quoted(kind) + " must be a map of its options, e.g. {" + kind + ": {seed: 1}}");
    return std::nullopt;
  }
  MapReader m(v, diags, kind);
  std::optional<textures::Texture> out;
  if (kind == "noise") {
    textures::NoiseColorOptions o;
    o.colorA = m.color({"color_a", "Colour where the noise is low."}, o.colorA);
    o.colorB = m.color({"color_b", "Colour where the noise is high."}, o.colorB);
    o.scale = m.number({"scale", "Noise features per unit."}, o.scale, 1e-6, 1e6);
    o.fractal.octaves = int(m.integer({"octaves", "Layers of noise summed (fBm)."}, o.fractal.octaves, 1, 16));
    o.fractal.lacunarity = m.number({"lacunarity", "Frequency ratio between successive octaves."}, o.fractal.lacunarity, 1.0, 16.0);
    o.fractal.gain = m.number({"gain", "Amplitude ratio between successive octaves."}, o.fractal.gain, 0.0, 1.0);
    o.turbulence = m.boolean({"turbulence", "Turbulence (sharp creases) instead of fBm."}, o.turbulence);
    o.solid = m.boolean({"solid", "A solid texture: looked up at the 3-D point instead of (u, v, 0)."}, o.solid);
    o.seed = readSeed(m);
    out = textures::NoiseTexture(o);
  } else if (kind == "bark") {
    // The bark keys tree species read too (model/bark_keys.h), plus the texture's tiling and seed.
    textures::BarkLook look;
    look.pattern.tileV = int(m.integer({"tile_v", "Repeat the pattern every this many units of v, frequencies along v rounded to whole cycles (0 = no tiling)."}, look.pattern.tileV, 0, 100000));
    readBarkLook(m, look);
    textures::BarkOptions o = look.resolved(look.pattern.ridgeColor, look.pattern.furrowColor);
    o.seed = readSeed(m);
    out = textures::BarkTexture(o);
    if (ridge && look.hasRidge()) {
      if (*ridge)
        v.error(diags, "the branch bark ridge keys (ridge_darkening, ridge_relief, ridge_arc, ...) shade the whole "
                       "blob: set them on one bark texture only");
      else
        *ridge = look;
    }
  } else if (kind == "stripes") {
    textures::StripesOptions o;
    o.frequency = m.number({"frequency", "Bands per unit."}, o.frequency, 0.0, 1e6);
    o.duty = m.number({"duty", "Fraction of each period in `stripe_color`."}, o.duty, 0.0, 1.0);
    o.wobble = m.number({"wobble", "Waviness of the bands, in periods."}, o.wobble, 0.0, 100.0);
    o.softness = m.number({"softness", "Width of the bands' edges, in periods."}, o.softness, 0.0, 1.0);
    o.spiral = m.boolean({"spiral", "Bands at constant u (along the growth direction) instead of constant v."}, o.spiral);
    o.baseColor = m.color({"base_color", "Colour between the stripes."}, o.baseColor);
    o.stripeColor = m.color({"stripe_color", "Colour of the stripes."}, o.stripeColor);
    o.seed = readSeed(m);
    out = textures::StripesTexture(o);
  } else if (kind == "spots") {
    textures::SpotsOptions o;
    o.frequency = m.number({"frequency", "Grid cells per unit (one spot at most per cell)."}, o.frequency, 0.0, 1e6);
    o.radius = m.number({"radius", "Mean spot radius, in cells."}, o.radius, 0.0, 2.0);
    o.radiusJitter = m.number({"radius_jitter", "Relative variation of the spot radius."}, o.radiusJitter, 0.0, 1.0);
    o.jitter = m.number({"jitter", "Displacement of the spot centres, in cells (up to ± jitter/2)."}, o.jitter, 0.0, 1.0);
    o.softness = m.number({"softness", "Width of the spots' edges, in cells."}, o.softness, 0.0, 1.0);
    o.density = m.number({"density", "Fraction of the cells that hold a spot."}, o.density, 0.0, 1.0);
    o.baseColor = m.color({"base_color", "Colour between the spots."}, o.baseColor);
    o.spotColor = m.color({"spot_color", "Colour of the spots."}, o.spotColor);
    o.seed = readSeed(m);
    out = textures::SpotsTexture(o);
  } else {  // leaf
    textures::LeafOptions o;
    o.veins = int(m.integer({"veins", "Pairs of lateral veins."}, o.veins, 0, 1000));
    o.veinAngleDeg = m.number({"vein_angle_deg", "Angle of the lateral veins to the midrib, in degrees."}, o.veinAngleDeg, 0.0, 90.0);
    o.veinWidth = m.number({"vein_width", "Half width of a vein, in units of u."}, o.veinWidth, 0.0, 0.5);
    o.bladeColor = m.color({"blade_color", "Colour of the leaf blade."}, o.bladeColor);
    o.veinColor = m.color({"vein_color", "Colour of the veins."}, o.veinColor);
    o.mottle = m.number({"mottle", "Strength of the fBm mottling of the blade."}, o.mottle, 0.0, 10.0);
    o.seed = readSeed(m);
    out = textures::LeafTexture(o);
  }
  m.finish();
  return out;
}

// `image: PATH`: resolved against the species file with policy, opened now so a missing
// or unreadable file is reported at the path before anything is rendered.
std::optional<textures::Texture> readImage(const YNode& v, const PathPolicy& policy, DiagnosticList& diags) {
  if (!v.isScalar()) {
    v.error(diags, "'image' must be a file name (a path relative to the species file)");
    return std::nullopt;
  }
  auto path = resolveReference(v, v.scalar(), policy, diags, /*mustExist=*/false);
  if (!path) return std::nullopt;
  try {
    return textures::ImageTexture::open(path->string(), v.loc());
  } catch (const InputError& e) {
    for (Diagnostic d : e.diagnostics()) {
      if (d.sourceLine.empty() && d.loc.file == v.loc().file) d.sourceLine = v.file().sourceLine(d.loc.line);
      diags.add(std::move(d));
    }
  }
  return std::nullopt;
}

}  // namespace

std::shared_ptr<const textures::TextureRegistry> readBlobTextures(const YNode& list, const PathPolicy& policy,
                                                                  DiagnosticList& diags,
                                                                  std::optional<textures::BarkLook>* ridge) {
  auto registry = std::make_shared<textures::TextureRegistry>();
  if (!list.isSequence()) {
    list.error(diags, "'textures' must be a sequence of textures, e.g. [{image: maps/bark.png}, {stripes: {}}]");
    return registry;
  }
  const auto items = list.items();
  if (items.size() >= kNoTexture) {
    list.error(diags, "'textures' holds " + std::to_string(items.size()) + " textures, more than " +
                          std::to_string(kNoTexture - 1));
    return registry;
  }
  for (const YNode& entry : items) {
    auto kindAndValue = describeOneKey(entry, kTextureKinds, "texture");  // `sprig schema`: one kind's keys
    if (!kindAndValue) {
      if (!entry.isMap() || entry.pairs().size() != 1 || !entry.pairs()[0].first.isScalar()) {
        entry.error(diags, "a texture must be a map with one key naming its kind, e.g. {image: maps/bark.png} "
                           "or {stripes: {frequency: 8}}");
        continue;
      }
      kindAndValue = entry.pairs()[0];  // a copy: pairs() is a temporary
    }
    const auto [key, value] = *kindAndValue;
    const std::string kind = key.scalar();
    describeHelp(value, textureKindHelp(kind));
    std::optional<textures::Texture> t;
    if (kind == "image") {
      t = readImage(value, policy, diags);
    } else if (kind == "color") {
      if (auto c = value.asColor(diags, "'color'")) t = textures::ConstantTexture{*c};
    } else if (std::find(kTextureKinds.begin(), kTextureKinds.end(), kind) != kTextureKinds.end()) {
      t = readProcedural(kind, value, diags, ridge);
    } else {
      key.error(diags, "unknown texture kind " + sprig::quoted(kind) + didYouMean(kind, kTextureKinds) +
                           " (image, color, noise, bark, stripes, spots or leaf)");
    }
    if (t) registry->add(std::move(*t));
  }
  return registry;
}

std::optional<BlobSpecies> readBlobSpecies(MapReader& top, DiagnosticList& diags, const PathPolicy& policy) {
  std::string kernel = top.choice({"kernel", "Field kernel of every primitive: `wyvill` (1 − s)³ or `soft` (the soft-object kernel, iso radius exactly R/2)."}, "wyvill", {"wyvill", "soft"});
  float cell = 0.0f;
  if (auto mesh = top.section({"mesh", "How `sprig mesh` polygonizes the blob: `cell` size (default automatic)."})) {
    MapReader mm(*mesh, diags, "mesh");
    cell = float(mm.number({"cell", "Cell size of the polygonizer, in world units (0 = automatic)."}, 0.0, 0.0, 1e6));
    mm.finish();
  }
  auto blob = top.get({"blob", "The BlobTree written out node by node: one node (a primitive, a blend, a CSG operation, a warp) with its children."});
  if (!blob) {
    top.node().error(diags, "missing required key 'blob' in species file (the BlobTree of a kind: blob species)");
    return std::nullopt;
  }
  // Textures first, so primitives' texture ids can be checked against their count.
  std::shared_ptr<const textures::TextureRegistry> registry;
  std::optional<textures::BarkLook> ridge;
  int textureCount = 0;
  if (auto list = top.get({"textures", "Texture ids 0, 1, ... in order, each `{image: PATH}`, `{color: C}` or a procedural texture (`noise`, `bark`, `stripes`, `spots`, `leaf`); primitives name them with `texture: {id}`."})) {
    registry = readBlobTextures(*list, policy, diags, &ridge);
    // Ids are checked against the list's length (not the registry's, which leaves out
    // broken entries), so one mistake is reported once; no list checks nothing more.
    textureCount = list->isSequence() ? int(list->items().size()) : -1;
    if (registry->size() == 0) registry.reset();
  }
  BlobSpecies s{.name = {},
                .tree = blobtree::BlobTree(kernel == "soft" ? blobtree::Kernel::SoftObject : blobtree::Kernel::Wyvill),
                .root = 0,
                .cellSize = cell,
                .textures = registry,
                .ridge = ridge};
  auto root = readBlobNode(*blob, s.tree, diags, textureCount);
  if (!root) return std::nullopt;
  s.root = *root;
  if (ridge && ridge->ridgeArc.height > 0) {
    // The raised branch bark ridges over the blob's branches, summed into the whole blob.
    std::vector<blobtree::NodeId> raised{s.root};
    for (const textures::RidgeArc& arc : blobRidgeArcs(s.tree, s.root))
      if (auto r = organisms::raisedRidgeArc(s.tree, s.root, arc, ridge->ridgeArc)) raised.push_back(*r);
    if (raised.size() > 1) s.root = s.tree.blend(raised);
  }
  return s;
}

namespace {

BlobSpecies readWhole(const std::shared_ptr<const YamlFile>& file, DiagnosticList& diags, const std::string& stem,
                      const PathPolicy& policy) {
  if (!file) diags.throwIfErrors();
  MapReader top(file->rootNode(), diags, "species file");
  auto kind = top.requiredString("kind");
  if (kind && *kind != "blob")
    top.get("kind")->error(diags, "this reader takes kind: blob species, got kind: " + *kind);
  std::string name = top.string("name", stem);
  top.string("description");
  top.allow({"render", "stages"});  // shared species keys, read and checked by loadSpecies
  std::optional<BlobSpecies> s;
  if (!kind || *kind == "blob") s = readBlobSpecies(top, diags, policy);
  top.finish();
  diags.throwIfErrors();
  if (!s) throw InputError(file->rootNode().loc(), "invalid blob species");
  s->name = name;
  return std::move(*s);
}

}  // namespace

BlobSpecies loadBlobSpecies(const std::filesystem::path& path, const PathPolicy& policy) {
  DiagnosticList diags;
  auto file = YamlFile::load(path, diags);
  return readWhole(file, diags, path.stem().string(), policy);
}

std::vector<textures::RidgeArc> blobRidgeArcs(const BlobTree& tree, NodeId root) {
  using blobtree::NodeKind;
  // Step 1: the segments and cones in world space.
  struct Axis {
    Vec3 a, b;
    float ra, rb;
  };
  std::vector<Axis> axes;
  std::function<void(NodeId, const Mat4&, int)> collect = [&](NodeId id, const Mat4& worldFromLocal, int depth) {
    if (depth > kMaxDepth) return;
    const blobtree::Node& n = tree.node(id);
    switch (n.kind) {
      case NodeKind::Segment:
      case NodeKind::Cone: {
        if (!(n.weight > 0) || n.texture.relief) return;  // relief: a raised ridge, no branch
        const float scale = std::cbrt(std::abs(glm::determinant(Mat3(worldFromLocal))));
        axes.push_back({Vec3(worldFromLocal * Vec4(n.p0, 1.0f)), Vec3(worldFromLocal * Vec4(n.p1, 1.0f)),
                        n.ra * scale, (n.kind == NodeKind::Segment ? n.ra : n.rb) * scale});
        return;
      }
      case NodeKind::Transform:
        for (NodeId c : n.children) collect(c, worldFromLocal * n.worldFromLocal, depth + 1);
        return;
      case NodeKind::Difference:
      case NodeKind::Intersect:  // the first child is the body, the rest cut it
        if (!n.children.empty()) collect(n.children[0], worldFromLocal, depth + 1);
        return;
      case NodeKind::Blend:
      case NodeKind::Ricci:
      case NodeKind::Union:
      case NodeKind::Pcm:
        for (NodeId c : n.children) collect(c, worldFromLocal, depth + 1);
        return;
      default:  // other primitives, negative fields, warps
        return;
    }
  };
  collect(root, Mat4(1.0f), 0);

  // Step 2: for each start point, the parts through it, ending at it and starting at it.
  std::vector<textures::RidgeArc> out;
  auto direction = [](const Axis& x) { return glm::normalize(x.b - x.a); };
  for (size_t bi = 0; bi < axes.size(); ++bi) {
    const Axis& branch = axes[bi];
    const Vec3 p = branch.a;
    const float tol = 1e-3f * std::max(branch.ra, 1e-6f);
    int through = -1, basal = -1;
    std::vector<size_t> starting;
    for (size_t k = 0; k < axes.size(); ++k) {
      const Axis& x = axes[k];
      const Vec3 d = x.b - x.a;
      const float len2 = glm::dot(d, d);
      if (!(len2 > 0)) continue;
      const float t = glm::dot(p - x.a, d) / len2;
      const float len = std::sqrt(len2);
      if (t < -tol / len || t > 1 + tol / len) continue;
      if (glm::length(x.a + glm::clamp(t, 0.0f, 1.0f) * d - p) > tol) continue;
      if (t * len <= tol)
        starting.push_back(k);
      else if ((1 - t) * len <= tol) {
        if (basal < 0 || x.rb > axes[size_t(basal)].rb) basal = int(k);
      } else if (through < 0 || x.ra > axes[size_t(through)].ra) {
        through = int(k);
      }
    }
    textures::RidgeArc arc;
    arc.point = p;
    arc.branchAxis = direction(branch);
    arc.branchRadius = branch.ra;
    if (through >= 0) {  // a branch out of the side of a part
      const Axis& parent = axes[size_t(through)];
      const float t = glm::dot(p - parent.a, parent.b - parent.a) / glm::dot(parent.b - parent.a, parent.b - parent.a);
      arc.parentAxis = direction(parent);
      arc.parentRadius = parent.ra + t * (parent.rb - parent.ra);
    } else if (basal >= 0) {  // a junction: the leader continues the basal part
      const Vec3 up = direction(axes[size_t(basal)]);
      size_t leader = starting.front();
      for (size_t k : starting)
        if (glm::dot(direction(axes[k]), up) > glm::dot(direction(axes[leader]), up)) leader = k;
      if (leader == bi) continue;
      arc.parentAxis = direction(axes[leader]);
      arc.parentRadius = std::max(axes[size_t(basal)].rb, axes[leader].ra);
    } else {
      continue;
    }
    out.push_back(arc);
  }
  return out;
}

namespace {


/// The blob's texture registry as a part's texture table (ids = the primitives' texture ids).
render::TextureTable textureTable(const std::shared_ptr<const textures::TextureRegistry>& registry) {
  render::TextureTable table;
  if (!registry) return table;
  for (textures::TextureId id = 0; id < registry->size(); ++id)
    table.push_back([registry, id](Vec2 uv, const Vec3& p) { return registry->color(id, uv, p); });
  return table;
}

/// A BlobTree written in the species file: one stage.
class BlobModel final : public StillKindModel {
 public:
  explicit BlobModel(const BlobSpecies& blob)
      : blob_(blob), compiled_(std::make_shared<const blobtree::CompiledBlob>(blobtree::compile(blob.tree, blob.root))) {}

  Box3 frameBox() override {
    if (frame_) return *frame_;
    // The blob's surface lies inside its support; a scene shrinks the support to the
    // surface with interval bounds, which is what the camera should frame.
    render::Scene probe;
    probe.addImplicit(*compiled_, probe.addMaterial({}));
    Box3 box = probe.bounds();
    frame_ = box.empty() ? Box3{Vec3(-0.5f), Vec3(0.5f)} : box;
    return *frame_;
  }

  BuiltStage build(const Stage&, GeometryMode mode, const SpeciesRender& look) override {
    if (mode == GeometryMode::Skeleton) throw UsageError("blob species have no skeleton: use --mode exact or mesh");
    BuiltStage out;
    const auto t0 = std::chrono::steady_clock::now();
    out.figures.primitives = compiled_->primitiveCount();
    const render::Material surface = withRidge(look.surface);
    if (mode == GeometryMode::Mesh) {
      blobtree::PolygonizeOptions po = polygonizeOptions(look);
      po.cellSize = blob_.cellSize;
      auto mesh = std::make_shared<blobtree::PolygonizeResult>(polygonizeForLook(*compiled_, po, look));
      out.figures.triangles = mesh->mesh.triangleCount();
      out.geometry.parts.push_back(render::PolygonizedPart{std::move(mesh), surface, textureTable(blob_.textures)});
    } else {
      out.geometry.parts.push_back(render::ImplicitPart{compiled_, surface, {}, textureTable(blob_.textures)});
    }
    out.figures.buildSeconds = secondsSince(t0);
    return out;
  }

  Mesh buildMesh(const Stage&, float cellSize, bool progress, ModelFigures& fig) override {
    fig.primitives = compiled_->primitiveCount();
    blobtree::PolygonizeOptions po;
    po.cellSize = cellSize > 0 ? cellSize : blob_.cellSize;
    po.progress = progress;
    return blobtree::polygonize(*compiled_, po);
  }

  std::vector<ExportPart> exportParts(const Stage&, float cellSize, bool progress, const SpeciesRender& look,
                                      const MeshCleanOptions& clean, ModelFigures& fig) override {
    fig.primitives = compiled_->primitiveCount();
    blobtree::PolygonizeOptions po = polygonizeOptions(look);
    po.cellSize = cellSize > 0 ? cellSize : blob_.cellSize;
    po.progress = progress;
    ExportPart part;
    part.name = "blob";
    const render::TextureTable textures = textureTable(blob_.textures);
    render::Material painted;  // the colours the renderer gives: texture and ridge darkening
    painted.baseColor = look.surface.baseColor;
    painted = withRidge(painted);
    part.mesh = paintPolygonized(blobtree::polygonizeDetailed(*compiled_, po), textures, painted);
    fig.clean = cleanMesh(part.mesh, clean);
    part.mesh.materials.clear();
    part.material = {"blob", look.surface.baseColor, look.surface.roughness, false};
    atlasBlobPart(part, compiled_, textures, painted);
    return {std::move(part)};
  }

 private:
  /// material with the bark texture's branch bark ridge (seams and arcs), if it sets one.
  render::Material withRidge(render::Material material) const {
    if (!blob_.ridge) return material;
    const textures::BarkLook& look = *blob_.ridge;
    std::shared_ptr<const textures::RidgeArcs> arcs;
    if (look.hasArcs())
      arcs = std::make_shared<const textures::RidgeArcs>(blobRidgeArcs(blob_.tree, blob_.root), look.ridgeArc);
    material.ridge = textures::RidgeShade(look.ridge(), std::move(arcs));
    return material;
  }

  const BlobSpecies& blob_;
  std::shared_ptr<const blobtree::CompiledBlob> compiled_;
  std::optional<Box3> frame_;
};

}  // namespace

std::shared_ptr<const KindSpec> readBlobSpec(MapReader& top, Species& species, DiagnosticList& diags) {
  if (!top.has("blob")) {
    top.allow({"kernel", "mesh", "textures"});
    top.node().error(diags, "missing required key 'blob' in species file");
    return nullptr;
  }
  std::optional<BlobSpecies> blob = readBlobSpecies(top, diags, species.policy);
  if (!blob) return nullptr;
  auto spec = std::make_shared<BlobSpec>();
  spec->blob = std::move(*blob);
  spec->blob.name = species.name;
  return spec;
}

std::string BlobSpec::checkSummary(const Species& species) const { return " '" + species.name + "'"; }

std::unique_ptr<KindModel> BlobSpec::makeModel(const Species&, const ModelOptions&) const {
  return std::make_unique<BlobModel>(blob);
}

}  // namespace sprig
