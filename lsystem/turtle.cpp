#include "lsystem/turtle.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <string_view>

#ifdef __linux__
#include <sys/mman.h>
#endif

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

/// Large fresh outputs are dominated by first-touch page faults (about half the time
/// for a 2-million-internode skeleton); asking Linux for transparent huge pages on the
/// buffer cuts the number of faults 512-fold. A hint only: failure changes nothing.
void adviseHugePages(void* data, size_t bytes) {
#ifdef __linux__
  constexpr uintptr_t kHuge = uintptr_t(2) << 20;
  if (bytes < 4 * kHuge) return;
  uintptr_t begin = (reinterpret_cast<uintptr_t>(data) + kHuge - 1) & ~(kHuge - 1);
  uintptr_t end = (reinterpret_cast<uintptr_t>(data) + bytes) & ~(kHuge - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)data;
  (void)bytes;
#endif
}

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
        case '$': c = Command::RollToVertical; break;
        case '[': c = Command::Push; break;
        case ']': c = Command::Pop; break;
        case '!': c = Command::Width; break;
        case '\'': c = Command::Color; break;
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
    } else if (n.size() > 1 && n[0] == '~') {
      c = Command::SurfaceNamed;
    }
    commands_[i] = c;
  }
}

Skeleton Turtle::run(const ModuleString& ms, std::span<const int32_t> moduleSteps) {
  Skeleton sk;
  run(ms, sk, moduleSteps);
  return sk;
}

