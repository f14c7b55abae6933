#include "model/shell_kind.h"
#include "core/timer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <glm/gtc/matrix_transform.hpp>

#include "blobtree/polygonize.h"
#include "core/parallel.h"
#include "model/mesh_parts.h"
#include "organisms/rest_pose.h"

namespace sprig {

using organisms::GeneratingPrimitive;
using organisms::GeneratingSurface;
using organisms::ShellParams;
using organisms::VarixSpine;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();


float num(MapReader& r, Key key, float def, double lo = -kInf, double hi = kInf) {
  return static_cast<float>(r.number(key, def, lo, hi));
}

/// A part section: absent (keeps `enabled`), `true`/`false`, or a map (enables it).
std::optional<YNode> partSection(MapReader& top, Key key, bool& enabled, DiagnosticList& diags) {
  auto n = top.get(key);
  if (!n) return std::nullopt;
  if (n->isScalar()) {
    if (auto b = n->asBoolean(diags, quoted(key.name))) enabled = *b;
    return std::nullopt;
  }
  if (!n->isMap() && !n->isNull()) {
    n->error(diags, quoted(key.name) + " must be a map or true/false");
    return std::nullopt;
  }
  enabled = true;
  return n;
}

std::vector<float> floatList(const YNode& n, DiagnosticList& diags, std::string_view what, double lo, double hi) {
  std::vector<float> out;
  if (!n.isSequence()) {
    n.error(diags, quoted(what) + " must be a sequence");
    return out;
  }
  for (const YNode& v : n.items())
    if (auto x = v.asNumber(diags, quoted(what) + " entry", lo, hi)) out.push_back(static_cast<float>(*x));
  return out;
}

void readGenerating(MapReader& top, ShellParams& p, DiagnosticList& diags) {
  auto g = top.get({"generating", "The generating surface swept along the spiral: `point`, `murex` or `{primitives: [...]}`."});
  if (!g) return;
  if (g->isScalar()) {
    static const std::vector<std::string> kinds = {"point", "murex"};
    const std::string k = g->scalar();
    p.generating = GeneratingSurface::point();
    p.canal.reset();
    if (k == "murex") {
      p.canal = organisms::CanalOptions{};
      p.canal->sweepDeg = 1.333 * p.whorlDeg;
    } else if (k != "point")
      g->error(diags, "unknown generating surface '" + k + "' (point, murex or a map of primitives)" + didYouMean(k, kinds));
    return;
  }
  MapReader gen(*g, diags, "generating");
  p.generating.primitives.clear();
  p.canal.reset();
  static const std::vector<std::string> kinds = {"point", "cone"};
  for (const YNode& item : gen.sequence({"primitives", "Primitives summed into the generating surface, each `{point: {...}}` or `{cone: {...}}`, in the unit frame (1 = D(θ))."})) {
    auto described = describeOneKey(item, kinds);  // `sprig schema`: a one-key map, one kind's keys
    if (!described && (!item.isMap() || item.pairs().size() != 1)) {
      item.error(diags, "a generating primitive must be a map with one key: point or cone");
      continue;
    }
    const auto [keyNode, value] = described ? *described : item.pairs().front();
    const std::string kind = keyNode.scalar();
    describeHelp(value, kind == "point" ? "A point primitive of the generating surface: a sphere of `radius` around `center`."
                                        : "A cone primitive of the generating surface: from `a` to `b`, radii `radius_a` and `radius_b`, bent by `bend`.");
    GeneratingPrimitive prim;
    MapReader r(value, diags, kind);
    if (kind == "point") {
      prim.kind = GeneratingPrimitive::Kind::Point;
      prim.a = r.vec3({"center", "Centre of the point in the unit generating frame."}, Vec3(0.0f), -100, 100);
      prim.radiusA = prim.radiusB = num(r, {"radius", "Radius of the point (its 0.5-iso radius), unit frame."}, 1.0f, 1e-4, 100);
    } else if (kind == "cone") {
      prim.kind = GeneratingPrimitive::Kind::Cone;
      prim.a = r.vec3({"a", "Start of the cone in the unit generating frame."}, Vec3(0.0f), -100, 100);
      prim.b = r.vec3({"b", "End of the cone in the unit generating frame (must differ from `a`)."}, Vec3(0.0f, 1.0f, 0.0f), -100, 100);
      prim.radiusA = num(r, {"radius_a", "Radius (0.5-iso) of the cone at `a`, unit frame."}, 0.3f, 1e-4, 100);
      prim.radiusB = num(r, {"radius_b", "Radius (0.5-iso) of the cone at `b`, unit frame."}, 0.2f, 1e-4, 100);
      prim.bendDeg = num(r, {"bend", "Bend of the cone in degrees, keeping `a` and `b` fixed (0 = straight)."}, 0.0f, 0.0, 180.0);
      prim.bendDirection = r.vec3({"bend_direction", "Direction the bent cone bulges towards."}, Vec3(1, 0, 0), -1e3, 1e3);
      prim.canal = r.boolean({"canal", "This cone is the siphonal canal: the axial spines sit along it."}, false);
      if (glm::length(prim.b - prim.a) < 1e-4f) value.error(diags, "cone 'a' and 'b' must differ");
    } else {
      keyNode.error(diags, "unknown generating primitive '" + kind + "' (point or cone)" + didYouMean(kind, kinds));
      continue;
    }
    prim.lastDeg = r.number({"last", "Sweep this primitive over the last DEG degrees before θ_end only (0 = the whole spiral)."}, 0.0, 0.0, 1e6);
    r.finish();
    p.generating.primitives.push_back(prim);
  }
  if (p.generating.primitives.empty()) g->error(diags, "'generating' needs at least one primitive");
  gen.finish();
}

/// `canal:` shapes the canal of `generating: murex` (organisms::CanalOptions).
void readCanal(MapReader& top, ShellParams& p, DiagnosticList& diags) {
  auto sec = top.section({"canal", "The Murex's siphonal canal (with `generating: murex` only)."});
  if (!sec) return;
  organisms::CanalOptions unused;  // the keys are still read (checked, and seen by `sprig schema`)
  if (!p.canal)
    sec->error(diags, "'canal' shapes the siphonal canal of 'generating: murex', and this shell's generating surface has "
                      "none (use generating: murex, or a cone with 'canal: true' among its primitives)");
  organisms::CanalOptions& c = p.canal ? *p.canal : unused;
  MapReader r(*sec, diags, "canal");
  if (auto st = r.get({"start", "[x, y] where the canal leaves the generating surface, unit frame (default [-0.45, 0.7]); x must lie farther from the axis than the tip."})) {
    const std::vector<float> xy = floatList(*st, diags, "start", -100.0, 100.0);
    if (xy.size() == 2)
      c.start = Vec2(xy[0], xy[1]);
    else if (st->isSequence())
      st->error(diags, "'start' must be [x, y] (the unit generating frame)");
  }
  c.length = num(r, {"length", "Axial extent of the canal from `start` to its tip, unit frame; at least the bend's own extent."}, c.length, 0.01, 100.0);
  c.axisOffset = num(r, {"axis_offset", "Distance of the canal's straight part from the shell axis, unit frame."}, c.axisOffset, -10.0, 10.0);
  c.radiusStart = num(r, {"radius_start", "Radius (0.5-iso) of the canal at `start`, unit frame; it runs linearly to `radius_end`."}, c.radiusStart, 1e-3, 10.0);
  c.radiusEnd = num(r, {"radius_end", "Radius (0.5-iso) of the canal at its tip, unit frame."}, c.radiusEnd, 1e-3, 10.0);
  c.turnDeg = num(r, {"turn", "Direction of the canal at `start`, in degrees from the axis direction (inwards); it bends until parallel to the axis."}, c.turnDeg, 1.0, 90.0);
  c.sweepDeg = r.number({"sweep", "The canal is swept over the last DEG degrees before θ_end (default: 1.333 × whorl_angle, 464 for the Murex preset)."}, c.sweepDeg, 1.0, 40 * 3600.0);
  r.finish();
  if (!p.canal) return;
  if (!(c.start.x > c.tipX(p.spiral))) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "the canal's start x (%.3g) must lie farther from the shell axis than its tip (x = %.3g here)",
                  static_cast<double>(c.start.x), c.tipX(p.spiral));
    sec->error(diags, buf);
  } else if (c.arcHeight(p.spiral) > c.length) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "the canal's 'length' (%.3g) is shorter than its bend, which turns %.3g degrees over %.3g along the axis",
                  static_cast<double>(c.length), static_cast<double>(c.turnDeg), c.arcHeight(p.spiral));
    sec->error(diags, buf);
  }
}

