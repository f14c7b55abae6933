#include "lsystem/turtle.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <string>
#include <string_view>

#include <glm/gtc/quaternion.hpp>

#include "core/diagnostics.h"
#include "lsystem/detail/cpfg.h"
#include "lsystem/detail/program.h"

namespace sprig::lsystem {

namespace {

/// a' = a cos + b sin, b' = b cos - a sin: the rotation of the (a, b) plane that moves a toward b.
inline void rotatePair(DVec3& a, DVec3& b, double c, double s) {
  DVec3 na = a * c + b * s;
  b = b * c - a * s;
  a = na;
}

/// sin/cos of angles in degrees, cached by the angle's bits: grammars repeat a handful
/// of angles (45, 137.5, ...), so most parameterized turns skip the trigonometry.
class SinCosCache {
 public:
  void get(double deg, double& s, double& c) {
    uint64_t bits = std::bit_cast<uint64_t>(deg);
    Entry& e = entries_[(bits ^ (bits >> 29) ^ (bits >> 47)) & (kSize - 1)];
    if (e.bits != bits || !e.valid) {
      double r = radians(deg);
      e = {bits, std::sin(r), std::cos(r), true};
    }
    s = e.s;
    c = e.c;
  }

 private:
  static constexpr size_t kSize = 64;
  struct Entry {
    uint64_t bits = 0;
    double s = 0, c = 1;
    bool valid = false;
  };
  Entry entries_[kSize];
};

void orthonormalize(TurtleFrame& f) {
  f.heading = glm::normalize(f.heading);
  f.up = glm::normalize(glm::cross(f.heading, f.left));
  f.left = glm::cross(f.up, f.heading);
}

}  // namespace

void rollToVertical(TurtleFrame& f) {
  const DVec3 v{0, 1, 0};
  DVec3 l = glm::cross(v, f.heading);
  double n = glm::length(l);
  if (n < 1e-12) return;
  f.left = l / n;
  f.up = glm::cross(f.heading, f.left);
}

void applyTropism(TurtleFrame& f, const DVec3& t, double e) {
  if (e == 0) return;
  DVec3 axis = glm::cross(f.heading, t);
  double n = glm::length(axis);
  if (n < 1e-12) return;
  axis /= n;
  double a = e * n;  // ABOP section 2.2: alpha = e |H x T|
  double c = std::cos(a), s = std::sin(a);
  // Rodrigues' rotation of each frame vector about the unit axis.
  auto rot = [&](const DVec3& x) { return x * c + glm::cross(axis, x) * s + axis * (glm::dot(axis, x) * (1 - c)); };
  f.heading = rot(f.heading);
  f.left = rot(f.left);
  f.up = rot(f.up);
  orthonormalize(f);
}

double TurtleSettings::growthScale() const {
  const double f = std::clamp(growthFraction, 0.0, 1.0);
  const double s0 = std::clamp(growthStart, 0.0, 1.0);
  return s0 + (1.0 - s0) * f;
}

Turtle::Turtle(const SymbolTable& symbols, TurtleSettings settings) : symbols_(symbols), settings_(settings) {
  commands_.assign(symbols.size(), Command::None);
  for (size_t i = 0; i < symbols.size(); ++i) {
    std::string_view n = symbols.name(static_cast<SymbolId>(i));
    Command c = Command::None;
    if (n.size() == 1) {
      switch (n[0]) {
        case 'F': c = Command::Forward; break;
        case 'f': c = Command::Move; break;
        case 'G': c = Command::ForwardNoVertex; break;
        case 'g': c = Command::MoveNoVertex; break;
        case '+': c = Command::TurnLeft; break;
        case '-': c = Command::TurnRight; break;
        case '&': c = Command::PitchDown; break;
        case '^': c = Command::PitchUp; break;
        case '\\': c = Command::RollLeft; break;
        case '/': c = Command::RollRight; break;
        case '|': c = Command::TurnAround; break;
        case '$': c = settings_.cpfg ? Command::SubEnd : Command::RollToVertical; break;
        case '?': c = settings_.cpfg ? Command::SubCall : Command::None; break;
        case '[': c = Command::Push; break;
        case ']': c = Command::Pop; break;
        case '!': c = Command::Width; break;
        case '\'': c = settings_.cpfg ? Command::None : Command::Color; break;
        case '#': c = Command::WidthUp; break;
        case '_': c = settings_.cpfg ? Command::OldElasticity : Command::None; break;
        case ';': c = Command::ColorUp; break;
        case ',': c = Command::ColorDown; break;
        case '{': c = Command::PolygonBegin; break;
        case '.': c = Command::Vertex; break;
        case '}': c = Command::PolygonEnd; break;
        case '~': c = Command::Surface; break;
        case '%': c = Command::Cut; break;
        default: break;
      }
    } else if (n == "@Ts") {
      c = Command::Tropism;
    } else if (n == "@v") {
      c = Command::RollToVertical;
    } else if (n == "@O") {
      c = Command::Sphere;
    } else if (n == "@o") {
      c = Command::Circle;
    } else if (n == "@c") {
      c = Command::Disc;
    } else if (n == "@Ti") {
      c = Command::TropismUp;
    } else if (n == "@Td") {
      c = Command::TropismDown;
    } else if (n == "@Tp") {
      c = Command::TwistAdjust;
    } else if (n == "@Tf") {
      c = Command::TwistForce;
    } else if (n == "@M") {
      c = Command::MoveTo;
    } else if (n == "@R") {
      c = Command::SetHeading;
    } else if (n == "@D") {
      c = Command::ScaleSet;
    } else if (n == "@Di") {
      c = Command::ScaleUp;
    } else if (n == "@Dd") {
      c = Command::ScaleDown;
    } else if (n == "@Gs") {
      c = Command::GcStart;
    } else if (n == "@Gc") {
      c = Command::GcPoint;
    } else if (n == "@Ge") {
      c = Command::GcEnd;
    } else if (n == "@Gt") {
      c = Command::GcTangents;
    } else if (n == "@Gr") {
      c = Command::GcRadiusTangents;
    } else if (n == "@#") {
      c = Command::Contour;
    } else if (n == "@!") {
      c = Command::ContourSides;
    } else if (n == "@Tx") {
      c = Command::Texture;
    } else if (n == "@L") {
      c = Command::Label;
    } else if (n == "?P" || n == "?H" || n == "?L" || n == "?U" || n == "?E") {
      c = Command::Query;
    } else if (n.size() > 1 && n[0] == '~') {
      c = Command::SurfaceNamed;
    }
    commands_[i] = c;
  }
}

namespace {

/// cpfg's least line width (interpret.c's MinWidth).
constexpr double kMinCpfgWidth = 1e-7;
/// Vertices of the polygon that draws a `@c` disc.
constexpr int kDiscSides = 32;
/// cpfg's rings per generalized-cylinder segment without a parameter (general.h, DEFAULT_RINGS).
constexpr int kDefaultGcRings = 4;
/// Most rings per segment Sprig draws (a larger `@Gc(n)` draws this many).
constexpr int kMaxGcRings = 1024;
/// Fewest points around a textured tube (a multiple of cpfg's count; see texturedSides).
constexpr int kMinTexturedSides = 32;

/// An open `{` polygon.
struct OpenPolygon {
  std::vector<DVec3> points;
  int32_t internode;  ///< the internode the polygon grows from (at its `{`)
  /// cpfg textures a polygon by its first vertex's state (irisGL.c, PolygonToMesh): its
  /// texture (-1: none), and its frame's H and -L, the texture's t and s axes.
  int texture = -1;
  DVec3 sAxis{1, 0, 0};
  DVec3 tAxis{0, 1, 0};
};

/// The working buffers of one run, besides the skeleton it draws.
struct WalkBuffers {
  std::vector<TurtleState> stack;      ///< states saved by `[`
  std::vector<OpenPolygon> polygons;   ///< open `{` polygons, innermost last
  std::vector<double> internodeGrowth; ///< per internode, for the pipe model's radii (growth only)
};

/*
 * TurtleWalk: one Turtle::run in progress. It holds the turtle's state and read-only
 * views of the string (raw pointers into its arrays) and of the settings. walk() is the
 * one pass over the string: a switch on each module's command that calls one small
 * handler per command. The handlers are member functions in this file, inlined into the
 * switch: the loop makes no indirect call and allocates nothing per module beyond the
 * output vectors.
 *
 * Handlers change st_.frame in place: copying the frame out to a local and back (around
 * `$`, say) made ABOP 2.6 a third slower in bench_turtle.
 *
 * kSummary: the same walk, but internodes are folded into a SkeletonSummary (count, length,
 * bounds) instead of stored (Turtle::summarize). The one later change to a stored internode,
 * taper setting a parent's tip radius to its continuation's base radius, is applied to the
 * bounds when the continuation is drawn: the parent's start, base radius and order travel
 * with the state (last_, saved beside the state stack). Skeleton::bounds uses
 * max(base, tip) at both ends, and the parent's end is the continuation's start.
 */
template <bool kSummary>
class TurtleWalk {
 public:
  using Command = Turtle::Command;