void Turtle::run(const ModuleString& ms, Skeleton& sk, std::span<const int32_t> moduleSteps) {
  sk.internodes.clear();
  sk.organs.clear();
  const size_t n = ms.size();
  const SymbolId* sym = ms.symbols.data();
  const uint32_t* off = ms.offsets.data();
  const double* prm = ms.params.data();
  const Command* cmd = commands_.data();
  const size_t ncmd = commands_.size();
  if (moduleSteps.empty() && ms.hasBirthSteps()) moduleSteps = ms.birthSteps;
  const bool haveSteps = moduleSteps.size() >= n;

  {
    // Reserve the exact number of drawing modules: cheaper than growing the vector.
    size_t draws = 0;
    for (size_t i = 0; i < n; ++i) {
      Command c = sym[i] < ncmd ? cmd[sym[i]] : Command::None;
      draws += c == Command::Forward || c == Command::ForwardNoVertex;
    }
    sk.internodes.reserve(draws);
    adviseHugePages(sk.internodes.data(), sk.internodes.capacity() * sizeof(Internode));
  }

  TurtleState st;
  st.frame.position = settings_.origin;
  st.width = settings_.initialWidth;
  st.elasticity = settings_.elasticity;
  std::vector<TurtleState> stack;
  stack.reserve(64);
  struct OpenPolygon {
    std::vector<DVec3> points;
    int32_t internode;  // the internode the polygon grows from (at its `{`)
  };
  std::vector<OpenPolygon> polygons;  // open `{` polygons, innermost last

  const double radiusScale = 0.5 * settings_.widthScale;
  const double maxRadiusPerLength = settings_.radii == RadiusModel::Width ? 0.5 * settings_.maxWidthToLength : 0.0;
  const bool taper = settings_.taper && settings_.radii == RadiusModel::Width;
  const DVec3 tropism = settings_.tropism;
  const double defS = std::sin(radians(settings_.angleDeg));
  const double defC = std::cos(radians(settings_.angleDeg));
  SinCosCache trig;

  auto angle = [&](size_t i, double& s, double& c) {
    if (off[i + 1] > off[i]) {
      trig.get(prm[off[i]], s, c);
    } else {
      s = defS;
      c = defC;
    }
  };
  auto stepOf = [&](size_t i) { return haveSteps ? moduleSteps[i] : 0; };
  // Growth: the scale of module i (1 = full size, 0 = not yet drawn).
  const bool growing = settings_.growthStep >= 0 && haveSteps;
  const double partial = settings_.growthScale();
  auto growth = [&](size_t i) {
    if (!growing) return 1.0;
    const int32_t born = moduleSteps[i];
    return born < settings_.growthStep ? 1.0 : born == settings_.growthStep ? partial : 0.0;
  };
  std::vector<double> internodeGrowth;  // per internode, for the pipe model's radii (growth only)
  auto length = [&](size_t i) {
    const double l = off[i + 1] > off[i] ? prm[off[i]] : settings_.stepLength;
    return growing ? l * growth(i) : l;
  };

  for (size_t i = 0; i < n; ++i) {
    const SymbolId s = sym[i];
    const Command c = s < ncmd ? cmd[s] : Command::None;
    double sn, cs;
    switch (c) {
      case Command::None: break;
      case Command::Forward:
      case Command::ForwardNoVertex: {
        DVec3 start = st.frame.position;
        st.frame.position += st.frame.heading * length(i);
        if (!polygons.empty()) {
          if (c == Command::Forward) polygons.back().points.push_back(st.frame.position);
          st.internode = -1;  // outlines are not drawn; the next segment starts a new axis
          break;
        }
        const double g = growth(i);
        if (g <= 0) break;  // not grown yet: nothing drawn, no bend; the axis carries on from its parent
        Internode in;
        in.start = start;
        in.end = st.frame.position;
        in.baseRadius = in.tipRadius = st.width * radiusScale * g;
        if (maxRadiusPerLength > 0)
          in.baseRadius = in.tipRadius = std::min(in.baseRadius, maxRadiusPerLength * glm::length(in.end - in.start));
        if (growing) internodeGrowth.push_back(g);
        in.parent = st.internode;
        in.order = st.order;
        in.step = stepOf(i);
        in.module = static_cast<uint32_t>(i);
        in.up = st.frame.up;
        // Taper: the continuation of an axis (the child drawn at the parent's own order; a
        // parent has at most one, since `[` raises the order) ends the parent's radius.
        if (taper && in.parent >= 0 && sk.internodes[in.parent].order == in.order)
          sk.internodes[in.parent].tipRadius = in.baseRadius;
        st.internode = static_cast<int32_t>(sk.internodes.size());
        sk.internodes.push_back(in);
        // A growing internode bends in proportion to its growth, so frames change smoothly.
        if (st.elasticity != 0) applyTropism(st.frame, tropism, st.elasticity * g);
        break;
      }
      case Command::Move:
      case Command::MoveNoVertex:
        st.frame.position += st.frame.heading * length(i);
        if (!polygons.empty() && c == Command::Move) polygons.back().points.push_back(st.frame.position);
        st.internode = -1;  // the next segment starts a new, disconnected axis
        break;
      case Command::TurnLeft: angle(i, sn, cs); rotatePair(st.frame.heading, st.frame.left, cs, sn); break;
      case Command::TurnRight: angle(i, sn, cs); rotatePair(st.frame.heading, st.frame.left, cs, -sn); break;
      case Command::PitchDown: angle(i, sn, cs); rotatePair(st.frame.up, st.frame.heading, cs, sn); break;
      case Command::PitchUp: angle(i, sn, cs); rotatePair(st.frame.up, st.frame.heading, cs, -sn); break;
      case Command::RollLeft: angle(i, sn, cs); rotatePair(st.frame.left, st.frame.up, cs, sn); break;
      case Command::RollRight: angle(i, sn, cs); rotatePair(st.frame.left, st.frame.up, cs, -sn); break;
      case Command::TurnAround:
        st.frame.heading = -st.frame.heading;
        st.frame.left = -st.frame.left;
        break;
      case Command::RollToVertical: rollToVertical(st.frame); break;
      case Command::Push:
        stack.push_back(st);
        ++st.order;
        break;
      case Command::Pop:
        if (!stack.empty()) {
          st = stack.back();
          stack.pop_back();
        }
        break;
      case Command::Width:
        st.width = off[i + 1] > off[i] ? prm[off[i]] : st.width * settings_.widthFactor;
        break;
      case Command::Color: st.color = off[i + 1] > off[i] ? static_cast<int>(prm[off[i]]) : st.color + 1; break;
      case Command::PolygonBegin: polygons.push_back({{}, st.internode}); break;
      case Command::Vertex:
        if (!polygons.empty()) polygons.back().points.push_back(st.frame.position);
        break;
      case Command::PolygonEnd:
        if (!polygons.empty()) {
          if (polygons.back().points.size() >= 3 && growth(i) > 0) {
            Organ o;
            o.kind = Organ::Kind::Polygon;
            o.points = std::move(polygons.back().points);
            o.position = o.points.front();
            o.heading = st.frame.heading;
            o.left = st.frame.left;
            o.up = st.frame.up;
            o.internode = polygons.back().internode;
            o.step = stepOf(i);
            o.color = st.color;
            sk.organs.push_back(std::move(o));
          }
          polygons.pop_back();
        }
        break;
      case Command::Surface:
      case Command::SurfaceNamed: {
        Organ o;
        o.kind = Organ::Kind::Surface;
        o.radius = off[i + 1] > off[i] ? prm[off[i]] : settings_.surfaceScale;
        if (c == Command::SurfaceNamed) {
          o.name = symbols_.name(s).substr(1);
        } else if (i + 1 < n) {
          // cpfg style `~l` or `~l(scale)`: the next module names the surface and is consumed.
          ++i;
          o.name = symbols_.name(sym[i]);
          if (off[i] == off[i - 1] && off[i + 1] > off[i]) o.radius = prm[off[i]];
        } else {
          break;
        }
        o.radius *= growth(i);
        if (o.radius <= 0 && growing) break;
        o.position = st.frame.position;
        o.heading = st.frame.heading;
        o.left = st.frame.left;
        o.up = st.frame.up;
        o.internode = st.internode;
        o.step = stepOf(i);
        o.color = st.color;
        sk.organs.push_back(std::move(o));
        break;
      }
      case Command::Sphere: {
        Organ o;
        o.kind = Organ::Kind::Sphere;
        o.radius = (off[i + 1] > off[i] ? prm[off[i]] : st.width * radiusScale) * growth(i);
        if (o.radius <= 0 && growing) break;
        o.position = st.frame.position;
        o.heading = st.frame.heading;
        o.left = st.frame.left;
        o.up = st.frame.up;
        o.internode = st.internode;
        o.step = stepOf(i);
        o.color = st.color;
        sk.organs.push_back(std::move(o));
        break;
      }
      case Command::Tropism:
        if (off[i + 1] > off[i]) st.elasticity = prm[off[i]];
        break;
      case Command::Cut: {
        // The branch ends here: mark its last internode as cut, skip to the matching `]`.
        if (st.internode >= 0) sk.internodes[st.internode].cut = true;
        int depth = 0;
        size_t j = i + 1;
        for (; j < n; ++j) {
          Command cj = sym[j] < ncmd ? cmd[sym[j]] : Command::None;
          if (cj == Command::Push) {
            ++depth;
          } else if (cj == Command::Pop) {
            if (depth == 0) break;
            --depth;
          }
        }
        i = j - 1;  // the loop's ++i lands on the `]` (or the end)
        break;
      }
    }
  }
  end_ = st;

  // Radii post-pass. Children always follow their parent in drawing order, so one
  // backward sweep sees every child before its parent.
  auto& ins = sk.internodes;
  const size_t m = ins.size();
  if (settings_.radii == RadiusModel::Pipe) {
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
    if (growing)
      for (size_t k = 0; k < m; ++k) {
        ins[k].baseRadius *= internodeGrowth[k];
        ins[k].tipRadius *= internodeGrowth[k];
      }
  }
}

Skeleton interpret(const ModuleString& modules, const SymbolTable& symbols, const TurtleSettings& settings,
                   std::span<const int32_t> moduleSteps) {
  Turtle t(symbols, settings);
  return t.run(modules, moduleSteps);
}

}  // namespace sprig::lsystem