void readVarices(MapReader& top, ShellParams& p, DiagnosticList& diags) {
  auto sec = partSection(top, {"varices", "Varices (Eq. 11-13, Fig. 7): ridges of spines every `spacing` degrees; `true`, `false` or a map of their keys (default: off; on in the `murex_cabritii` preset)."}, p.varices.enabled, diags);
  if (!sec) return;
  auto& v = p.varices;
  MapReader r(*sec, diags, "varices");
  v.enabled = r.boolean({"enabled", "Grow the varices (false: none)."}, true);
  v.spacingDeg = r.number({"spacing", "Angle between successive varices, in degrees; the first sits at this angle."}, v.spacingDeg, 1.0, 3600.0);
  if (auto spines = r.get({"spines", "The spines of each varix: `murex_table1` (Table 1 of the Murex paper) or one row per whorl of [angle, size] pairs."})) {
    if (spines->isScalar() && spines->scalar() == "murex_table1") {
      v.spinesByWhorl = organisms::murexTable1();
    } else if (!spines->isSequence()) {
      spines->error(diags, "'spines' must be murex_table1 or a sequence of rows (one per whorl) of [angle, size]");
    } else {
      v.spinesByWhorl.clear();
      for (const YNode& row : spines->items()) {
        std::vector<VarixSpine> out;
        if (!row.isSequence()) {
          row.error(diags, "a spine row must be a sequence of [angle, size] pairs");
        } else {
          for (const YNode& pair : row.items()) {
            auto xs = floatList(pair, diags, "spine", -180.0, 180.0);
            if (xs.size() != 2) {
              pair.error(diags, "a spine must be [angle, size]");
              continue;
            }
            if (!(xs[1] > 0.0f)) {
              pair.error(diags, "spine size must be > 0");
              continue;
            }
            out.push_back({xs[0], xs[1]});
          }
        }
        v.spinesByWhorl.push_back(std::move(out));
      }
    }
  }
  v.spineLength = num(r, {"spine_length", "Unit-frame length of a spine of size 1, from the shell edge."}, v.spineLength, 0.0, 20.0);
  v.baseRadius = num(r, {"base_radius", "Spine cone radius at the base (unit frame)."}, v.baseRadius, 1e-3, 5.0);
  v.tipRadius = num(r, {"tip_radius", "Spine tip radius (unit frame)."}, v.tipRadius, 1e-3, 5.0);
  v.shortTipRadius = num(r, {"short_tip_radius", "Tip radius of short spines (the thicker tips of Fig. 7)."}, v.shortTipRadius, 1e-3, 5.0);
  v.shortSize = num(r, {"short_size", "Spines with a size below this get `short_tip_radius`."}, v.shortSize, 0.0, 100.0);
  v.bendDeg = num(r, {"bend", "Spine curvature towards the apex side, in degrees (endpoint-preserving bend)."}, v.bendDeg, 0.0, 170.0);
  v.edge = num(r, {"edge", "Where spine bases sit across the generating surface (unit frame, 1 = the shell edge)."}, v.edge, 0.0, 3.0);
  v.widenAcross = r.boolean({"widen_across", "Scale each spine by σ_max across the varix (Eq. 12)."}, v.widenAcross);
  v.tori = r.boolean({"tori", "Add the two tori along each varix."}, v.tori);
  v.torusRadius = num(r, {"torus_radius", "Tube radius of the tori (unit frame)."}, v.torusRadius, 1e-3, 2.0);
  v.torusOuter = num(r, {"torus_outer", "Major radius of the outer torus (the inner one sits at 1)."}, v.torusOuter, 0.0, 5.0);
  v.lipVarix = r.boolean({"lip", "A varix at the growing edge θ_end as the shell grows."}, v.lipVarix);
  r.finish();
}