  TurtleWalk(const SymbolTable& symbols, const TurtleSettings& settings, const std::vector<Command>& commands,
             const ModuleString& ms, Skeleton& sk, std::span<const int32_t> moduleSteps,
             SkeletonSummary* summary = nullptr)
      : symbols_(symbols), settings_(settings), sk_(sk), sum_(summary), n_(ms.size()), sym_(ms.symbols.data()),
        off_(ms.offsets.data()), prm_(ms.params.data()), cmd_(commands.data()), ncmd_(commands.size()),
        steps_(moduleSteps), haveSteps_(moduleSteps.size() >= n_),
        radiusScale_(0.5 * settings.widthScale),
        maxRadiusPerLength_(settings.radii == RadiusModel::Width ? 0.5 * settings.maxWidthToLength : 0.0),
        taper_(settings.taper && settings.radii == RadiusModel::Width),
        tropism_(settings.tropism),
        defS_(std::sin(radians(settings.angleDeg))),
        defC_(std::cos(radians(settings.angleDeg))),
        growing_(settings.growthStep >= 0 && haveSteps_),
        partial_(settings.growthScale()) {
    st_.frame.position = settings.origin;
    st_.width = settings.initialWidth;
    st_.elasticity = settings.elasticity;
    st_.color = settings.initialColor;
    st_.scale = settings.cpfg ? settings.initialScale : 1.0;
    st_.prevHeading = st_.frame.heading;
    st_.prevUp = st_.frame.up;
    for (size_t k = 0; k < settings.tropisms.size() && k < size_t(kMaxTropisms); ++k)
      st_.elasticities[k] = settings.tropisms[k].elasticity;
    buf_.stack.reserve(64);
    for (size_t k = 0; k < ncmd_ && !usesGc_; ++k)
      usesGc_ = cmd_[k] == Command::GcStart || cmd_[k] == Command::GcPoint || cmd_[k] == Command::GcEnd ||
                cmd_[k] == Command::GcTangents || cmd_[k] == Command::GcRadiusTangents;
  }

  /// Reserves the exact number of drawing modules: cheaper than growing the vector.
  void reserveInternodes() {
    size_t draws = 0;
    for (size_t i = 0; i < n_; ++i) {
      Command c = commandAt(i);
      draws += c == Command::Forward || c == Command::ForwardNoVertex;
    }
    sk_.internodes.reserve(draws);
  }

  /// Where walk() records the frame at each query module (none when null).
  void recordQueries(std::vector<Turtle::QueryHit>* out) { queries_ = out; }

  /// Interprets every module; returns the state after the last one.
  const TurtleState& walk() {
    for (size_t i = 0; i < n_; ++i) {
      const Command c = commandAt(i);
      switch (c) {
        case Command::None: break;
        case Command::Forward:
        case Command::ForwardNoVertex: forward(i, c == Command::Forward); break;
        case Command::Move:
        case Command::MoveNoVertex: move(i, c == Command::Move); break;
        case Command::TurnLeft: rotate(i, st_.frame.heading, st_.frame.left, false); break;
        case Command::TurnRight: rotate(i, st_.frame.heading, st_.frame.left, true); break;
        case Command::PitchDown: rotate(i, st_.frame.up, st_.frame.heading, false); break;
        case Command::PitchUp: rotate(i, st_.frame.up, st_.frame.heading, true); break;
        case Command::RollLeft: rotate(i, st_.frame.left, st_.frame.up, false); break;
        case Command::RollRight: rotate(i, st_.frame.left, st_.frame.up, true); break;
        case Command::TurnAround: turnAround(); break;
        case Command::RollToVertical: rollToVertical(st_.frame); break;
        case Command::Push: push(); break;
        case Command::Pop: pop(); break;
        case Command::Width: width(i); break;
        case Command::Color: color(i); break;
        case Command::PolygonBegin: buf_.polygons.push_back({{}, st_.internode}); break;
        case Command::Vertex: vertex(); break;
        case Command::PolygonEnd: polygonEnd(i); break;
        case Command::Surface: i = surface(i); break;
        case Command::SurfaceNamed: surfaceNamed(i); break;
        case Command::Sphere: sphere(i); break;
        case Command::Tropism: tropismChange(i); break;
        case Command::Cut:
          // The parsers refuse cpfg's `%(n)` and `%(n, t)`; a string built otherwise too.
          if (hasParam(i))
            throw InputError(SourceLoc{"sprig", 0, 0},
                             *detail::cpfgUnsupported("%", paramCount(i), true, '\0', detail::Dialect::Cpfg));
          if (!settings_.interpretPastCut) i = cut(i);
          break;
        case Command::WidthUp: widthUp(i); break;
        case Command::ColorUp: colorStep(i, +1); break;
        case Command::ColorDown: colorStep(i, -1); break;
        case Command::Circle: sphere(i); break;
        case Command::Disc: disc(i); break;
        case Command::TropismUp: tropismStep(i, +1); break;
        case Command::TropismDown: tropismStep(i, -1); break;
        case Command::TwistAdjust: twistFree(); break;
        case Command::TwistForce:
          st_.prevHeading = st_.frame.heading;
          st_.prevUp = st_.frame.up;
          break;
        case Command::MoveTo: moveTo(i); break;
        case Command::SetHeading: setHeading(i); break;
        case Command::ScaleSet: if (hasParam(i)) st_.scale = param(i); break;
        case Command::ScaleUp: scaleStep(i, false); break;
        case Command::ScaleDown: scaleStep(i, true); break;
        case Command::OldElasticity:
          st_.elasticity = hasParam(i) ? param(i) : st_.elasticity + settings_.elasticityIncrement;
          break;
        case Command::Query:
          if (queries_) queries_->push_back({i, st_.frame});
          break;
        case Command::SubCall: i = subCall(i); break;
        case Command::SubEnd: subEnd(); break;
        case Command::GcStart:
          gcRestart();
          gcPoint(i, false);
          break;
        case Command::GcPoint: gcPoint(i, false); break;
        case Command::GcEnd: gcPoint(i, true); break;
        case Command::Contour: contour(i); break;
        case Command::Texture: texture(i); break;
        case Command::Label: label(i); break;
        case Command::GcRadiusTangents: gcRadiusTangents(i); break;
        case Command::ContourSides:
          // cpfg's `@!(n)`: points around a contour (at least 3; 8 without a parameter).
          st_.contourSides = hasParam(i) ? std::clamp(static_cast<int>(std::isfinite(param(i)) ? std::clamp(param(i), -1e6, 1e6) : 0.0),
                                                     CpfgContour::kMinSides, CpfgContour::kMaxSides)
                                         : CpfgContour::kDefaultSides;
          break;
        case Command::GcTangents:
          if (hasParam(i)) {
            gc_.tangentIn = param(i);
            gc_.tangentOut = paramCount(i) > 1 ? paramAt(i, 1) : param(i);
          }
          break;
      }
    }
    return st_;
  }

  /// Pipe model radii, after the walk. Children always follow their parent in drawing
  /// order, so one backward sweep sees every child before its parent.
  void pipeRadii() {
    auto& ins = sk_.internodes;
    const size_t m = ins.size();
    const double e = settings_.pipeExponent;
    std::vector<double> sum(m, 0.0), maxChild(m, 0.0);
    for (size_t k = m; k-- > 0;) {
      double r = sum[k] > 0 ? std::pow(sum[k], 1.0 / e) : settings_.tipRadius;
      ins[k].baseRadius = r;
      ins[k].tipRadius = maxChild[k] > 0 ? maxChild[k] : settings_.tipRadius;
      if (int32_t p = ins[k].parent; p >= 0) {
        sum[p] += std::pow(r, e);
        maxChild[p] = std::max(maxChild[p], r);
      }
    }
    // Growing internodes thicken with their growth, like the width model's radii.
    if (growing_)
      for (size_t k = 0; k < m; ++k) {
        ins[k].baseRadius *= buf_.internodeGrowth[k];
        ins[k].tipRadius *= buf_.internodeGrowth[k];
      }
  }

 private:
  Command commandAt(size_t i) const { return sym_[i] < ncmd_ ? cmd_[sym_[i]] : Command::None; }
  bool hasParam(size_t i) const { return off_[i + 1] > off_[i]; }
  /// The first parameter of module i (which must have one).
  double param(size_t i) const { return prm_[off_[i]]; }
  int32_t stepOf(size_t i) const { return haveSteps_ ? steps_[i] : 0; }
  /// Growth: the scale of module i (1 = full size, 0 = not yet drawn).
  double growth(size_t i) const {
    if (!growing_) return 1.0;
    const int32_t born = steps_[i];
    return born < settings_.growthStep ? 1.0 : born == settings_.growthStep ? partial_ : 0.0;
  }
  /// Length of the move of module i (its parameter, or the step length), scaled by growth.
  double length(size_t i) const {
    const double l = fullLength(i);
    return growing_ ? l * growth(i) : l;
  }
  /// The radius a segment of this length is drawn with at full growth: the width's,
  /// capped by TurtleSettings::maxWidthToLength.
  double drawnRadius(double length) const {
    const double r = st_.width * radiusScale_;
    return maxRadiusPerLength_ > 0 ? std::min(r, maxRadiusPerLength_ * length) : r;
  }

  /// Length of the move of module i at full growth.
  double fullLength(size_t i) const { return (hasParam(i) ? param(i) : settings_.stepLength) * st_.scale; }

  /// cpfg's update_segment_texture (textures.c): how far the texture's t advances along a
  /// cylinder of this diameter and length, length / (pi diameter) times the image's
  /// width / height, divided by the texture's `R:` ratio: a square texel stays square
  /// around a cylinder whose circumference holds the image's width once. 0 without a
  /// texture or for a zero diameter.
  double texStep(int texture, double diameter, double length) const {
    if (texture < 0 || !settings_.cpfgTextures || static_cast<size_t>(texture) >= settings_.cpfgTextures->size()) return 0.0;
    if (!(diameter > 0)) return 0.0;
    const CpfgTexture& tex = (*settings_.cpfgTextures)[static_cast<size_t>(texture)];
    const double aspect = tex.image && tex.image->height > 0 ? static_cast<double>(tex.image->width) / tex.image->height : 1.0;
    return length / (kPi * diameter) * aspect / tex.ratio;
  }