void readBumps(MapReader& top, ShellParams& p, DiagnosticList& diags) {
  auto sec = partSection(top, {"bumps", "Bumps between the varices (Fig. 8), super-elliptically blended; `true`, `false` or a map of their keys (default: off; on in the `murex_cabritii` preset)."}, p.bumps.enabled, diags);
  if (!sec) return;
  auto& b = p.bumps;
  MapReader r(*sec, diags, "bumps");
  b.enabled = r.boolean({"enabled", "Grow the bumps (false: none)."}, true);
  b.setsPerSection = static_cast<int>(r.integer({"sets", "Rows of bumps between two varices."}, b.setsPerSection, 0, 100));
  b.size = num(r, {"size", "Mean bump radius s (unit frame)."}, b.size, 1e-3, 5.0);
  b.sdFraction = num(r, {"sd", "Standard deviation of the bump sizes, as a fraction of `size`."}, b.sdFraction, 0.0, 1.0);
  b.elongation = num(r, {"elongation", "Added to a bump's scale along the spiral: bumps are capsules this much longer."}, b.elongation, 0.0, 10.0);
  b.blendN = num(r, {"blend_n", "Super-elliptic blend exponent of the bumps with the shell (1 = plain sum; 400 keeps them distinct)."}, b.blendN, 1.0, 1000.0);
  b.random = r.boolean({"random", "Draw bump sizes from the normal distribution (false: all equal)."}, b.random);
  b.edge = num(r, {"edge", "Distance of the bump centres from the generating centre (unit frame)."}, b.edge, 0.0, 3.0);
  r.finish();
}

void readAxial(MapReader& top, ShellParams& p, DiagnosticList& diags) {
  auto sec = partSection(top, {"axial_spines", "Axial spines along the siphonal canal (Fig. 9, Table 2); `true`, `false` or a map of their keys (default: off; on in the `murex_cabritii` preset)."}, p.axialSpines.enabled, diags);
  if (!sec) return;
  auto& a = p.axialSpines;
  MapReader r(*sec, diags, "axial_spines");
  a.enabled = r.boolean({"enabled", "Grow the axial (canal) spines (false: none)."}, true);
  if (auto rows = r.get({"rows", "Spine sizes along the canal: `murex_table2` (Table 2 of the Murex paper) or lists of relative sizes."})) {
    if (rows->isScalar() && rows->scalar() == "murex_table2") {
      a.rows = organisms::murexTable2();
    } else if (!rows->isSequence()) {
      rows->error(diags, "'rows' must be murex_table2 or a sequence of rows of relative sizes");
    } else {
      a.rows.clear();
      for (const YNode& row : rows->items()) a.rows.push_back(floatList(row, diags, "rows", 1e-3, 20.0));
    }
  }
  a.length = num(r, {"length", "Unit-frame length of an axial spine of size 1."}, a.length, 0.0, 20.0);
  a.baseRadius = num(r, {"base_radius", "Axial spine radius at the base (unit frame)."}, a.baseRadius, 1e-3, 5.0);
  a.tipRadius = num(r, {"tip_radius", "Axial spine tip radius (unit frame)."}, a.tipRadius, 1e-3, 5.0);
  a.firstT = num(r, {"first", "Position of the first spine along the canal (0 = the canal's start)."}, a.firstT, 0.0, 1.0);
  a.lastT = num(r, {"last", "Position of the last spine along the canal."}, a.lastT, 0.0, 1.0);
  a.downTilt = num(r, {"tilt", "Downward tilt: a spine points along normalize(1, tilt, 0) in the unit frame."}, a.downTilt, -10.0, 10.0);
  a.randomBends = r.boolean({"random_bends", "Bend each spine a random number of times by random angles (seeded by `seed`)."}, a.randomBends);
  a.bendMinDeg = num(r, {"bend_min", "Smallest random bend, in degrees."}, a.bendMinDeg, 0.0, 45.0);
  a.bendMaxDeg = num(r, {"bend_max", "Largest random bend, in degrees."}, a.bendMaxDeg, 0.0, 45.0);
  a.bendsMin = static_cast<int>(r.integer({"bends_min", "Fewest random bends per spine."}, a.bendsMin, 0, 10));
  a.bendsMax = static_cast<int>(r.integer({"bends_max", "Most random bends per spine."}, a.bendsMax, 0, 10));
  if (a.bendsMax < a.bendsMin) sec->error(diags, "'bends_max' must be >= 'bends_min'");
  if (a.bendMaxDeg < a.bendMinDeg) sec->error(diags, "'bend_max' must be >= 'bend_min'");
  r.finish();
}

void readOpening(MapReader& top, ShellParams& p, DiagnosticList& diags) {
  auto sec = partSection(top, {"opening", "The opening (aperture) cut by CSG (Eq. 14-15, Fig. 10-11); `true`, `false` or a map of its keys (default: off; on in the `murex_cabritii` preset)."}, p.opening.enabled, diags);
  if (!sec) return;
  auto& o = p.opening;
  MapReader r(*sec, diags, "opening");
  o.enabled = r.boolean({"enabled", "Cut the opening (Eq. 14-15; false: none)."}, true);
  o.innerScale = num(r, {"inner_scale", "Size of the inside generating surface relative to the main one."}, o.innerScale, 0.05, 0.98);
  o.depthDeg = r.number({"depth", "How far back from θ_end the hollow reaches, in degrees."}, o.depthDeg, 0.0, 3600.0);
  o.extendDeg = r.number({"extend", "How far past θ_end the cutter reaches (opens the lip), in degrees."}, o.extendDeg, 0.0, 360.0);
  o.insideWall = r.boolean({"inside_wall", "Add the inside wall back (Eq. 15): a rounded lip ring."}, o.insideWall);
  o.subtractPrevious = r.boolean({"subtract_previous", "Subtract the previous whorl from the hollow (Eq. 14)."}, o.subtractPrevious);
  const std::string show = r.choice({"show", "Fig. 10's construction surfaces: `shell` (the shell with its opening), or instead of it `inside_surface` (the inside generating surface at the lip), `inside_whorl` (B_inside, that surface swept) or `cutter` (B_inside − B_previous, the solid cut out)."}, "shell", {"shell", "inside_surface", "inside_whorl", "cutter"});
  using Show = organisms::OpeningOptions::Show;
  o.show = show == "inside_surface" ? Show::InsideSurface : show == "inside_whorl" ? Show::InsideWhorl : show == "cutter" ? Show::Cutter : Show::Shell;
  r.finish();
}

void readTextures(MapReader& top, organisms::ShellTextureOptions& t, DiagnosticList& diags) {
  if (auto sec = top.section({"textures", "Colours of the shell: whorl, cords, growth lines, varices, spine tips, axial spines, bumps, inside."})) {
    MapReader r(*sec, diags, "textures");
    t.whorlColor = r.color({"whorl", "Base colour of the whorls."}, t.whorlColor);
    t.cordColor = r.color({"cord_color", "Colour of the spiral cords."}, t.cordColor);
    t.cords = static_cast<int>(r.integer({"cords", "Spiral cords around a whorl (0 = none)."}, t.cords, 0, 200));
    t.cordStrength = num(r, {"cord_strength", "How strongly the cords mix `cord_color` into the whorl (0 = no cords)."}, t.cordStrength, 0.0, 1.0);
    t.growthLineDeg = num(r, {"growth_lines", "Spacing of the axial growth lines along the spiral, in degrees of θ (0 = none)."}, t.growthLineDeg, 0.0, 360.0);
    t.growthLineStrength = num(r, {"growth_line_strength", "How much a growth line darkens the whorl (0 = not at all)."}, t.growthLineStrength, 0.0, 1.0);
    t.varixColor = r.color({"varix", "Colour of the varices."}, t.varixColor);
    t.spineTipColor = r.color({"spine_tip", "Colour of the spine tips."}, t.spineTipColor);
    t.axialColor = r.color({"axial", "Colour of the axial (canal) spines."}, t.axialColor);
    t.bumpColor = r.color({"bump", "Colour of the bumps."}, t.bumpColor);
    t.insideColor = r.color({"inside", "Colour inside the opening."}, t.insideColor);
    t.insideRadial = num(r, {"inside_radial", "With an opening: whorl points nearer the generating centre than this fraction of D(θ), within the opening's `depth` of the lip, take `inside` (0 = off)."}, t.insideRadial, 0.0, 1.0);
    r.finish();
  }
  bool on = t.pigment;
  auto sec = partSection(top, {"pigment", "Pigment pattern from Meinhardt's activator-inhibitor reaction-diffusion along the growing edge; `true`, `false` or a map of its keys (default: off)."}, on, diags);
  t.pigment = on;
  if (!sec) return;
  auto& o = t.pigmentOptions;
  MapReader r(*sec, diags, "pigment");
  o.cells = static_cast<int>(r.integer({"cells", "Cells around the growing edge (periodic): the pattern's resolution across the whorl."}, o.cells, 3, 4096));
  o.rows = static_cast<int>(r.integer({"rows", "Rows of the pattern (moments of growth), spanning the fully grown shell's θ range."}, o.rows, 1, 8192));
  o.stepsPerRow = static_cast<int>(r.integer({"steps_per_row", "Integration steps between two output rows."}, o.stepsPerRow, 1, 1000));
  o.warmupRows = static_cast<int>(r.integer({"warmup", "Rows simulated before the output starts (the larval shell)."}, o.warmupRows, 0, 10000));
  o.dt = r.number({"dt", "Time step of the explicit integration; dt × max(da, db) must stay below 0.5."}, o.dt, 1e-4, 10.0);
  o.diffusionA = r.number({"da", "Dₐ, diffusion of the activator (cells²/time)."}, o.diffusionA, 0.0, 10.0);
  o.diffusionB = r.number({"db", "D_b, diffusion of the inhibitor (cells²/time)."}, o.diffusionB, 0.0, 10.0);
  o.decayA = r.number({"ra", "rₐ, decay rate of the activator."}, o.decayA, 1e-6, 10.0);
  o.decayB = r.number({"rb", "r_b, decay rate of the inhibitor (below `ra`: travelling waves, oblique lines)."}, o.decayB, 1e-6, 10.0);
  o.baseA = r.number({"ba", "bₐ, basic production of the activator."}, o.baseA, 0.0, 10.0);
  o.baseB = r.number({"bb", "b_b, basic production of the inhibitor."}, o.baseB, 0.0, 10.0);
  o.saturation = r.number({"saturation", "κ, saturation of the activator production (Meinhardt Eq. 2.5; 0 = none)."}, o.saturation, 0.0, 100.0);
  o.sourceNoise = r.number({"noise", "Relative fluctuation of the source density s from cell to cell, uniform in ± this."}, o.sourceNoise, 0.0, 1.0);
  o.seed = static_cast<uint64_t>(r.integer({"seed", "Seed of the source density's fluctuation."}, static_cast<int64_t>(o.seed), 0));
  t.pigmentColor = r.color({"color", "Colour where the activator is high."}, t.pigmentColor);
  t.pigmentStrength = num(r, {"strength", "How strongly the pattern mixes `color` into the whorl (0 = not at all)."}, t.pigmentStrength, 0.0, 1.0);
  if (o.dt * std::max(o.diffusionA, o.diffusionB) >= 0.5)
    sec->error(diags, "pigment: dt * max(da, db) must stay below 0.5 (explicit integration is unstable)");
  r.finish();
}

}  // namespace