  /// Points around a textured tube: cpfg's count (`@!(n)`, else `contour sides:`) times
  /// the least factor that gives at least kMinTexturedSides, so cpfg's vertices (and their
  /// s) are among them and the silhouette stays round.
  static int texturedSides(int cpfgSides) {
    const int n = std::max(cpfgSides, 3);
    return n * ((kMinTexturedSides + n - 1) / n);
  }

  /// cpfg's textured `F` cylinder (irisGL.c, iGlEndNode and MakeCylinder): an open tube in
  /// the frame f of its start, from f.position along f.heading, of the given radius; its
  /// point at angle a lies at r (cos a L + sin a U') (U' = -U, cpfg's up vector), with
  /// texture coordinates s = a / 2 pi (the seam, s = 0 and 1, along L) and t = t0 at the
  /// base, t1 at the top. A Surface organ named kTexturedCylinderName, with the texture
  /// selected.
  void texturedCylinder(size_t i, const TurtleFrame& f, double length, double radius, double t0, double t1) {
    Organ o = organHere(Organ::Kind::Surface, i);
    o.name = kTexturedCylinderName;
    o.texture = st_.texture;
    o.position = f.position;
    o.heading = f.heading;
    o.left = f.left;
    o.up = f.up;
    o.radius = radius;
    const int sides = texturedSides(st_.contourSides > 0 ? st_.contourSides : settings_.contourSides);
    const uint32_t per = static_cast<uint32_t>(sides) + 1;
    for (int ring = 0; ring < 2; ++ring)
      for (int m = 0; m <= sides; ++m) {
        const double a = 2 * kPi * (m % sides) / sides;
        const DVec3 d = std::cos(a) * f.left - std::sin(a) * f.up;
        o.points.push_back(f.position + (ring ? length : 0.0) * f.heading + radius * d);
        o.normals.push_back(d);
        o.uvs.emplace_back(static_cast<float>(static_cast<double>(m) / sides), static_cast<float>(ring ? t1 : t0));
      }
    for (uint32_t m = 0; m < static_cast<uint32_t>(sides); ++m) {
      const uint32_t a = m, b = a + 1, c = a + per, d = c + 1;
      o.triangles.insert(o.triangles.end(), {a, c, b, b, c, d});
    }
    sk_.organs.push_back(std::move(o));
  }

  /// Number of parameters of module i.
  uint32_t paramCount(size_t i) const { return off_[i + 1] - off_[i]; }
  /// Parameter k of module i (which must have it).
  double paramAt(size_t i, uint32_t k) const { return prm_[off_[i] + k]; }

  /// `F` and `G`: draws an internode (or, inside a polygon, adds an outline point when
  /// withVertex). Growing modules draw shorter and thinner; unborn ones draw nothing.
  void forward(size_t i, bool withVertex) {
    if (settings_.cpfg) cpfgTropisms();
    DVec3 start = st_.frame.position;
    const TurtleFrame drawnIn = st_.frame;  // cpfg draws the cylinder in its start node's frame
    const double texT0 = st_.texT;
    st_.texT += texStep(st_.texture, 2 * drawnRadius(fullLength(i)), fullLength(i));
    st_.frame.position += st_.frame.heading * length(i);
    if (settings_.cpfg) {
      cpfgOldBend();
      st_.prevHeading = st_.frame.heading;
      st_.prevUp = st_.frame.up;
    }
    if (!buf_.polygons.empty()) {
      if (withVertex) addPolygonPoint(st_.frame.position);
      st_.internode = -1;  // outlines are not drawn; the next segment starts a new axis
      return;
    }
    const double g = growth(i);
    if (g <= 0) return;  // not grown yet: nothing drawn, no bend; the axis carries on from its parent
    // A contour (`@#(id)`) does not shape an `F`: cpfg draws its cylinder round, with
    // `@!(n)` sides (irisGL.c, iGlEndCylNode); only generalized cylinders take contours.
    if (st_.texture >= 0) {
      double radius = st_.width * radiusScale_ * g;
      if (maxRadiusPerLength_ > 0) radius = std::min(radius, maxRadiusPerLength_ * length(i));
      texturedCylinder(i, drawnIn, length(i), radius, texT0, st_.texT);
      st_.internode = -1;  // a mesh, not an internode: the next segment starts a new axis
      return;
    }
    Internode in;
    in.start = start;
    in.end = st_.frame.position;
    in.baseRadius = in.tipRadius = st_.width * radiusScale_ * g;
    if (maxRadiusPerLength_ > 0)
      in.baseRadius = in.tipRadius = std::min(in.baseRadius, maxRadiusPerLength_ * glm::length(in.end - in.start));
    if (growing_) buf_.internodeGrowth.push_back(g);
    in.parent = st_.internode;
    in.order = st_.order;
    in.step = stepOf(i);
    in.module = static_cast<uint32_t>(i);
    in.up = st_.frame.up;
    // Taper: the continuation of an axis (the child drawn at the parent's own order; a
    // parent has at most one, since `[` raises the order) ends the parent's radius.
    if constexpr (kSummary) {
      summarize(in);
    } else {
      if (taper_ && in.parent >= 0 && sk_.internodes[in.parent].order == in.order)
        sk_.internodes[in.parent].tipRadius = in.baseRadius;
      st_.internode = static_cast<int32_t>(sk_.internodes.size());
      sk_.internodes.push_back(in);
    }
    // A growing internode bends in proportion to its growth, so frames change smoothly.
    if (!settings_.cpfg && st_.elasticity != 0) applyTropism(st_.frame, tropism_, st_.elasticity * g);
  }

  /// kSummary: folds the internode just computed into the summary, as Skeleton::bounds and
  /// totalLength would see it after the walk (see the class comment).
  void summarize(const Internode& in) {
    SkeletonSummary& s = *sum_;
    const double r = std::max(in.baseRadius, in.tipRadius);
    s.bounds.extend(in.start - r);
    s.bounds.extend(in.start + r);
    s.bounds.extend(in.end - r);
    s.bounds.extend(in.end + r);
    if (taper_ && in.parent >= 0 && last_.order == in.order && in.baseRadius > last_.radius) {
      s.bounds.extend(last_.start - in.baseRadius);
      s.bounds.extend(last_.start + in.baseRadius);
      s.bounds.extend(in.start - in.baseRadius);
      s.bounds.extend(in.start + in.baseRadius);
    }
    s.totalLength += in.length();
    st_.internode = static_cast<int32_t>(s.internodes++);
    last_ = {in.start, r, in.order};
  }

  /// `f` and `g`: moves without drawing (`f` adds a polygon point when withVertex). A move
  /// leaves a gap, so the next segment starts a new, disconnected axis; a move of length 0
  /// at full growth (`f(0)`, tree_lime's fallen leaf) goes nowhere and the axis carries on:
  /// what is drawn next still hangs from the last internode. (Full growth, so that a growing
  /// move links the same internodes in every frame.)
  void move(size_t i, bool withVertex) {
    if (settings_.cpfg) cpfgTropisms();
    st_.texT += texStep(st_.texture, 2 * drawnRadius(fullLength(i)), fullLength(i));
    st_.frame.position += st_.frame.heading * length(i);
    if (settings_.cpfg) cpfgOldBend();
    if (!buf_.polygons.empty() && withVertex) addPolygonPoint(st_.frame.position);
    if (fullLength(i) != 0) st_.internode = -1;
  }

  /// `+ - & ^ \ /`: rotates the plane (a, b) by module i's angle (or the default), moving
  /// a toward b, or away from it when reverse.
  void rotate(size_t i, DVec3& a, DVec3& b, bool reverse) {
    double s, c;
    if (hasParam(i)) {
      trig_.get(param(i), s, c);
    } else {
      s = defS_;
      c = defC_;
    }
    rotatePair(a, b, c, reverse ? -s : s);
  }

  /// `|`: turns about U by 180 degrees.
  void turnAround() {
    st_.frame.heading = -st_.frame.heading;
    st_.frame.left = -st_.frame.left;
  }

  /// `[`: saves the state; the branch is one order higher.
  void push() {
    buf_.stack.push_back(st_);
    if (usesGc_) gcStack_.push_back(gc_);
    if constexpr (kSummary) lastStack_.push_back(last_);
    ++st_.order;
  }

  /// `]`: restores the state of the matching `[` (an unmatched `]` is ignored).
  void pop() {
    if (!buf_.stack.empty()) {
      st_ = buf_.stack.back();
      buf_.stack.pop_back();
      if (usesGc_ && !gcStack_.empty()) {
        gc_ = gcStack_.back();
        gcStack_.pop_back();
      }
      if constexpr (kSummary) {
        last_ = lastStack_.back();
        lastStack_.pop_back();
      }
    }
  }

  /// Adds p to the innermost open polygon (the first point records the texture and frame).
  void addPolygonPoint(DVec3 p) {
    OpenPolygon& poly = buf_.polygons.back();
    if (poly.points.empty()) {
      poly.texture = st_.texture;
      poly.sAxis = -st_.frame.left;
      poly.tAxis = st_.frame.heading;
    }
    poly.points.push_back(p);
  }