std::optional<ShellSpec> readShellSection(const YNode& section, DiagnosticList& diags) {
  if (!section.isMap()) {
    section.error(diags, "'shell' must be a map");
    return std::nullopt;
  }
  ShellSpec s;
  s.loc = section.loc();
  MapReader top(section, diags, "shell");
  const std::string preset = top.choice({"preset", "Start from a preset: `murex_cabritii` is the paper's Murex (every key below still overrides it); `none` starts from the defaults."}, "none", {"none", "murex_cabritii"});
  ShellParams& p = s.params;
  if (preset == "murex_cabritii") {
    p = organisms::murexCabritii();
    s.textures.pigment = false;
  }
  p.spiral.lambda = top.number({"lambda", "λ, the ratio of the spiral's radii one turn apart (above 1; Eq. 1 of the Murex paper)."}, p.spiral.lambda, 1.0001, 100.0);
  p.spiral.betaDeg = top.number({"beta", "β, the spiral's angle in degrees: 90 is planispiral (every whorl in one plane), smaller is taller."}, p.spiral.betaDeg, 0.1, 90.0);
  p.spiral.r0 = top.number({"r0", "R₀, the spiral's radius at angle 0, in world units."}, p.spiral.r0, 1e-6, 1e6);
  p.whorls = static_cast<int>(top.integer({"whorls", "Whorls of the grown shell."}, p.whorls, 1, 40));
  p.whorlDeg = top.number({"whorl_angle", "Degrees per whorl."}, p.whorlDeg, 1.0, 3600.0);
  p.sectionDeg = top.number({"section_angle", "Degrees per section (the controlled-blending unit of Eq. 10)."}, p.sectionDeg, 1.0, 3600.0);
  p.surfacesPerSection = static_cast<int>(top.integer({"surfaces_per_section", "Generating surfaces per section (Δθ = section_angle / this)."}, p.surfacesPerSection, 1, 1000));
  p.startDeg = top.number({"start", "Angle θ of the first generating surface, in degrees."}, p.startDeg, -36000.0, 36000.0);
  if (top.has("age")) p.ageDeg = top.number({"age", "θ_end, the angle of the last generating surface, in degrees (default: whorls × whorl_angle)."}, p.whorls * p.whorlDeg, 0.0, 40 * 3600.0);
  for (const YNode& st : top.sequence({"stages", "Ages θ_end of a growth sequence in degrees, for the gallery's strip and `sprig animate` (default: evenly spaced ages up to `age`)."}))
    if (auto v = st.asNumber(diags, "'stages' entry", 0.0, 40 * 3600.0)) s.stages.push_back(*v);
  p.seed = static_cast<uint64_t>(top.integer({"seed", "Seed of the bumps and of the axial spines' bends."}, static_cast<int64_t>(p.seed), 0));
  p.controlledBlending = top.boolean({"controlled_blending", "Blend each section only with its neighbours (Eq. 10; false: every section with every other, whorls fuse)."}, p.controlledBlending);
  p.calibrateSize = top.boolean({"calibrate", "Calibrate the size and shift of the summed row of generating surfaces."}, p.calibrateSize);
  p.apexUp = top.boolean({"apex_up", "Turn the shell apex up in world space."}, p.apexUp);
  readGenerating(top, p, diags);
  readCanal(top, p, diags);
  readVarices(top, p, diags);
  readBumps(top, p, diags);
  readAxial(top, p, diags);
  readOpening(top, p, diags);
  readTextures(top, s.textures, diags);
  top.finish();
  const double end = p.endDeg();
  if (end < p.startDeg) section.error(diags, "shell 'age' must not be below 'start'");
  return s;
}

std::vector<double> shellGrowthStages(const ShellSpec& species, int count) {
  if (!species.stages.empty()) return species.stages;
  const auto& p = species.params;
  const double end = p.endDeg();
  std::vector<double> out;
  for (int i = 1; i <= count; ++i) {
    const double age = p.startDeg + (end - p.startDeg) * i / count;
    if (age >= p.startDeg + p.stepDeg()) out.push_back(age);
  }
  return out;
}

ShellBuild buildShell(const ShellSpec& species, std::optional<double> ageDeg, const glm::dmat4& pose) {
  organisms::ShellParams p = species.params;
  if (ageDeg) p.ageDeg = *ageDeg;
  p.pose = pose;
  ShellBuild b;
  b.model = organisms::buildShell(p, species.loc);
  b.blob = std::make_shared<const blobtree::CompiledBlob>(blobtree::compile(b.model.tree, b.model.root));
  b.painter = std::make_shared<const organisms::ShellPainter>(p, b.model, species.textures);
  b.rested = pose != glm::dmat4(1.0);
  return b;
}

render::Geometry shellGeometry(const ShellBuild& shell, std::shared_ptr<const blobtree::PolygonizeResult> mesh) {
  using organisms::ShellPart;
  render::Material porcelain;
  porcelain.baseColor = shell.painter->options().whorlColor;
  porcelain.roughness = 0.35f;
  porcelain.specular = 0.05f;
  // The table's ids are the parts' texture ids in the shell's BlobTree (organisms/shell_paint.h).
  render::TextureTable textures;
  for (ShellPart part : {ShellPart::Whorl, ShellPart::VarixSpine, ShellPart::AxialSpine, ShellPart::Bump, ShellPart::Inside}) {
    std::shared_ptr<const organisms::ShellPainter> painter = shell.painter;
    textures.push_back([painter, part](Vec2 uv, const Vec3& p) { return painter->partColor(part, p, uv); });
  }
  render::Geometry out;
  if (mesh) {
    out.parts.push_back(render::PolygonizedPart{std::move(mesh), porcelain, std::move(textures)});
    return out;
  }
  render::ImplicitOptions opt;
  // The renderer's automatic size follows the smallest feature (the apex's tiny spine
  // tips), which makes hundreds of thousands of cells; a fixed fraction of the model's
  // diagonal renders the Murex faster (docs/PERFORMANCE.md, Shells).
  opt.cellSize = organisms::shellCellSize(*shell.blob);
  opt.trace.relativeTolerance = organisms::kShellTraceTolerance;
  opt.tightBase = shell.rested;
  out.parts.push_back(render::ImplicitPart{shell.blob, porcelain, opt, std::move(textures)});
  return out;
}

glm::dmat4 shellRestingPose(const ShellBuild& shell, bool apertureUp, Box3* restedBox) {
  const blobtree::CompiledBlob& blob = *shell.blob;
  blobtree::PolygonizeOptions po;
  po.cellSize = glm::length(blob.bounds().size()) / kRestPoseCells;
  const Mesh surface = blobtree::polygonize(blob, po);
  if (surface.positions.empty()) return glm::dmat4(1.0);
  // The aperture faces along the spiral's tangent at the lip (the direction of growth).
  const organisms::ShellModel& m = shell.model;
  const DVec3 lip = DVec3(m.worldFromShell * glm::dvec4(m.spiral.point(m.endDeg), 1.0));
  const DVec3 ahead = DVec3(m.worldFromShell * glm::dvec4(m.spiral.point(m.endDeg + 1.0), 1.0));
  const DVec3 facing = glm::normalize(ahead - lip);
  const DVec3 up = organisms::restingUp(surface.positions, organisms::volumeCentroid(surface), apertureUp ? facing : -facing);
  // The axis from the apex towards the canal lies along the image's horizontal (+x).
  const DVec3 apexToCanal = DVec3(m.worldFromShell * glm::dvec4(0.0, 1.0, 0.0, 0.0));
  const glm::dmat3 turn = organisms::uprightRotation(up, apexToCanal);
  // Turn about the centre of the shell's box so the rested shell stays near the origin.
  const DVec3 c(blob.bounds().center());
  const glm::dmat4 pose = glm::translate(glm::dmat4(1.0), c) * glm::dmat4(turn) * glm::translate(glm::dmat4(1.0), -c);
  if (restedBox) {
    // The surface's own box, a cell wider each way: the turned support box of the blob
    // (each primitive's support is over twice its surface's radius) would frame a shell
    // lying aslant several times too loosely.
    *restedBox = Box3{};
    for (const Vec3& p : surface.positions) restedBox->extend(Vec3(pose * glm::dvec4(DVec3(p), 1.0)));
    *restedBox = Box3{restedBox->lo - Vec3(po.cellSize), restedBox->hi + Vec3(po.cellSize)};
  }
  return pose;
}

namespace {

/// Mesh cell of a shell when none is asked for: 1/340 of its diagonal.
float shellMeshCell(const blobtree::CompiledBlob& blob) { return glm::length(blob.bounds().size()) / 340.0f; }

/// The whorl's helico-spiral coordinates, one per vertex of mesh (world positions).
std::vector<organisms::HelicoCoords> whorlCoords(const Mesh& mesh, const organisms::ShellPainter& painter) {
  std::vector<organisms::HelicoCoords> coords(mesh.positions.size());
  parallelFor(0, coords.size(), [&](size_t v) { coords[v] = painter.helicoCoordsOfWorld(mesh.positions[v]); }, 256);
  return coords;
}

/// The whorl's image over (around, θ) cannot show what depends on a point's distance from
/// the generating centre: the aperture's inside (ShellPainter::insideWeight), which shares
/// (around, θ) with the outer wall in front of it. Moves every whorl triangle with a corner
/// there to the `inside` part (made when the shell has none), whose atlas is baked from the
/// renderer's colours at its surface points. Returns the remaining whorl's coordinates.
std::vector<organisms::HelicoCoords> moveApertureToInside(std::vector<ExportPart>& parts, ExportPart& whorl,
                                                          const organisms::ShellPainter& painter, float roughness) {
  std::vector<organisms::HelicoCoords> coords = whorlCoords(whorl.mesh, painter);
  Mesh& mesh = whorl.mesh;
  mesh.materials.assign(mesh.triangleCount(), 0);
  bool any = false;
  for (size_t t = 0; t < mesh.triangleCount(); ++t)
    for (int k = 0; k < 3; ++k)
      if (painter.insideWeight(coords[mesh.triangles[t][k]]) > 0.0) mesh.materials[t] = 1, any = true;
  if (!any) {
    mesh.materials.clear();
    return coords;
  }
  std::vector<char> kept(mesh.vertexCount(), 0);
  for (size_t t = 0; t < mesh.triangleCount(); ++t)
    if (mesh.materials[t] == 0)
      for (int k = 0; k < 3; ++k) kept[mesh.triangles[t][k]] = 1;
  std::vector<std::pair<uint32_t, Mesh>> groups = splitByMaterial(mesh);
  Mesh aperture = std::move(groups.back().second);
  mesh = groups.size() == 2 ? std::move(groups.front().second) : Mesh{};
  std::vector<organisms::HelicoCoords> rest;
  for (size_t v = 0; v < kept.size(); ++v)
    if (kept[v]) rest.push_back(coords[v]);
  auto inside = std::find_if(parts.begin(), parts.end(), [](const ExportPart& p) { return p.name == "inside"; });
  if (inside != parts.end()) {
    inside->mesh.append(aperture);
  } else {
    const Vec3 color = painter.options().insideColor;
    parts.push_back(ExportPart{"inside", std::move(aperture), PartMaterial{"inside", color, roughness, false, nullptr}});
  }
  return rest;
}

/// Maps the main whorl's texture onto the whorl part as an image over the helico-spiral
/// coordinates of each vertex (organisms/shell_paint.h): s = angle around the generating
/// curve / 360° (repeating), t = θ over the part's range, the first and last θ on the
/// centres of the first and last rows. A shell with varix bands has two such images
/// stacked, the outer wall's (bottom) and the canal's (top, without the bands): a vertex
/// farther than kShellCanalRadial from every generating centre takes the top one. A
/// triangle spanning more than 90° of θ or around (between two whorls, at the apex, or
/// between wall and canal) takes one corner's coordinates. The texels are the painter's
/// whorl colour at their coordinates (whorlSurfaceColor); coords are the mesh's vertices'.
void textureWhorl(ExportPart& part, const organisms::ShellPainter& painter, const std::vector<organisms::HelicoCoords>& coords) {
  Mesh& mesh = part.mesh;
  if (mesh.triangleCount() == 0) return;
  double lo = INFINITY, hi = -INFINITY;
  bool canal = false;
  for (const auto& h : coords) {
    lo = std::min(lo, h.thetaDeg), hi = std::max(hi, h.thetaDeg);
    canal = canal || h.radial >= organisms::kShellCanalRadial;
  }
  canal = canal && painter.hasVarixBands();
  const double range = std::max(hi - lo, 1e-6);
  const int rows = kExportTextureLong, height = rows * (canal ? 2 : 1);
  mesh.uvs.resize(mesh.positions.size());
  for (size_t v = 0; v < coords.size(); ++v) {
    const double s = coords[v].aroundDeg / 360.0;
    const int half = canal && coords[v].radial >= organisms::kShellCanalRadial ? 1 : 0;
    const double row = half * rows + 0.5 + (coords[v].thetaDeg - lo) / range * (rows - 1);
    mesh.uvs[v] = Vec2(float(s < 0 ? s + 1.0 : s), float(row / height));
  }
  UvSeamOptions seams;
  seams.repeatU = true;
  seams.maxSpan = Vec2(0.25f, float(90.0 / range * rows / height));
  part.material.texture = bakeTexture(kExportTextureAround, height, [&](double s, double t) {
    const long j = std::lround(t * height - 0.5);  // the texel's row from the bottom
    const double around = s > 0.5 ? 360.0 * s - 360.0 : 360.0 * s;  // helicoCoords' range (−180°, 180°]
    return painter.whorlSurfaceColor(lo + double(j % rows) / (rows - 1) * range, around, j >= rows);
  }, seams);
}

/// A shell grown to any age.
class ShellModel final : public KindModel {
 public:
  ShellModel(const ShellSpec& spec, RestPose rest) : spec_(spec), rest_(rest) {}