  /// `!`: sets the width, or thins it: Sprig's notation multiplies it by the width
  /// factor, cpfg's subtracts the width increment (times the turtle scale; at least 1e-7).
  void width(size_t i) {
    if (!settings_.cpfg) {
      st_.width = hasParam(i) ? param(i) : st_.width * settings_.widthFactor;
      return;
    }
    st_.width = hasParam(i) ? param(i) * st_.scale : st_.width - settings_.widthIncrement * st_.scale;
    st_.width = std::max(st_.width, kMinCpfgWidth);
  }
  /// `#`: sets the width, or adds the width increment (times the turtle scale in cpfg's notation).
  void widthUp(size_t i) {
    st_.width = hasParam(i) ? param(i) * st_.scale : st_.width + settings_.widthIncrement * st_.scale;
    if (settings_.cpfg) st_.width = std::max(st_.width, kMinCpfgWidth);
  }
  /// `'`: sets the color index, or increments it.
  void color(size_t i) { st_.color = hasParam(i) ? colorIndex(param(i)) : st_.color + 1; }
  /// `;` (sign +1) and `,` (sign -1): sets the color index, or steps it by the color
  /// increment; cpfg keeps the index in 0..255 by wrapping.
  void colorStep(size_t i, int sign) {
    st_.color = hasParam(i) ? colorIndex(param(i)) : st_.color + sign * settings_.colorIncrement;
    if (settings_.cpfg) {
      if (sign > 0 && st_.color > 255) st_.color -= 256;
      if (sign < 0 && st_.color < 0) st_.color += 256;
    }
  }
  /// cpfg's generalized cylinder (`@Gs`, `@Gc(n)`, `@Ge(n)`; general.c, SetControlPoint and
  /// interpolate_connection, Hermite base, circular contour): each control point after the
  /// first joins the previous one by a Hermite cubic whose end tangents are the two
  /// headings times the chord length times the tangent parameters (`@Gt`, default 1.2),
  /// drawn as n internodes (n from the point's parameter, at least 1; 4 without one) at
  /// t = k/n, their radii linear from half the previous point's width to half this one's.
  /// Control points closer than 1e-5 draw nothing. The state is saved by `[` and restored
  /// by `]`, as cpfg's spline stack is. end: `@Ge`, which ends the cylinder after its point.
  void gcPoint(size_t i, bool end) {
    const DVec3 p2 = st_.frame.position, h2 = st_.frame.heading;
    const double w2 = st_.width;
    if (!gc_.active) gcRestart();
    DVec3 upEnd = st_.frame.up;  // the frame of this control point's ring (Sprig's U)
    if (gc_.hasPoint && !settings_.gcTwist) upEnd = -transportedUp(gc_.heading, -gc_.up, h2);
    if (gc_.hasPoint) {
      const DVec3 p1 = gc_.position;
      const double len = glm::length(p2 - p1);
      const double g = growth(i);
      if (len >= 1e-5 && g > 0) {
        const DVec3 t1 = gc_.heading * (len * gc_.pointTangentOut), t2 = h2 * (len * gc_.tangentIn);
        const DVec3 a2 = -3.0 * (p1 - p2) - 2.0 * t1 - t2, a3 = 2.0 * (p1 - p2) + t1 + t2;
        int rings = hasParam(i) ? std::max(1, static_cast<int>(param(i))) : kDefaultGcRings;
        rings = std::min(rings, kMaxGcRings);
        // cpfg's radius Hermite (general.c, interpolate_connection): the pairs (t, radius)
        // from (0, w1/2) to (1, w2/2) with the tangents of `@Gr` (the first point's second
        // and this point's first; times |p2 - p1| after `@Gr(1)`); a zero tangent is
        // (1, (w2 - w1)/2), so that without `@Gr` t = k/n and the radius is linear.
        glm::dvec2 r0 = gc_.pointRadiusOut, r1 = gc_.radiusIn;
        if (gc_.scaleRadiusTangents) {
          r0.y *= len;
          r1.y *= len;
        }
        const double half = 0.5 * (w2 - gc_.width);
        if (r0 == glm::dvec2(0.0)) r0 = glm::dvec2(1, half);
        if (r1 == glm::dvec2(0.0)) r1 = glm::dvec2(1, half);
        const glm::dvec2 c0(0, 0.5 * gc_.width), c2(3 - 2 * r0.x - r1.x, 3 * half - 2 * r0.y - r1.y),
            c3(-2 + r0.x + r1.x, -2 * half + r0.y + r1.y);
        std::vector<glm::dvec2> ring(static_cast<size_t>(rings) + 1);  // (t, width) per ring
        for (int k = 0; k <= rings; ++k) {
          const double r = static_cast<double>(k) / rings;
          const glm::dvec2 v = k == rings ? glm::dvec2(1, 0.5 * w2) : ((c3 * r + c2) * r + r0) * r + c0;
          ring[static_cast<size_t>(k)] = glm::dvec2(v.x, 2 * v.y);
        }
        // cpfg's texture t (general.c, interpolate_connection): from the first point's, each
        // ring adds update_segment_texture over the chord from the ring before at the ring's
        // width; the turtle's t becomes the last ring's. Textured when both control points
        // select a texture, with the first one's (cpfg's tu1.texture).
        std::vector<double> ringT(static_cast<size_t>(rings) + 1, gc_.texT);
        DVec3 prev = p1;
        for (int k = 1; k <= rings; ++k) {
          const double t = ring[static_cast<size_t>(k)].x;
          const DVec3 at = k == rings ? p2 : p1 + t * (t1 + t * (a2 + t * a3));
          ringT[static_cast<size_t>(k)] =
              ringT[static_cast<size_t>(k) - 1] +
              texStep(gc_.texture, 2 * radiusScale_ * ring[static_cast<size_t>(k)].y, glm::length(at - prev));
          prev = at;
        }
        st_.texT = ringT.back();
        const int texture = gc_.texture >= 0 && st_.texture >= 0 ? gc_.texture : -1;
        if (gc_.contour != 0 || st_.contour != 0 || texture >= 0) {
          gcContourMesh(i, p1, t1, a2, a3, len, ring, texture, ringT, -upEnd);
          rings = 0;  // drawn as a mesh
        }
        DVec3 from = p1;
        int32_t parent = gc_.lastInternode;
        for (int k = 1; k <= rings; ++k) {
          const double t = ring[static_cast<size_t>(k)].x;
          const DVec3 to = k == rings ? p2 : p1 + t * (t1 + t * (a2 + t * a3));
          Internode in;
          in.start = from;
          in.end = to;
          in.baseRadius = radiusScale_ * ring[static_cast<size_t>(k) - 1].y;
          in.tipRadius = radiusScale_ * ring[static_cast<size_t>(k)].y;
          if (maxRadiusPerLength_ > 0) {
            in.baseRadius = std::min(in.baseRadius, maxRadiusPerLength_ * len);
            in.tipRadius = std::min(in.tipRadius, maxRadiusPerLength_ * len);
          }
          in.parent = parent;
          in.order = st_.order;
          in.step = stepOf(i);
          in.module = static_cast<uint32_t>(i);
          in.up = st_.frame.up;
          if (growing_) buf_.internodeGrowth.push_back(g);
          if constexpr (kSummary) {
            const int32_t keep = st_.internode;
            summarize(in);
            parent = st_.internode;
            st_.internode = keep;
          } else {
            parent = static_cast<int32_t>(sk_.internodes.size());
            sk_.internodes.push_back(in);
          }
          from = to;
        }
        gc_.lastInternode = parent;
      }
    } else {
      gc_.lastInternode = st_.internode;
    }
    gc_.hasPoint = true;
    gc_.position = p2;
    gc_.heading = h2;
    gc_.up = upEnd;
    gc_.width = w2;
    gc_.contour = st_.contour;
    gc_.sides = st_.contourSides > 0 ? st_.contourSides : settings_.contourSides;
    gc_.pointTangentOut = gc_.tangentOut;
    gc_.pointRadiusOut = gc_.radiusOut;
    gc_.texture = st_.texture;
    gc_.texT = st_.texT;
    if (end) gc_.active = gc_.hasPoint = false;
  }

  /// cpfg's `@Gr` (blackbox.c): `@Gr(s)` makes later radius tangents scale with the
  /// segment's length (s != 0) or not; `@Gr(a, l)` sets both radius tangents to
  /// l (cos a, sin a) (a in degrees; in (t, radius) space), `@Gr(a, l, a2, l2)` the second
  /// to l2 (cos a2, sin a2). Without parameters: nothing.
  void gcRadiusTangents(size_t i) {
    const uint32_t n = paramCount(i);
    if (n == 1) {
      gc_.scaleRadiusTangents = paramAt(i, 0) != 0;
      return;
    }
    if (n < 2) return;
    auto tangent = [&](uint32_t k) {
      const double a = radians(paramAt(i, k)), l = paramAt(i, k + 1);
      return glm::dvec2(std::cos(a) * l, std::sin(a) * l);
    };
    gc_.radiusIn = gc_.radiusOut = tangent(0);
    if (n >= 4) gc_.radiusOut = tangent(2);
  }

  /// cpfg's `@Tx(n)` (blackbox.c): the view file's texture n (its n-th `texture:` line, cpfg
  /// truncating n) on the surfaces `~X`, polygons, `F` cylinders and generalized cylinders
  /// drawn after it on this branch; `@Tx` or `@Tx(0)`: none. A number no `texture:` line
  /// has is an error when the turtle draws (cpfg draws untextured); the turtle that only
  /// answers queries (checkTextures false) selects none, as cpfg.
  void texture(size_t i) {
    const double v = hasParam(i) ? param(i) : 0.0;
    const size_t count = settings_.cpfgTextures ? settings_.cpfgTextures->size() : 0;
    if (!std::isfinite(v) || v < 0 || v >= static_cast<double>(count) + 1) {
      if (!settings_.checkTextures) {
        st_.texture = -1;
        return;
      }
      char shown[32];
      std::snprintf(shown, sizeof shown, "%g", v);
      throw InputError(SourceLoc{"sprig", 0, 0},
                       std::string("cpfg's '@Tx(") + shown + ")' names no texture: the view file has " +
                           (count == 0 ? std::string("no 'texture:' line")
                                       : std::to_string(count) + " 'texture:' line" + (count == 1 ? "" : "s")));
    }
    st_.texture = static_cast<int>(v) - 1;
  }

  /// cpfg's `@#(id)`: the contour of the generalized cylinders from here on (0 or no
  /// parameter: the circle). An id the view file does not define is an error.
  void contour(size_t i) {
    const double v = hasParam(i) ? param(i) : 0.0;
    const int id = std::isfinite(v) ? static_cast<int>(std::clamp(v, -2e9, 2e9)) : -1;
    if (id != 0 && !findContour(id))
      throw InputError(SourceLoc{"sprig", 0, 0}, "cpfg's '@#(" + (std::isfinite(v) ? std::to_string(id) : std::string("nan")) +
                                        ")' names no contour: " +
                                        (settings_.cpfgContours ? "the view file has no 'contour: " + std::to_string(id) + " ...' line"
                                                                : std::string("the view file has no 'contour:' line")));
    st_.contour = id;
  }

  const CpfgContour* findContour(int id) const {
    if (!settings_.cpfgContours) return nullptr;
    for (const CpfgContourEntry& e : *settings_.cpfgContours)
      if (e.id == id) return &e.contour;
    return nullptr;
  }

  /// cpfg's `@L("format", v1, ...)` (blackbox.c; utility.c, MakeLabel): the grammar's string
  /// numbered by the first parameter, without its quotes, filled as cpfg's sprintf fills it
  /// with the values as cpfg's 32-bit floats (more than 9 values: no text, cpfg's "Too many
  /// parameters in label"), recorded at the turtle's position with its colour index. A
  /// module not yet born (growth) records nothing. Throws InputError for a first parameter
  /// naming no string and for a format whose conversions are not numbers or outnumber the
  /// values (cpfg would print what its stack holds).
  void label(size_t i) {
    if (growth(i) <= 0) return;
    const uint32_t n = paramCount(i);
    const std::vector<std::string>* formats = settings_.labelFormats.get();
    const double id = n > 0 ? paramAt(i, 0) : -1.0;
    if (!formats || !(id >= 0 && id < static_cast<double>(formats->size())))
      throw InputError(SourceLoc{"sprig", 0, 0}, "cpfg's '@L' names no format: its first parameter must be a \"string\"");
    const std::string format = labelFormat((*formats)[static_cast<size_t>(id)]);
    std::vector<double> values;
    for (uint32_t k = 1; k < n; ++k) values.push_back(static_cast<double>(static_cast<float>(paramAt(i, k))));
    const int conversions = labelConversions(format);
    if (conversions < 0 || conversions > static_cast<int>(values.size()))
      throw InputError(SourceLoc{"sprig", 0, 0},
                       "cpfg's '@L(\"" + format + "\", ...)' " +
                           (conversions < 0 ? std::string("has a conversion that is not a number's (%d %i %o %u %x %c %f %e %g %a)")
                                            : "has " + std::to_string(conversions) + " conversions for " +
                                                  std::to_string(values.size()) + " values"));
    Label l;
    l.position = st_.frame.position;
    l.text = n > 10 ? std::string() : detail::formatPrintf(format, values.data(), static_cast<int>(values.size()));
    l.color = st_.color;
    l.step = stepOf(i);
    sk_.labels.push_back(std::move(l));
  }

  /// A label's format as the grammar wrote it ("..." with C escapes) without its quotes.
  static std::string labelFormat(const std::string& quoted) {
    std::string out;
    const size_t b = quoted.size() >= 2 && quoted.front() == '"' ? 1 : 0, e = b && quoted.back() == '"' ? quoted.size() - 1 : quoted.size();
    for (size_t k = b; k < e; ++k) {
      if (quoted[k] == '\\' && k + 1 < e) {
        const char c = quoted[++k];
        out += c == 'n' ? '\n' : c == 't' ? '\t' : c;
      } else {
        out += quoted[k];
      }
    }
    return out;
  }

  /// Number of conversions of a printf format, or -1 when one is not a number's.
  static int labelConversions(const std::string& f) {
    int n = 0;
    for (size_t k = 0; k < f.size(); ++k) {
      if (f[k] != '%') continue;
      if (k + 1 < f.size() && f[k + 1] == '%') {
        ++k;
        continue;
      }
      size_t g = k + 1;
      while (g < f.size() && std::string_view("-+ #0123456789.hlL").find(f[g]) != std::string_view::npos) ++g;
      if (g >= f.size() || std::string_view("diouxXcfFeEgGaA").find(f[g]) == std::string_view::npos) return -1;
      ++n;
      k = g;
    }
    return n;
  }

  /// cpfg's up vector u0 of a frame of heading h0 carried to heading h without twist
  /// (general.c, adjust_up_and_leftS with no angle): turned by the least rotation taking
  /// h0 to h (Rodrigues); u0 itself when h is h0 or its opposite.
  static DVec3 transportedUp(const DVec3& h0, const DVec3& u0, const DVec3& h) {
    const DVec3 axis = glm::cross(h0, h);
    const double sn = glm::length(axis), cs = glm::dot(h0, h);
    if (sn <= 1e-12) return u0;
    const DVec3 a = axis / sn;
    return u0 * cs + glm::cross(a, u0) * sn + a * glm::dot(a, u0) * (1 - cs);
  }

  /// A generalized-cylinder segment with a contour (general.c, interpolate_connection and
  /// make_contour): rings at the (t, width) pairs of ring along the Hermite curve
  /// p1 + t t1 + t^2 a2 + t^3 a3, each the contours of the two control points blended by t,
  /// scaled by the radius (half the width), placed in the ring's frame: H the
  /// curve's tangent (the first point's heading at t = 0), cpfg's up vector U' the first
  /// point's turned by the rotation taking its heading to H and then about H by t times the
  /// twist angle (from that transported vector to the second point's own at t = 1; the last
  /// ring is the second point's frame), L = H x U'; a contour point
  /// (x, y, z) goes to the ring's centre + r (x U' - y L) + r z H / |p2 - p1|. One Surface
  /// organ per segment, its triangles joining consecutive rings.
  /// texture >= 0: cpfg's texture coordinates (general.c, make_contour): contour point k of
  /// n has s = 1 - k / n (the seam, s = 1 and 0, at the contour's first point, along U' on
  /// the circle), ring k has t = ringT[k]; the organ is named kTexturedGcName and a circle gets
  /// texturedSides points so that it stays round.
  void gcContourMesh(size_t i, const DVec3& p1, const DVec3& t1, const DVec3& a2, const DVec3& a3, double len,
                     const std::vector<glm::dvec2>& ring, int texture, const std::vector<double>& ringT,
                     const DVec3& uEnd) {
    const int rings = static_cast<int>(ring.size()) - 1;
    const CpfgContour circle = CpfgContour::circle();
    const CpfgContour* c1 = gc_.contour ? findContour(gc_.contour) : &circle;
    const CpfgContour* c2 = st_.contour ? findContour(st_.contour) : &circle;
    if (!c1) c1 = &circle;
    if (!c2) c2 = &circle;
    const int sides = texture >= 0 && c1->isCircle() && c2->isCircle() ? texturedSides(gc_.sides) : gc_.sides;
    const std::vector<DVec3> k1 = c1->sample(sides), k2 = c2->sample(sides);
    const double g = growth(i);
    Organ o = organHere(Organ::Kind::Surface, i);
    o.name = texture >= 0 ? kTexturedGcName : "@#";
    o.texture = texture;
    o.position = p1;
    const DVec3 h0 = gc_.heading, u0 = -gc_.up;  // cpfg's up vector at the first point
    auto transported = [&](const DVec3& h) { return transportedUp(h0, u0, h); };
    auto turned = [](const DVec3& v, const DVec3& axis, double angle) {
      return v * std::cos(angle) + glm::cross(axis, v) * std::sin(angle) + axis * glm::dot(axis, v) * (1 - std::cos(angle));
    };
    // cpfg's twist angle (get_twist_angle): from the transported up vector to the second
    // point's (uEnd: its own with `twist of cylinders: on`, else the transported one, so
    // 0), about its heading; ring t turns by t times it, the last ring is uEnd's frame.
    const TurtleFrame& fe = st_.frame;
    const DVec3 u1 = transported(fe.heading);
    const double twist = std::atan2(glm::dot(glm::cross(u1, uEnd), fe.heading), glm::dot(u1, uEnd));
    const uint32_t per = static_cast<uint32_t>(sides) + 1;
    for (int k = 0; k <= rings; ++k) {
      const double t = ring[static_cast<size_t>(k)].x;
      const DVec3 pos = k == rings ? fe.position : p1 + t * (t1 + t * (a2 + t * a3));
      DVec3 h = h0, u = u0, l;
      if (k == rings) {
        h = fe.heading;
        u = uEnd;
      } else if (k > 0) {
        const DVec3 d = t1 + t * (2.0 * a2 + t * 3.0 * a3);
        if (glm::length(d) > 1e-12) h = glm::normalize(d);
        u = turned(transported(h), h, twist * t);
      }
      l = glm::cross(h, u);
      const double r = radiusScale_ * ring[static_cast<size_t>(k)].y * g;
      for (uint32_t m = 0; m < per; ++m) {
        const DVec3 c = k1[m] * (1 - t) + k2[m] * t;
        o.points.push_back(pos + r * (c.x * u - c.y * l) + (r * c.z / len) * h);
        if (texture >= 0)
          o.uvs.emplace_back(static_cast<float>(1.0 - static_cast<double>(m) / sides), static_cast<float>(ringT[static_cast<size_t>(k)]));
      }
    }
    for (uint32_t k = 0; k < static_cast<uint32_t>(rings); ++k)
      for (uint32_t m = 0; m < static_cast<uint32_t>(sides); ++m) {
        const uint32_t a = k * per + m, b = a + 1, c = a + per, d = c + 1;
        o.triangles.insert(o.triangles.end(), {a, c, b, b, c, d});
      }
    // Vertex normals: the area-weighted normals of the triangles around each vertex.
    o.normals.assign(o.points.size(), DVec3(0.0));
    for (size_t k = 0; k + 2 < o.triangles.size(); k += 3) {
      const DVec3 n = glm::cross(o.points[o.triangles[k + 1]] - o.points[o.triangles[k]],
                                 o.points[o.triangles[k + 2]] - o.points[o.triangles[k]]);
      for (int v = 0; v < 3; ++v) o.normals[o.triangles[k + v]] += n;
    }
    for (DVec3& n : o.normals) {
      const double l = glm::length(n);
      n = l > 0 ? n / l : n;
    }
    sk_.organs.push_back(std::move(o));
  }