  bool hasSurface() const override { return true; }

  Stage finalStage() const override {
    Stage s;
    s.age = spec_.params.endDeg();
    return s;
  }

  Stage stageFromIndex(int k) const override {
    Stage s = finalStage();
    s.age = std::min(s.age, std::max(1, k) * spec_.params.whorlDeg);
    return s;
  }

  Stage stageAtAge(double ageDeg) const override {
    Stage s = finalStage();
    s.age = std::min(ageDeg, s.age);
    return s;
  }

  std::vector<Stage> stripStages(int count) const override {
    std::vector<Stage> out;
    for (double age : shellGrowthStages(spec_, count)) {
      Stage s;
      s.age = age;
      out.push_back(s);
    }
    // A shell that starts at its final age (a generating surface alone, Fig. 6) has no
    // growth to show: its strip is the final stage.
    if (out.empty()) out.push_back(finalStage());
    return out;
  }

  std::vector<Stage> animationFrames(int framesPerStage, int, int) const override {
    // From the youngest strip stage to the final age, framesPerStage frames per whorl.
    const double end = finalStage().age;
    const double whorl = spec_.params.whorlDeg;
    const double begin = std::min(end, stripStages(5).front().age);
    const int n = std::max(1, static_cast<int>(std::ceil((end - begin) / whorl * std::max(1, framesPerStage))));
    std::vector<Stage> out;
    for (int i = 0; i <= n; ++i) {
      Stage s;
      s.age = begin + (end - begin) * i / n;
      out.push_back(s);
    }
    return out;
  }

  std::string stageName(const Stage& stage) const override {
    char buf[64];
    std::snprintf(buf, sizeof buf, "age %.0f deg", stage.age);
    return buf;
  }

  int stageNumber(const Stage& stage) const override { return static_cast<int>(std::lround(stage.age)); }

  Box3 frameBox() override {
    pose();
    if (restedBox_ && !restedBox_->empty()) return *restedBox_;  // render.rest: the rested surface's box
    Box3 box = finalShell().blob->bounds();
    return box.empty() ? Box3{Vec3(-0.5f), Vec3(0.5f)} : box;
  }

  BuiltStage build(const Stage& stage, GeometryMode mode, const SpeciesRender& look) override {
    if (mode == GeometryMode::Skeleton) throw UsageError("shells have no skeleton: use --mode exact or mesh");
    BuiltStage out;
    const auto t0 = std::chrono::steady_clock::now();
    const double age = stage.age < 0 ? finalStage().age : stage.age;
    std::optional<ShellBuild> built;
    const ShellBuild* shell = nullptr;
    if (age == finalStage().age) {
      shell = &finalShell();
    } else {
      built = buildShell(spec_, age, pose());
      shell = &*built;
    }
    out.figures.primitives = shell->blob->primitiveCount();
    std::shared_ptr<const blobtree::PolygonizeResult> mesh;
    if (mode == GeometryMode::Mesh) {
      blobtree::PolygonizeOptions po = polygonizeOptions(look);
      po.cellSize = shellMeshCell(*shell->blob);
      mesh = std::make_shared<blobtree::PolygonizeResult>(polygonizeForLook(*shell->blob, po, look));
      out.figures.triangles = mesh->mesh.triangleCount();
    }
    out.figures.buildSeconds = secondsSince(t0);
    out.geometry = shellGeometry(*shell, std::move(mesh));
    return out;
  }

  Mesh buildMesh(const Stage& stage, float cellSize, bool progress, ModelFigures& fig) override {
    const ShellBuild shell = buildShell(spec_, stage.age < 0 ? std::nullopt : std::optional(stage.age));
    fig.primitives = shell.blob->primitiveCount();
    blobtree::PolygonizeOptions po;
    po.cellSize = cellSize > 0 ? cellSize : shellMeshCell(*shell.blob);
    po.progress = progress;
    return blobtree::polygonize(*shell.blob, po);
  }