  /// Starts a generalized cylinder with no control point yet (the tangent parameters stay).
  void gcRestart() {
    gc_.active = true;
    gc_.hasPoint = false;
    gc_.lastInternode = -1;
  }

  /// cpfg's `?(n, s)` (interpret.c, UpdateCurrentLsystem): the sub-L-system scale becomes
  /// the enclosing one times s (unchanged without s), and so do the turtle scale and the
  /// line width (in proportion). The scales form a stack of their own, which `[` and `]`
  /// do not save.
  /// cpfg's `?(n, s)` (a sub-L-system call); returns the last module it takes. A `?`
  /// without parameters is cpfg's query whose letter is the next module (interpret.c, case
  /// '?'): that module is taken and nothing drawn (cpfg warns "unknown query"), unless it
  /// is a letter cpfg would fill (P H L U Q E), a bracket or a module of several
  /// characters, which are errors.
  size_t subCall(size_t i) {
    if (!hasParam(i)) {
      if (i + 1 >= n_) return i;
      const std::string& next = symbols_.name(sym_[i + 1]);
      if (next.size() != 1 || std::string_view("PHLUQE[]").find(next[0]) != std::string_view::npos)
        throw InputError(SourceLoc{"sprig", 0, 0}, "cpfg's '?' followed by the module '" + next +
                                                       "' (cpfg reads it as the query '?" + next +
                                                       "') is not supported");
      return i + 1;
    }
    if (subScales_.empty()) subScales_.push_back(settings_.initialScale);
    const double outer = subScales_.back();
    const double inner = off_[i + 1] - off_[i] >= 2 ? outer * prm_[off_[i] + 1] : outer;
    subScales_.push_back(inner);
    st_.scale = inner;
    st_.width = outer != 0 ? st_.width * inner / outer : st_.width;
    return i;
  }

  /// cpfg's `$`: back to the enclosing sub-L-system's scale (an unmatched `$` does nothing,
  /// as cpfg does after its warning).
  void subEnd() {
    if (subScales_.size() < 2) return;
    const double inner = subScales_.back();
    subScales_.pop_back();
    st_.scale = subScales_.back();
    st_.width = inner != 0 ? st_.width * st_.scale / inner : st_.width;
  }

  /// `@Di` (divide false) and `@Dd` (divide true): multiplies or divides the turtle scale
  /// by the parameter (ignored when 0, as cpfg does), or by the scale multiplier.
  void scaleStep(size_t i, bool divide) {
    double f = hasParam(i) ? param(i) : settings_.scaleMultiplier;
    if (f == 0) return;
    st_.scale = divide ? st_.scale / f : st_.scale * f;
  }
  /// `@M(x,y,z)`: moves to (x, y, z) (z = 0 with two parameters) without drawing.
  void moveTo(size_t i) {
    const uint32_t n = paramCount(i);
    if (n < 2) return;
    st_.frame.position = DVec3(paramAt(i, 0), paramAt(i, 1), n >= 3 ? paramAt(i, 2) : 0.0);
    st_.internode = -1;
  }
  /// `@R(hx,hy,hz)` and `@R(hx,hy,hz,ux,uy,uz)`: sets the heading (and cpfg's up vector,
  /// which is Sprig's -U); without a valid up the frame turns without twist (`@Tp`).
  void setHeading(size_t i) {
    const uint32_t n = paramCount(i);
    if (n < 2) return;
    DVec3 h(paramAt(i, 0), paramAt(i, 1), n >= 3 ? paramAt(i, 2) : 0.0);
    h = glm::dot(h, h) == 0 ? DVec3(0, 1, 0) : glm::normalize(h);
    st_.frame.heading = h;
    if (n >= 6) {
      const DVec3 upCpfg(paramAt(i, 3), paramAt(i, 4), paramAt(i, 5));
      if (glm::dot(upCpfg, upCpfg) != 0 && glm::dot(upCpfg, h) == 0) {
        st_.frame.up = -glm::normalize(upCpfg);
        st_.frame.left = glm::cross(st_.frame.up, h);
        return;
      }
    }
    twistFree();
  }
  /// cpfg's twist-free frame (`@Tp`, and after every tropism bend): U is the U of the last
  /// `F` turned by the rotation that takes that `F`'s heading to the current one; L = U x H.
  void twistFree() {
    TurtleFrame& f = st_.frame;
    DVec3 axis = glm::cross(f.heading, st_.prevHeading);
    double len = glm::length(axis);
    if (len > 1e-6) {
      // The rotation by phi about prevH x H takes prevH to H (phi in [0, pi]).
      double phi = std::asin(std::min(len, 1.0));
      if (glm::dot(f.heading, st_.prevHeading) < 0) phi = kPi - phi;
      const DVec3 a = -axis / len;  // prevH x H, normalized
      const DVec3 u = st_.prevUp;
      f.up = u * std::cos(phi) + glm::cross(a, u) * std::sin(phi) + a * (glm::dot(a, u) * (1 - std::cos(phi)));
    }
    f.left = glm::cross(f.up, f.heading);
  }
  /// cpfg's tropisms (movements.c), before every `F f G g`: the heading turns toward the
  /// sum D of the tropisms (each T times its elasticity, tilted by its angle A) by the
  /// angle min(|H x D|, 1) radians, about H x D; then the frame is made twist-free.
  void cpfgTropisms() {
    const size_t n = std::min(settings_.tropisms.size(), size_t(kMaxTropisms));
    if (n == 0) return;
    TurtleFrame& f = st_.frame;
    DVec3 d(0), twist(0);
    for (size_t k = 0; k < n; ++k) {
      const CpfgTropism& t = settings_.tropisms[k];
      const double e = st_.elasticities[k];
      if (t.torque) {
        twist += e * t.direction;
        continue;
      }
      const double a = radians(t.angleDeg);
      d += std::cos(a) * e * t.direction;
      if (std::sin(a) != 0) {
        DVec3 v = glm::cross(f.heading, t.direction);
        double len = glm::length(v);
        if (len < 1e-7) {
          v = f.left;
          len = 1;
        }
        d += (e * std::sin(a) / len) * glm::cross(t.direction, v);
      }
    }
    DVec3 axis = glm::cross(f.heading, d);
    double len = glm::length(axis);
    if (len >= 1e-6) {
      const double angle = std::min(len, 1.0);
      axis /= len;
      const DVec3 h = f.heading;
      f.heading = glm::normalize(h * std::cos(angle) + glm::cross(axis, h) * std::sin(angle) +
                                 axis * (glm::dot(axis, h) * (1 - std::cos(angle))));
      twistFree();
    }
    if (twist != DVec3(0)) cpfgTorque(twist);
  }

  /// cpfg's torque (movements.c): the sum of the torques' e T, projected perpendicular to H,
  /// turns cpfg's up vector (-U) by min(|U' x D|, 1) radians, by cpfg's own quaternion
  /// rule, reproduced as written; H stays. The frame becomes the twist-free reference.
  void cpfgTorque(const DVec3& twist) {
    TurtleFrame& f = st_.frame;
    const double length = glm::length(twist);
    const DVec3 v = glm::cross(f.heading, twist / length);
    if (glm::dot(v, v) > 1e-8) {
      const DVec3 des = glm::cross(v, f.heading) * length;
      const DVec3 uc = -f.up;
      const DVec3 w = glm::cross(uc, des);
      const double wl = glm::length(w);
      if (wl >= 1e-7) {
        const double lc = std::min(wl, 1.0);
        const double half = 0.5 * lc;
        const glm::dquat q(std::cos(half), std::sin(half) * (w / lc));  // (w, x, y, z)
        const glm::dquat r = glm::inverse(q) * glm::dquat(0, uc) * q;
        f.up = -DVec3(r.x, r.y, r.z);
        f.left = glm::cross(f.up, f.heading);
      }
      st_.prevHeading = f.heading;
      st_.prevUp = f.up;
    }
  }
  /// cpfg's old tropism (interpret.c, `bend`), after every `F f G g`: with s1 = e T.U' and
  /// s2 = e T.L (U' = -U, cpfg's up; T of unit length), H turns toward U' by asin s1, then
  /// toward L by asin s2. cpfg computes NaN when e |T.U'| or e |T.L| exceeds 1; Sprig clamps.
  void cpfgOldBend() {
    const double e = st_.elasticity;
    if (e == 0) return;
    TurtleFrame& f = st_.frame;
    const DVec3 t = oldTropism_;
    double s1 = std::clamp(e * glm::dot(t, -f.up), -1.0, 1.0), c1 = std::sqrt(1 - s1 * s1);
    DVec3 h = c1 * f.heading + s1 * (-f.up);
    f.up = -(c1 * (-f.up) - s1 * f.heading);
    f.heading = h;
    double s2 = std::clamp(e * glm::dot(t, f.left), -1.0, 1.0), c2 = std::sqrt(1 - s2 * s2);
    h = c2 * f.heading + s2 * f.left;
    f.left = c2 * f.left - s2 * f.heading;
    f.heading = h;
  }

  /// `@Ti(n, de)` (sign +1) and `@Td(n, de)` (sign -1): steps the elasticity of tropism n
  /// by de, or by its step S: without de (cpfg's index rule: trunc(n - 1); out of range: ignored).
  void tropismStep(size_t i, int sign) {
    const uint32_t n = paramCount(i);
    if (n == 0) return;
    const int k = tropismIndex(paramAt(i, 0));
    if (settings_.cpfg) {
      if (k < 0 || k >= static_cast<int>(std::min(settings_.tropisms.size(), size_t(kMaxTropisms)))) return;
      st_.elasticities[k] += sign * (n >= 2 ? paramAt(i, 1) : settings_.tropisms[k].step);
    } else if (k == 0 && n >= 2) {
      st_.elasticity += sign * paramAt(i, 1);
    }
  }
  /// `.`: adds the position to the innermost open polygon.
  void vertex() {
    if (!buf_.polygons.empty()) addPolygonPoint(st_.frame.position);
  }
  /// cpfg's index of tropism number n: n - 1 truncated toward 0 (`(short)(n - 1)`), -1
  /// when out of any tropism's range.
  static int tropismIndex(double n) {
    const double k = std::trunc(n - 1);
    return k >= 0 && k < kMaxTropisms ? static_cast<int>(k) : -1;
  }
  /// A color index from a parameter (clamped into int's range).
  static int colorIndex(double c) { return static_cast<int>(std::clamp(c, -1e9, 1e9)); }

  /// `@Ts(n, e)`: sets the elasticity of tropism n to e (cpfg's index rule: trunc(n - 1);
  /// an index out of range is ignored, as cpfg does). In cpfg's notation `@Ts(n)` sets it
  /// to 0, as cpfg does; in Sprig's, `@Ts(e)` sets the one (species) tropism's elasticity to e.
  void tropismChange(size_t i) {
    const uint32_t n = paramCount(i);
    if (n == 0) return;
    if (!settings_.cpfg && n == 1) {
      st_.elasticity = param(i);
      return;
    }
    const int k = tropismIndex(paramAt(i, 0));
    const double e = n >= 2 ? paramAt(i, 1) : 0.0;
    if (settings_.cpfg) {
      if (k >= 0 && k < static_cast<int>(std::min(settings_.tropisms.size(), size_t(kMaxTropisms)))) st_.elasticities[k] = e;
    } else if (k == 0) {
      st_.elasticity = e;
    }
  }

  /// An organ of kind at the turtle, attached to the current internode, for module i.
  Organ organHere(Organ::Kind kind, size_t i) const {
    Organ o;
    o.kind = kind;
    o.position = st_.frame.position;
    o.heading = st_.frame.heading;
    o.left = st_.frame.left;
    o.up = st_.frame.up;
    o.internode = st_.internode;
    o.step = stepOf(i);
    o.color = st_.color;
    return o;
  }

  /// `}`: closes the innermost polygon; one of at least 3 points (and grown) is an organ.
  void polygonEnd(size_t i) {
    if (buf_.polygons.empty()) return;
    if (buf_.polygons.back().points.size() >= 3 && growth(i) > 0) {
      OpenPolygon& poly = buf_.polygons.back();
      Organ o = organHere(Organ::Kind::Polygon, i);
      o.points = std::move(poly.points);
      o.position = o.points.front();
      o.internode = poly.internode;
      if (poly.texture >= 0) texturePolygon(o, poly);
      sk_.organs.push_back(std::move(o));
    }
    buf_.polygons.pop_back();
  }

  /// A textured polygon as cpfg draws it (irisGL.c PolygonToMesh, textures.c
  /// SetPolygonTextureParams): a fan of triangles from its first point, each point's texture
  /// coordinates its position along the first point's -L (s) and H (t), over the polygon's
  /// extent along them (0 to 1; a polygon without extent along an axis gets 0 on it). The
  /// normals are the polygon's Newell normal, as untextured polygons are drawn.
  static void texturePolygon(Organ& o, const OpenPolygon& poly) {
    o.texture = poly.texture;
    double s0 = std::numeric_limits<double>::infinity(), s1 = -s0, t0 = s0, t1 = -s0;
    DVec3 n(0);
    for (size_t k = 0; k < o.points.size(); ++k) {
      const DVec3& p = o.points[k];
      s0 = std::min(s0, glm::dot(p, poly.sAxis)), s1 = std::max(s1, glm::dot(p, poly.sAxis));
      t0 = std::min(t0, glm::dot(p, poly.tAxis)), t1 = std::max(t1, glm::dot(p, poly.tAxis));
      n += glm::cross(p, o.points[(k + 1) % o.points.size()]);
    }
    const double ln = glm::length(n);
    const DVec3 normal = ln > 0 ? n / ln : o.up;
    for (const DVec3& p : o.points) {
      o.uvs.emplace_back(s1 > s0 ? static_cast<float>((glm::dot(p, poly.sAxis) - s0) / (s1 - s0)) : 0.0f,
                         t1 > t0 ? static_cast<float>((glm::dot(p, poly.tAxis) - t0) / (t1 - t0)) : 0.0f);
      o.normals.push_back(normal);
    }
    for (uint32_t k = 1; k + 1 < o.points.size(); ++k) o.triangles.insert(o.triangles.end(), {0u, k, k + 1});
  }

  /// Adds a surface organ named name with scale radius for module i (not when growth
  /// leaves nothing of it).
  [[gnu::always_inline]] void addSurface(size_t i, std::string name, double radius) {
    radius *= growth(i);
    if (radius <= 0 && growing_) return;
    Organ o = organHere(Organ::Kind::Surface, i);
    o.radius = radius;
    o.name = std::move(name);
    sk_.organs.push_back(std::move(o));
  }

  /// cpfg's `~X`, `~X(s)` or `~X(sx, sy, sz)` for module i (interpret.c's '~' case,
  /// patches.c): the view file's surface X, scaled by s (default 1) times the turtle scale,
  /// a Surface organ with its mesh placed at the turtle (CpfgSurface's comment has the map);
  /// then the turtle moves to the surface's end point (scaled by s only, as in cpfg). An id
  /// the view file does not define draws nothing (the grammar parser refuses it).
  void cpfgSurface(size_t i, char id) {
    if (!settings_.cpfgSurfaces) return;
    const CpfgSurface* sf = nullptr;
    const CpfgSurfaceEntry* entry = nullptr;
    for (const CpfgSurfaceEntry& e : *settings_.cpfgSurfaces)
      if (e.id == id) {
        sf = &e.surface;
        entry = &e;
      }
    if (!sf) return;
    const uint32_t n = paramCount(i);
    DVec3 sc(1.0);
    if (n >= 3) sc = DVec3(paramAt(i, 0), paramAt(i, 1), paramAt(i, 2));
    else if (n >= 1) sc = DVec3(paramAt(i, 0));
    sc *= st_.scale * growth(i);
    const TurtleFrame& f = st_.frame;
    const DVec3 cpfgUp = -f.up;
    if (sc.x != 0 && sc.y != 0 && sc.z != 0) {
      Organ o = organHere(Organ::Kind::Surface, i);
      o.radius = sc.y;
      o.name = std::string(1, id);
      // The surface's own texture number overrides the turtle's (patches.c, s_textures).
      o.texture = entry->texture < 0 ? st_.texture : entry->texture - 1;
      if (o.texture >= 0 && settings_.cpfgTextures && static_cast<size_t>(o.texture) < settings_.cpfgTextures->size()) {
        const std::vector<glm::dvec2>& uv = sf->uvs((*settings_.cpfgTextures)[static_cast<size_t>(o.texture)].perSurface);
        o.uvs.reserve(uv.size());
        for (const glm::dvec2& q : uv) o.uvs.emplace_back(static_cast<float>(q.x), static_cast<float>(q.y));
      } else {
        o.texture = -1;
      }
      const glm::dmat3 m(sc.x * f.left, sc.y * f.heading, sc.z * cpfgUp);  // columns
      // Normals transform by the inverse transpose (cofactor form: no division by zero).
      const glm::dmat3 nm(glm::cross(m[1], m[2]), glm::cross(m[2], m[0]), glm::cross(m[0], m[1]));
      o.points.reserve(sf->vertices().size());
      o.normals.reserve(sf->vertices().size());
      for (size_t k = 0; k < sf->vertices().size(); ++k) {
        o.points.push_back(f.position + m * sf->vertices()[k]);
        const DVec3 nk = nm * sf->normals()[k];
        const double len = glm::length(nk);
        o.normals.push_back(len > 0 ? nk / len : nk);
      }
      o.triangles = sf->triangles();
      // A mirroring scale (an odd number of negative factors) turns the winding over.
      if (sc.x * sc.y * sc.z < 0)
        for (size_t k = 0; k + 2 < o.triangles.size(); k += 3) std::swap(o.triangles[k + 1], o.triangles[k + 2]);
      sk_.organs.push_back(std::move(o));
    }
    const double s = sc.x;
    const DVec3 e = sf->endPoint();
    st_.frame.position += s * (e.x * f.left + e.y * f.heading + e.z * cpfgUp);
  }