  std::vector<ExportPart> exportParts(const Stage& stage, float cellSize, bool progress, const SpeciesRender& look,
                                      const MeshCleanOptions& clean, ModelFigures& fig) override {
    const ShellBuild shell = buildShell(spec_, stage.age < 0 ? std::nullopt : std::optional(stage.age));
    fig.primitives = shell.blob->primitiveCount();
    blobtree::PolygonizeOptions po = polygonizeOptions(look);
    po.cellSize = cellSize > 0 ? cellSize : shellMeshCell(*shell.blob);
    po.progress = progress;
    // Painted as the renderer paints it, cleaned as one surface, then split by the part
    // whose texture weighs most on each triangle.
    const render::Geometry geometry = shellGeometry(shell, nullptr);
    const auto& implicit = std::get<render::ImplicitPart>(geometry.parts.front());
    const organisms::ShellTextureOptions& colors = shell.painter->options();
    Mesh surface = paintPolygonized(blobtree::polygonizeDetailed(*shell.blob, po), implicit.textures, colors.whorlColor);
    fig.clean = cleanMesh(surface, clean);
    using organisms::ShellPart;
    std::vector<ExportPart> parts;
    for (auto& [id, mesh] : splitByMaterial(surface)) {
      const auto part = id == kNoPartTexture ? ShellPart::Whorl : ShellPart(id);
      std::pair<const char*, Vec3> named = {"whorl", colors.whorlColor};
      switch (part) {
        case ShellPart::Whorl: break;
        case ShellPart::VarixSpine: named = {"varices", colors.varixColor}; break;
        case ShellPart::AxialSpine: named = {"spines", colors.axialColor}; break;
        case ShellPart::Bump: named = {"bumps", colors.bumpColor}; break;
        case ShellPart::Inside: named = {"inside", colors.insideColor}; break;
      }
      auto same = std::find_if(parts.begin(), parts.end(), [&](const ExportPart& p) { return p.name == named.first; });
      if (same != parts.end()) {
        same->mesh.append(mesh);  // no texture and the whorl's texture are both the whorl
        continue;
      }
      parts.push_back(ExportPart{named.first, std::move(mesh), PartMaterial{named.first, named.second, implicit.material.roughness, false, nullptr}});
    }
    render::Material painted;  // as paintPolygonized painted the surface
    painted.baseColor = colors.whorlColor;
    // A whorl with growth lines is an atlas of the renderer's colours like the other parts:
    // the lines are sharp tents a third of their spacing wide (0.5° either side of every 3°
    // line on the Murex, 812 lines over the image's 2,048 rows), which no image over θ
    // holds. Without them (or above the atlas budget) the whorl is an image over its
    // helico-spiral coordinates, and the aperture's inside moves to the inside part.
    std::vector<organisms::HelicoCoords> whorlCoords;
    const bool growthLines = colors.growthLineDeg > 0.0f && colors.growthLineStrength > 0.0f;
    for (size_t i = 0; i < parts.size(); ++i)
      if (parts[i].name == "whorl") {
        if (!growthLines || atlasBlobPart(parts[i], shell.blob, implicit.textures, painted) == 0)
          whorlCoords = moveApertureToInside(parts, parts[i], *shell.painter, implicit.material.roughness);
        break;
      }
    for (ExportPart& p : parts) {
      if (p.name == "whorl") {
        if (!p.material.texture) textureWhorl(p, *shell.painter, whorlCoords);
      } else  // varices, spines, bumps, inside: an atlas of the renderer's colours
        atlasBlobPart(p, shell.blob, implicit.textures, painted);
    }
    return parts;
  }

  /// LOD0 of a shell within 250,000 triangles (docs/MESHES.md "Levels of detail").
  size_t lodBudget() const override { return 250000; }

  GalleryMotion galleryMotion(bool final) override {
    GalleryMotion m;
    m.framesPerStage = final ? 6 : 1;  // per whorl
    return m;
  }

 private:
  /// The final shell in the pictures' pose, built once: it frames the camera and is reused
  /// for the final stage.
  const ShellBuild& finalShell() {
    if (!final_) final_ = buildShell(spec_, std::nullopt, pose());
    return *final_;
  }

  /// The pictures' pose (render.rest): identity as built; else the final shell's resting
  /// pose (shellRestingPose), found once and kept for every stage, so a growth strip or
  /// animation turns every young shell as the grown one lies.
  const glm::dmat4& pose() {
    if (pose_) return *pose_;
    if (rest_ == RestPose::None) {
      pose_ = glm::dmat4(1.0);
    } else {
      restedBox_ = Box3{};
      pose_ = shellRestingPose(buildShell(spec_), rest_ == RestPose::ApertureUp, &*restedBox_);
    }
    return *pose_;
  }

  const ShellSpec& spec_;
  RestPose rest_ = RestPose::None;
  std::optional<glm::dmat4> pose_;
  std::optional<Box3> restedBox_;  ///< the rested final surface's box (render.rest), framing every stage
  std::optional<ShellBuild> final_;
};

}  // namespace

std::shared_ptr<const KindSpec> readShellSpec(MapReader& top, Species&, DiagnosticList& diags) {
  std::optional<YNode> section = top.section({"shell", "The helico-spiral shell: spiral, generating surface, varices, spines, bumps, opening, textures, pigment (docs/SHELLS.md)."});
  if (!section) {
    if (!top.has("shell")) top.node().error(diags, "missing required key 'shell' in species file");
    return nullptr;
  }
  std::optional<ShellSpec> spec = readShellSection(*section, diags);
  if (!spec) return nullptr;
  return std::make_shared<ShellSpec>(std::move(*spec));
}

std::string ShellSpec::checkSummary(const Species& species) const {
  buildShell(*this);  // builder errors (invalid parameters) show here too; cheap
  return " '" + species.name + "'";
}

std::unique_ptr<KindModel> ShellSpec::makeModel(const Species& species, const ModelOptions&) const {
  return std::make_unique<ShellModel>(*this, species.render.rest);
}

}  // namespace sprig