  /// cpfg's `~l` or `~l(scale)` written as two modules: the module after `~` names the
  /// surface and is consumed. Returns the index of the last module read.
  size_t surface(size_t i) {
    if (i + 1 >= n_) return i;
    if (settings_.cpfg) {
      // cpfg: `~` reads the next module; its name's first letter is the surface id.
      ++i;
      const std::string& name = symbols_.name(sym_[i]);
      cpfgSurface(i, name.empty() ? '\0' : name[0]);
      return i;
    }
    double radius = hasParam(i) ? param(i) : settings_.surfaceScale;
    ++i;
    if (off_[i] == off_[i - 1] && hasParam(i)) radius = param(i);
    addSurface(i, symbols_.name(sym_[i]), radius);
    return i;
  }

  /// `~l` as one symbol (`~` and a letter).
  void surfaceNamed(size_t i) {
    if (settings_.cpfg) {
      cpfgSurface(i, symbols_.name(sym_[i])[1]);
      return;
    }
    addSurface(i, symbols_.name(sym_[i]).substr(1), hasParam(i) ? param(i) : settings_.surfaceScale);
  }

  /// `@O(r)`: a sphere of radius r (default: half the line width). In cpfg's notation
  /// `@O(d)` and `@o(d)` take a diameter (times the turtle scale; default the line width);
  /// cpfg draws `@o` as a disc facing the viewer, whose outline a sphere has from every side.
  void sphere(size_t i) {
    double radius = hasParam(i) ? param(i) : st_.width * radiusScale_;
    if (settings_.cpfg && hasParam(i)) radius = 0.5 * param(i) * st_.scale;
    radius *= growth(i);
    if (radius <= 0 && growing_) return;
    Organ o = organHere(Organ::Kind::Sphere, i);
    o.radius = radius;
    sk_.organs.push_back(std::move(o));
  }

  /// `@c(d)`: a disc of diameter d (times the turtle scale; default the line width) in the
  /// turtle's HL plane, centered at the turtle: a polygon organ of kDiscSides vertices.
  void disc(size_t i) {
    double radius = hasParam(i) ? 0.5 * param(i) * (settings_.cpfg ? st_.scale : 1.0) : st_.width * radiusScale_;
    radius *= growth(i);
    if (radius <= 0) return;
    Organ o = organHere(Organ::Kind::Polygon, i);
    o.points.reserve(kDiscSides);
    for (int k = 0; k < kDiscSides; ++k) {
      const double t = 2 * kPi * k / kDiscSides;
      o.points.push_back(st_.frame.position + radius * (std::cos(t) * st_.frame.heading + std::sin(t) * st_.frame.left));
    }
    o.position = o.points.front();
    sk_.organs.push_back(std::move(o));
  }

  /// `%`: the branch ends here: marks its last internode as cut and skips to the matching
  /// `]`. Returns the index before that `]` (or the last index), for the loop's ++i.
  /// In cpfg's notation a `%` in the string is a cut the next derivation step makes (cpfg
  /// keeps it until then): the rest of the branch is skipped as cpfg's SkipCutPart does,
  /// also up to the `$` that ends the sub-L-system call it is in, and nothing is marked.
  size_t cut(size_t i) {
    if constexpr (!kSummary)
      if (st_.internode >= 0 && !settings_.cpfg) sk_.internodes[st_.internode].cut = true;
    int depth = 0, calls = 0;
    size_t j = i + 1;
    for (; j < n_; ++j) {
      Command cj = commandAt(j);
      if (cj == Command::Push) {
        ++depth;
      } else if (cj == Command::Pop) {
        if (depth == 0) break;
        --depth;
      } else if (cj == Command::SubCall && paramCount(j) >= 1) {
        ++calls;
      } else if (cj == Command::SubEnd && calls-- == 0) {
        break;
      }
    }
    return j - 1;
  }

  /// kSummary: what the current state's last internode contributes to a continuation.
  struct LastDrawn {
    DVec3 start{0};
    double radius = 0;  ///< max(base, tip) as drawn
    int order = 0;
  };

  const SymbolTable& symbols_;
  const TurtleSettings& settings_;
  Skeleton& sk_;
  SkeletonSummary* sum_;
  LastDrawn last_;
  std::vector<LastDrawn> lastStack_;
  WalkBuffers buf_;
  const size_t n_;
  const SymbolId* sym_;
  const uint32_t* off_;
  const double* prm_;
  const Command* cmd_;
  const size_t ncmd_;
  const std::span<const int32_t> steps_;
  const bool haveSteps_;
  const double radiusScale_;
  const double maxRadiusPerLength_;
  const bool taper_;
  const DVec3 tropism_;
  const DVec3 oldTropism_ = glm::length(settings_.tropism) > 0 ? glm::normalize(settings_.tropism) : DVec3(0);
  const double defS_, defC_;
  const bool growing_;
  const double partial_;
  SinCosCache trig_;
  TurtleState st_;
  std::vector<double> subScales_;  ///< cpfg's sub-L-system scales (`?(n, s)`), outermost first
  /// cpfg's generalized cylinder in progress (gcPoint) and the turtle's tangent parameters.
  struct GcState {
    bool active = false;      ///< between `@Gs` (or a first `@Gc`) and `@Ge`
    bool hasPoint = false;    ///< the previous control point below is set
    DVec3 position{0}, heading{0, 1, 0}, up{0, 0, 1};
    double width = 0;
    int contour = 0;  ///< the contour id at the previous control point
    glm::dvec2 radiusIn{0.0}, radiusOut{0.0};  ///< `@Gr(a, l[, a2, l2])`: the turtle's radius tangents (cpfg's [0], [1])
    glm::dvec2 pointRadiusOut{0.0};            ///< radiusOut at the previous control point
    bool scaleRadiusTangents = false;          ///< `@Gr(s)`, s != 0: radius tangents times the segment's length
    int sides = CpfgContour::kDefaultSides;  ///< points around its contour
    double tangentIn = 1.2, tangentOut = 1.2;  ///< `@Gt(in, out)`: the turtle's (cpfg's defaults)
    double pointTangentOut = 1.2;              ///< tangentOut at the previous control point
    int32_t lastInternode = -1;                ///< the last piece drawn (parent of the next)
    int texture = -1;                          ///< the texture selected at the previous control point
    double texT = 0.0;                         ///< the turtle's texture t there
  };
  GcState gc_;
  std::vector<GcState> gcStack_;  ///< saved by `[` when the string has generalized cylinders
  bool usesGc_ = false;
  std::vector<Turtle::QueryHit>* queries_ = nullptr;
};

}  // namespace

Skeleton Turtle::run(const ModuleString& ms, std::span<const int32_t> moduleSteps) {
  Skeleton sk;
  run(ms, sk, moduleSteps);
  return sk;
}

void Turtle::run(const ModuleString& ms, Skeleton& sk, std::span<const int32_t> moduleSteps) {
  sk.internodes.clear();
  sk.organs.clear();
  if (moduleSteps.empty() && ms.hasBirthSteps()) moduleSteps = ms.birthSteps;
  TurtleWalk<false> walk(symbols_, settings_, commands_, ms, sk, moduleSteps);
  walk.reserveInternodes();
  end_ = walk.walk();
  if (settings_.radii == RadiusModel::Pipe) walk.pipeRadii();
}

SkeletonSummary Turtle::summarize(const ModuleString& ms, std::span<const int32_t> moduleSteps) {
  if (moduleSteps.empty() && ms.hasBirthSteps()) moduleSteps = ms.birthSteps;
  Skeleton sk;
  SkeletonSummary sum;
  if (settings_.radii == RadiusModel::Pipe || settings_.growthStep >= 0) {
    // Pipe radii are set after the whole walk, growth radii per internode: draw it all.
    run(ms, sk, moduleSteps);
    sum.internodes = sk.internodes.size();
    sum.totalLength = sk.totalLength();
    sum.bounds = sk.bounds();
  } else {
    TurtleWalk<true> walk(symbols_, settings_, commands_, ms, sk, moduleSteps, &sum);
    end_ = walk.walk();
    const DBox3 organs = sk.bounds();  // sk holds the organs only
    if (!organs.empty()) {
      sum.bounds.extend(organs.lo);
      sum.bounds.extend(organs.hi);
    }
  }
  sum.organs = std::move(sk.organs);
  return sum;
}

std::vector<Turtle::QueryHit> Turtle::query(const ModuleString& ms) {
  std::vector<QueryHit> hits;
  Skeleton sk;
  SkeletonSummary sum;
  TurtleWalk<true> walk(symbols_, settings_, commands_, ms, sk, {}, &sum);
  walk.recordQueries(&hits);
  end_ = walk.walk();
  return hits;
}

Skeleton interpret(const ModuleString& modules, const SymbolTable& symbols, const TurtleSettings& settings,
                   std::span<const int32_t> moduleSteps) {
  Turtle t(symbols, settings);
  return t.run(modules, moduleSteps);
}

}  // namespace sprig::lsystem
