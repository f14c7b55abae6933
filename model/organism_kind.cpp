#include "model/organism_kind.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

#include "core/mesh_clean.h"
#include "core/inr_volume.h"
#include "core/paths.h"
#include "core/polymesh.h"
#include "core/timer.h"
#include "model/mesh_parts.h"
#include "model/model.h"
#include "model/species_field.h"
#include "organisms/analysis.h"
#include "organisms/base_mesh.h"
#include "organisms/iso_surface.h"
#include "organisms/simplify.h"
#include "render/scene.h"
#include "organisms/detail.h"
#include "organisms/placement.h"
#include "textures/noise.h"

namespace sprig {

namespace {

using namespace organisms;

constexpr int kMaxLevels = 8;
/// Faces of the finest level an organism may have (the memory of one synthesis is about
/// 200 bytes per face): 16.8 million, 4^7 times a 1024-face control mesh.
constexpr size_t kMaxFinestFaces = size_t(1) << 24;

const std::vector<std::string> kBases = {"cube_sphere", "torus", "cylinder", "plane", "revolution", "mesh", "species"};
const std::vector<std::string> kProcedures = {"rock", "berry", "tentacle", "spur", "mushroom", "captured"};

/// What each base, detail procedure, alpha and shader is (`sprig schema`'s text for its key).
std::string_view kindHelp(std::string_view what, std::string_view kind) {
  static const std::map<std::pair<std::string_view, std::string_view>, std::string_view> kHelp = {
      {{"base", "cube_sphere"}, "A cube of quads pushed onto a sphere about the origin: closed."},
      {{"base", "torus"}, "A torus about the y axis: closed, every vertex regular."},
      {{"base", "cylinder"}, "A cylinder about the y axis, with polygon caps or open."},
      {{"base", "plane"}, "An open square of quads in the xz plane, normal +y."},
      {{"base", "revolution"}, "A surface of revolution about the y axis: radius `profile`(t) at y = t."},
      {{"base", "mesh"}, "A mesh or volume file as the control mesh; it must be manifold and consistently oriented."},
      {{"base", "species"}, "Another species' final surface, reduced to about `faces` triangles."},
      {{"detail", "rock"}, "Volumetric fractal (§4.2.1): noise along the normal, amplitude·gain^k at level first + k."},
      {{"detail", "berry"}, "Hybrid fractal (§4.2.2): domes at Poisson-disk seeds, each level's smaller domes clustered on the last."},
      {{"detail", "tentacle"}, "Tentacles (§4.2.3): each level moves the seed by a link, alternating sides; may turn and grow over time."},
      {{"detail", "spur"}, "A spike: the seed moves `length` along its normal at each level of its range (Fig. 8a, 10)."},
      {{"detail", "mushroom"}, "Hybrid morphogenic mushroom (§4.2.4): the footprint moves onto a cap-and-stalk profile; may grow over time."},
      {{"detail", "captured"}, "The details of `capture:`, replayed (no keys)."},
      {{"alpha", "plane"}, "Alpha from a plane: smoothstep of the signed distance over `width` (the paper's Fig. 12-13)."},
      {{"alpha", "noise"}, "A procedural alpha: smoothstep of noise of the reference surface."},
      {{"alpha", "painted"}, "Alpha painted on the base mesh's vertex colours (a `mesh` or `species` base with colours)."},
      {{"shader", "planet"}, "The planet shader (§6.3): displaces by the rocks' scalar channel and colours by height bands."}};
  auto it = kHelp.find({what, kind});
  return it == kHelp.end() ? std::string_view() : it->second;
}

/// Organisms whose base is another species may nest this deep (a file naming itself fails).
constexpr int kMaxSpeciesNesting = 4;
thread_local int gSpeciesNesting = 0;

/// `center`, `size` and `rotate` of a mesh read from a file: moved so its box is centred at
/// the origin, scaled so its largest side is size (0 = as it is), then turned by angle_deg
/// about axis (right-handed).
struct MeshPlacement {
  bool center = false;
  float size = 0;
  Vec3 axis{0, 1, 0};
  float angleDeg = 0;
  /// `flip`: reverse every face's winding, for a mesh wound inward (clockwise seen from
  /// outside: its normals, and so every detail along them, point into the shape).
  bool flip = false;
  void apply(std::vector<Vec3>& positions, const Box3& box) const {
    const Vec3 c = center ? 0.5f * (box.lo + box.hi) : Vec3(0.0f);
    const Vec3 ext = box.hi - box.lo;
    const float largest = std::max(ext.x, std::max(ext.y, ext.z));
    const float k = size > 0 && largest > 0 ? size / largest : 1.0f;
    // Rodrigues' rotation.
    const Vec3 u = glm::normalize(axis);
    const float th = float(radians(double(angleDeg))), cs = std::cos(th), sn = std::sin(th);
    for (Vec3& p : positions) {
      const Vec3 q = (p - c) * k;
      p = angleDeg == 0 ? q : q * cs + glm::cross(u, q) * sn + u * glm::dot(u, q) * (1 - cs);
    }
  }
};

/// Why base cannot be subdivided, or nullopt: no faces, a face that is not three or more
/// distinct vertices in range, a position that is not finite, or no area at all (every face
/// degenerate: the vertices coincide or lie on one line). Single degenerate faces among
/// others are allowed (the frames of organisms/multires.h fall back where a normal vanishes).
std::optional<std::string> baseMeshProblem(const ControlMesh& base) {
  if (base.faceSizes.empty()) return std::string("has no faces");
  const size_t n = base.positions.size();
  for (size_t v = 0; v < n; ++v)
    if (!std::isfinite(base.positions[v].x) || !std::isfinite(base.positions[v].y) || !std::isfinite(base.positions[v].z))
      return "has a vertex (" + std::to_string(v) + ", 0-based) that is not a finite point";
  double area = 0;
  size_t corner = 0;
  for (size_t f = 0; f < base.faceSizes.size(); ++f) {
    const uint32_t size = base.faceSizes[f];
    if (size < 3 || corner + size > base.faceVertices.size())
      return "has a face (" + std::to_string(f) + ", 0-based) of fewer than 3 vertices";
    const uint32_t* idx = base.faceVertices.data() + corner;
    corner += size;
    for (uint32_t k = 0; k < size; ++k) {
      if (idx[k] >= n)
        return "has a face (" + std::to_string(f) + ", 0-based) whose vertex index " + std::to_string(idx[k]) +
               " is out of range (" + std::to_string(n) + " vertices)";
      for (uint32_t j = 0; j < k; ++j)
        if (idx[j] == idx[k])
          return "has a face (" + std::to_string(f) + ", 0-based) that repeats vertex " + std::to_string(idx[k]);
    }
    DVec3 vectorArea(0.0);  // Newell: twice the polygon's vector area
    for (uint32_t k = 0; k < size; ++k) vectorArea += glm::cross(DVec3(base.positions[idx[k]]), DVec3(base.positions[idx[(k + 1) % size]]));
    area += glm::length(vectorArea);
  }
  if (!(area > 0)) return std::string("has zero area (every face is degenerate: its vertices coincide or lie on one line)");
  return std::nullopt;
}

ControlMesh controlOf(const PolyMesh& m) {
  ControlMesh c;
  c.positions = m.positions;
  c.faceSizes = m.faceSizes;
  c.faceVertices = m.faceVertices;
  return c;
}

/// Reads the organism section; every error goes to diags.
class OrganismReader {
 public:
  OrganismReader(DiagnosticList& diags, OrganismSpec& spec, const PathPolicy& policy)
      : diags_(diags), spec_(spec), policy_(policy) {}

  void read(const YNode& section) {
    MapReader m(section, diags_, "organism");
    spec_.levels = int(m.integer({"levels", "Catmull-Clark subdivision levels of the base mesh (the finest level may have at most 16,777,216 faces)."}, spec_.levels, 1, kMaxLevels));
    if (auto b = m.get({"base", "The control mesh: `cube_sphere`, `torus`, `cylinder`, `plane`, `revolution`, a `mesh` file or another `species`."})) {
      const size_t before = errorCount();
      readBase(*b);
      // A base read without an error may still be one the subdivision cannot take.
      if (errorCount() == before)
        if (std::optional<std::string> problem = baseMeshProblem(spec_.base)) b->error(diags_, "the base mesh" + baseName_ + " " + *problem);
    } else {
      m.node().error(diags_, "missing required key 'base' in organism (e.g. base: {cube_sphere: {radius: 1}})");
    }
    if (!spec_.base.faceSizes.empty()) {
      const size_t finest = finestFaceCount(spec_.base, spec_.levels);
      if (finest > kMaxFinestFaces)
        (m.get("levels") ? *m.get("levels") : m.node())
            .error(diags_, "'levels' " + std::to_string(spec_.levels) + " makes " + std::to_string(finest) +
                               " faces, more than the limit " + std::to_string(kMaxFinestFaces) +
                               "; use fewer levels or a coarser base");
    }
    if (auto c = m.section({"capture", "Detail captured from a surface (§2.2 analysis): the levels of another mesh or species, replayed as detail."})) {
      captureGiven_ = true;
      readCapture(*c);
    }
    for (const YNode& item : m.sequence({"detail", "Detail procedures (noise, berries, spurs, tentacles, mushrooms ...) added level by level, summed."})) readProcedure(item, spec_.detail);
    if (auto b = m.section({"blend", "A second detail blended over the first by an alpha (§6): `detail`, `alpha` (required) and `color`."})) readBlend(*b);
    for (const YNode& item : m.sequence({"modify", "Local modifications: per-level gains of the detail inside a sphere (§5.2)."})) readModification(item);
    if (auto s = m.section({"shader", "The post-blend shader of §6.3 (`planet:`): colours by height and slope."})) readShader(*s);
    spec_.frames = int(m.integer({"frames", "Animation stages over time 0 to 1 (default: 24 when something depends on time, else 1)."}, spec_.animated ? 24 : 1, 1, 10000));
    m.finish();
    const bool scalar = std::any_of(spec_.detail.begin(), spec_.detail.end(), [](auto& p) { return p->writesScalar(); }) ||
                        std::any_of(spec_.blendDetail.begin(), spec_.blendDetail.end(), [](auto& p) { return p->writesScalar(); });
    if (scalar && !spec_.planet)
      section.error(diags_, "a rock with 'output: scalar' needs a shader that uses the scalar (shader: {planet: {...}})");
  }

 private:
  // ---- base ----
  void readBase(const YNode& node) {
    std::optional<std::pair<YNode, YNode>> one = single(node, "base", kBases);
    if (!one) return;
    const auto& [key, value] = *one;
    const std::string kind = key.scalar();
    describeHelp(value, kindHelp("base", kind));
    MapReader m(value, diags_, kind);
    if (auto file = value.isMap() ? value.node()["file"] : YAML::Node(); file && file.IsScalar())
      baseName_ = " " + sprig::quoted(file.Scalar());
    try {
      if (kind == "cube_sphere") {
        spec_.base = cubeSphere(float(m.number({"radius", "Radius of the sphere."}, 1.0, 1e-6)),
                                int(m.integer({"quads", "Quads along each cube edge: 6·quads² quads in all."}, 2, 1, 64)));
      } else if (kind == "torus") {
        spec_.base = torus(float(m.number({"major", "Major radius: of the core circle about the y axis."}, 1.0, 1e-6)),
                           float(m.number({"minor", "Minor radius: of the tube."}, 0.35, 1e-6)),
                           int(m.integer({"around", "Quads along the major circle."}, 12, 3, 1024)),
                           int(m.integer({"across", "Quads around the tube."}, 8, 3, 1024)));
      } else if (kind == "cylinder") {
        spec_.base = cylinder(float(m.number({"radius", "Radius of the cylinder about the y axis."}, 0.5, 1e-6)),
                              float(m.number({"height", "Height: from y = 0 to y = height."}, 2.0, 1e-6)),
                              int(m.integer({"around", "Quads around the axis."}, 8, 3, 1024)),
                              int(m.integer({"rings", "Rings of quads along the height."}, 4, 1, 1024)),
                              m.boolean({"caps", "Close both ends with a polygon cap (false: an open tube)."}, true));
      } else if (kind == "plane") {
        spec_.base = plane(float(m.number({"size", "Edge length of the square in the xz plane, centred at the origin."}, 2.0, 1e-6)),
                           int(m.integer({"quads", "Quads along each edge."}, 8, 1, 1024)));
      } else if (kind == "revolution") {
        readRevolution(m);
      } else if (kind == "mesh") {
        m.markRequired("file");  // (capture's 'file' is one of two)
        readMeshBase(m);
      } else if (kind == "species") {
        m.markRequired("file");
        readSpeciesBase(m);
      }
    } catch (const std::invalid_argument& e) {
      value.error(diags_, e.what());
    }
    m.finish();
  }

  MeshPlacement meshPlacement(MapReader& m) {
    MeshPlacement p;
    p.center = m.boolean({"center", "Move the centre of the mesh's bounding box to the origin."}, false);
    p.size = float(m.number({"size", "Scale the mesh so its bounding box's largest extent is this, in world units (0 = as it is)."}, 0.0, 0.0, 1e6));
    if (auto r = m.section({"rotate", "Rotate the mesh: `axis` and `angle_deg` (after `center` and `size`)."})) {
      MapReader rm(*r, diags_, "rotate");
      p.axis = rm.vec3({"axis", "Axis of the rotation, through the origin (not zero)."}, p.axis);
      p.angleDeg = float(rm.number({"angle_deg", "Angle of the rotation, in degrees."}, 0.0, -360.0, 360.0));
      if (glm::length(p.axis) == 0) r->error(diags_, "the rotation 'axis' must not be zero");
      rm.finish();
    }
    p.flip = m.boolean({"flip", "Reverse every face's winding: for a mesh wound inward (its normals, and the details along them, would point into the shape)."}, false);
    return p;
  }

  /// A polygon mesh file, checked (every error at its face's file:line:col), placed.
  std::optional<PolyMesh> readMeshFile(MapReader& m, const MeshPlacement& place) {
    // Read below, once the file is known to be a volume.
    m.allow({{"iso", "Volume files (.inr) only, and required there: the value of the surface; the region above it is inside."}});
    auto file = m.path({"file", "A mesh file (.obj, .ply, .off) or a volume (.inr, with `iso`), relative to the species file."}, policy_);
    if (!file) {
      if (!m.has("file")) m.node().error(diags_, "missing required key 'file' in " + std::string("mesh"));
      return std::nullopt;
    }
    const bool isVolume = lowerExtension(*file) == ".inr";
    std::optional<double> iso;
    if (isVolume) {
      if (!m.has("iso")) m.get("file")->error(diags_, "a volume file (.inr) needs 'iso', the value of its surface");
      else iso = m.number("iso", 0.0, -1e30, 1e30);
    } else if (m.has("iso")) {
      m.get("iso")->error(diags_, "'iso' is for volume files (.inr); this file is a mesh");
    }
    try {
      PolyMesh mesh;
      if (isVolume) {
        if (!iso) return std::nullopt;
        mesh = organisms::isoSurface(readInrVolume(*file), *iso);
      } else {
        mesh = readPolyMesh(*file);
      }
      const size_t before = diags_.items().size();
      checkPolyMesh(mesh, diags_);
      if (diags_.items().size() != before) return std::nullopt;
      place.apply(mesh.positions, mesh.bounds());
      if (place.flip) reverseWinding(mesh);
      return mesh;
    } catch (const InputError& e) {
      diags_.append(e.diagnostics());
    } catch (const std::invalid_argument& e) {
      m.get(isVolume && m.has("iso") ? "iso" : "file")->error(diags_, e.what());
    }
    return std::nullopt;
  }

  void readMeshBase(MapReader& m) {
    const MeshPlacement place = meshPlacement(m);
    const int64_t faces = m.integer({"faces", "Simplify the mesh to about this many faces (0 = as it is)."}, 0, 0, 1'000'000);
    std::optional<PolyMesh> mesh = readMeshFile(m, place);
    if (!mesh) return;
    if (faces > 0 && mesh->faceCount() > size_t(faces)) mesh = organisms::simplifyToFaceCount(triangulate(*mesh), size_t(faces));
    spec_.base = controlOf(*mesh);
    baseColors_ = mesh->colors;
  }

  /// The surface (final stage's mesh) of the species file at key `key`, or nullopt after
  /// an error. Species bases nest at most kMaxSpeciesNesting deep.
  std::optional<Mesh> speciesSurface(MapReader& m, const char* key) {
    auto file = m.path({key, "Another species file (relative to this one): its final surface, as `sprig mesh` makes it."}, policy_);
    if (!file) {
      if (!m.has(key)) m.node().error(diags_, std::string("missing required key '") + key + "' (a species file)");
      return std::nullopt;
    }
    if (gSpeciesNesting >= kMaxSpeciesNesting) {
      m.get(key)->error(diags_, "species bases nest more than " + std::to_string(kMaxSpeciesNesting) +
                                    " deep (does a species name itself?)");
      return std::nullopt;
    }
    std::optional<Mesh> out;
    ++gSpeciesNesting;
    try {
      // Cleaned as `sprig mesh` cleans it (shell_top's 133 voids and 2 specks would otherwise
      // each become a separate piece of the organism); built once per distinct reference.
      const ReferencedSpecies base = referencedSpecies(*m.get(key), *file, policy_, std::nullopt);
      if (!base.hasSurface)
        throw UsageError("species " + file->string() + " has no surface (a tree needs a tree: section)");
      out = *base.surface;
    } catch (const InputError& e) {
      diags_.append(e.diagnostics());
    } catch (const std::exception& e) {
      m.get(key)->error(diags_, e.what());
    }
    --gSpeciesNesting;
    return out;
  }

  /// Another species' surface reduced to about `faces` faces.
  void readSpeciesBase(MapReader& m) {
    const int64_t faces = m.integer({"faces", "Reduce the species' surface to about this many triangles (meshoptimizer)."}, 1000, 4, 1'000'000);
    const MeshPlacement place = meshPlacement(m);
    std::optional<Mesh> surface = speciesSurface(m, "file");
    if (!surface) return;
    PolyMesh control = organisms::simplifyToFaceCount(*surface, size_t(faces));
    place.apply(control.positions, control.bounds());
    if (place.flip) reverseWinding(control);
    spec_.base = controlOf(control);
    baseColors_ = control.colors;
  }

  /// `capture: {file | species, max_distance, smoothing, center, size, rotate}`: analysis of a captured mesh
  /// onto the base (§2.2); its details become the `captured` procedure.
  void readCapture(const YNode& node) {
    MapReader m(node, diags_, "capture");
    const MeshPlacement place = meshPlacement(m);
    organisms::AnalysisOptions o;
    o.maxDistance = float(m.number({"max_distance", "How far along each vertex normal (both ways) the rays look for the captured surface, in world units."}, o.maxDistance, 1e-9));
    o.smoothing = int(m.integer({"smoothing", "Umbrella (Laplacian) smoothing steps before each decimation to the coarser level."}, o.smoothing, 0, 100));
    std::optional<Mesh> captured;
    if (m.has("species") == m.has("file")) {
      m.node().error(diags_, "capture takes one of 'file' (a mesh file) and 'species' (a species file)");
    } else if (m.has("species")) {
      captured = speciesSurface(m, "species");
      if (captured) {
        place.apply(captured->positions, captured->bounds());
        if (place.flip) {
          for (glm::uvec3& t : captured->triangles) std::swap(t.y, t.z);
          for (Vec3& n : captured->normals) n = -n;
        }
      }
    } else if (std::optional<PolyMesh> mesh = readMeshFile(m, place)) {
      captured = triangulate(*mesh);
    }
    m.finish();
    if (!captured || spec_.base.faceSizes.empty()) return;
    render::Scene scene;
    scene.addMesh(*captured, scene.addMaterial({}));
    scene.commit();
    const organisms::SurfaceProbe probe = [&scene](const Vec3& from, const Vec3& d, float maxDistance) -> std::optional<float> {
      const auto ahead = scene.intersect(from, d, 0.0f, maxDistance);
      const auto behind = scene.intersect(from, -d, 0.0f, maxDistance);
      if (ahead && (!behind || ahead->t <= behind->t)) return ahead->t;
      if (behind) return -behind->t;
      return std::nullopt;
    };
    const Subdivision sub(spec_.base, spec_.levels);
    organisms::AnalysisResult a = organisms::analyze(sub, spec_.base.positions, probe, o);
    spec_.captureMisses = a.misses;
    spec_.base.positions = std::move(a.control);
    spec_.captured = makeStoredDetail(std::move(a.details));
  }

  void readRevolution(MapReader& m) {
    m.markRequired("profile");
    auto profile = m.get({"profile", "The radius as an expression of t (the grammar's expression language: trigonometric functions take degrees)."});
    std::optional<lsystem::Expression> r;
    if (!profile) {
      m.node().error(diags_, "missing required key 'profile' in revolution (the radius as an expression of t)");
    } else if (auto text = profile->asString(diags_, "'profile'")) {
      SourceLoc at = profile->loc();
      const bool quoted = profile->node().Tag() == "!";
      at.col += quoted ? 1 : 0;
      try {
        r = lsystem::Expression::compile(*text, {"t"}, at, profile->file().sourceLine(at.line));
      } catch (const InputError& e) {
        diags_.append(e.diagnostics());
      }
    }
    double t0 = 0, t1 = 1;
    if (auto range = m.get({"t", "[t0, t1], the range of t, with t1 > t0; the surface lies at y = t (default [0, 1])."})) {
      auto items = range->items();
      std::optional<double> a, b;
      if (items.size() == 2) a = items[0].asNumber(diags_, "'t'"), b = items[1].asNumber(diags_, "'t'");
      if (!a || !b || !(*b > *a)) range->error(diags_, "'t' must be [t0, t1] with t1 > t0");
      else t0 = *a, t1 = *b;
    }
    const int around = int(m.integer({"around", "Quads around the y axis."}, 12, 3, 1024)),
              rings = int(m.integer({"rings", "Rings of quads along t."}, 12, 1, 4096));
    if (!r) return;
    spec_.base = revolution([&](double t) { return (*r)({t}); }, t0, t1, around, rings);
  }

  // ---- detail procedures ----
  void readProcedure(const YNode& item, DetailSet& into) {
    std::optional<std::pair<YNode, YNode>> one = single(item, "detail entry", kProcedures);
    if (!one) return;
    const auto& [key, value] = *one;
    const std::string kind = key.scalar();
    describeHelp(value, kindHelp("detail", kind));
    MapReader m(value, diags_, kind);
    std::shared_ptr<const DetailProcedure> p;
    if (kind == "rock") {
      RockOptions o;
      o.amplitude = float(m.number({"amplitude", "Normal displacement of the first level, in world units; level first + k gets amplitude·gain^k."}, o.amplitude, -1e6, 1e6));
      o.frequency = float(m.number({"frequency", "Noise frequency of the first level; level first + k uses frequency·lacunarity^k."}, o.frequency, 1e-6, 1e6));
      o.gain = float(m.number({"gain", "Amplitude ratio between successive levels."}, o.gain, 0.0, 4.0));
      o.lacunarity = float(m.number({"lacunarity", "Frequency ratio between successive levels."}, o.lacunarity, 1.0, 8.0));
      o.levels = levelRange(m, {1, spec_.levels}, "(default: [1, levels])");
      o.seed = uint64_t(m.integer({"seed", "Seed of the noise."}, 1, 0));
      o.scalar = m.choice({"output", "`displace` moves the surface; `scalar` writes the scalar channel the planet shader reads."}, "displace", {"displace", "scalar"}) == "scalar";
      p = makeRock(o);
    } else if (kind == "berry") {
      BerryOptions o;
      o.radius = float(m.number({"radius", "Radius R of the first level's domes, in world units."}, o.radius, 1e-6, 1e6));
      o.ratio = float(m.number({"ratio", "Each finer level's domes: radius and seed spacing times this."}, o.ratio, 0.05, 0.95));
      o.height = float(m.number({"height", "Multiplier of the dome height (1 = a spherical cap of radius R; negative: a pit)."}, o.height, -10.0, 10.0));
      o.cluster = float(m.number({"cluster", "The next level's seeds lie within cluster·R of their parent dome's seed."}, o.cluster, 0.05, 1.0));
      o.levels = levelRange(m, {1, std::min(3, spec_.levels)}, "(default: [1, min(3, levels)])");
      o.placement = placement(m, 1.8f * o.radius);
      p = makeBerry(o);
    } else if (kind == "tentacle") {
      TentacleOptions o;
      o.length = float(m.number({"length", "Length of one link, in world units: the displacement of the tentacle's level k is length·k."}, o.length, -1e6, 1e6));
      o.angleDeg = float(m.number({"angle_deg", "θ, the link direction's angle in the seed's tangent plane, in degrees."}, o.angleDeg, -3600.0, 3600.0));
      o.spinDeg = float(m.number({"spin_deg", "Degrees θ turns over time 0 to 1 (θ = angle_deg + spin_deg·time)."}, o.spinDeg, -36000.0, 36000.0));
      o.grow = float(m.number({"grow", "Time over which the tentacle grows to full length (0 = full from the start)."}, o.grow, 0.0, 1.0));
      const std::string alt = m.choice({"alternate", "What even levels flip: `tangent` (links swing to alternate sides), `all` (the whole direction: pits), `none`."}, "tangent", {"tangent", "all", "none"});
      o.alternate = alt == "all" ? Alternate::All : alt == "none" ? Alternate::None : Alternate::Tangent;
      o.levels = levelRange(m, {1, std::min(4, spec_.levels)}, "(default: [1, min(4, levels)])");
      o.placement = placement(m, 0.3f);
      spec_.animated |= o.spinDeg != 0 || o.grow > 0;
      p = makeTentacle(o);
    } else if (kind == "spur") {
      SpurOptions o;
      o.length = float(m.number({"length", "How far the seed moves along its normal at each level of the range, in world units."}, o.length, -1e6, 1e6));
      o.levels = levelRange(m, {1, 1}, "(default: [1, 1])");
      o.placement = placement(m, 0.3f);
      p = makeSpur(o);
    } else if (kind == "captured") {
      if (!spec_.captured && !captureGiven_)
        key.error(diags_, "'captured' detail needs a 'capture:' section in the organism");
      p = spec_.captured;
    } else if (kind == "mushroom") {
      MushroomOptions o;
      o.height = float(m.number({"height", "H, height of the cap's rim above the surface, in world units (> cap_under)."}, o.height, 1e-6, 1e6));
      o.capRadius = float(m.number({"cap_radius", "Radius of the cap's rim (stalk_radius < cap_radius < footprint)."}, o.capRadius, 1e-6, 1e6));
      o.capTop = float(m.number({"cap_top", "Height of the cap's dome above the rim."}, o.capTop, 0.0, 1e6));
      o.capUnder = float(m.number({"cap_under", "Depth of the cap's underside below the rim (< height)."}, o.capUnder, 0.0, 1e6));
      o.stalkRadius = float(m.number({"stalk_radius", "Radius of the stalk."}, o.stalkRadius, 1e-6, 1e6));
      o.footprint = float(m.number({"footprint", "Radius around the seed within which the surface moves onto the mushroom's profile."}, o.footprint, 1e-6, 1e6));
      o.grow = float(m.number({"grow", "Time over which the mushroom grows to full size (0 = full from the start)."}, o.grow, 0.0, 1.0));
      o.levels = levelRange(m, {1, std::min(4, spec_.levels)}, "(default: [1, min(4, levels)])");
      o.placement = placement(m, 2.5f * o.footprint);
      if (!(o.stalkRadius < o.capRadius && o.capRadius < o.footprint))
        m.node().error(diags_, "a mushroom needs stalk_radius < cap_radius < footprint");
      if (!(o.capUnder < o.height)) m.node().error(diags_, "a mushroom needs cap_under < height");
      spec_.animated |= o.grow > 0;
      p = makeMushroom(o);
    }
    m.finish();
    if (p) into.push_back(std::move(p));
  }

  /// `levels: [first, last]` within 0..spec levels; `defaultText` says def in words ("(default: [1, 1])").
  LevelRange levelRange(MapReader& m, LevelRange def, const char* defaultText) {
    const std::string help =
        std::string("[first, last]: the synthesis levels it acts on (1 = the first subdivision), within 0..`levels` ") +
        defaultText + ".";
    auto node = m.get({"levels", help});
    if (!node) return def;
    auto items = node->items();
    std::optional<int64_t> a, b;
    if (items.size() == 2) a = items[0].asInteger(diags_, "a level"), b = items[1].asInteger(diags_, "a level");
    if (!a || !b || *a > *b) {
      node->error(diags_, "'levels' must be [first, last] with first <= last");
      return def;
    }
    if (*a < 0 || *b > spec_.levels) {
      node->error(diags_, "level range [" + std::to_string(*a) + ", " + std::to_string(*b) +
                              "] lies outside the organism's levels 0.." + std::to_string(spec_.levels));
      return def;
    }
    return {int(*a), int(*b)};
  }

  /// `seeds: {spacing | control_vertices | points | faces, footprint, seed}`.
  Placement placement(MapReader& parent, float defaultSpacing) {
    Placement p;
    p.spacing = defaultSpacing;
    auto section = parent.section({"seeds", "Where the features sit (§5.1): one of `spacing`, `control_vertices`, `points`, `faces`, with `footprint` and `seed` (default: Poisson-disk seeds at the procedure's spacing)."});
    if (!section) return p;
    MapReader m(*section, diags_, "seeds");
    const int ways = int(m.has("spacing")) + int(m.has("control_vertices")) + int(m.has("points")) + int(m.has("faces"));
    if (ways > 1) m.node().error(diags_, "seeds take one of 'spacing', 'control_vertices', 'points' and 'faces'");
    p.seed = uint64_t(m.integer({"seed", "Seed of the Poisson-disk dart throwing (the order of the darts)."}, 1, 0));
    p.surfaceFootprint = m.choice({"footprint", "`vertex`: a seed snaps to the nearest vertex of its level; `surface`: it is the nearest surface point, re-projected at every level."}, "vertex", {"vertex", "surface"}) == "surface";
    if (m.has("spacing")) {
      p.kind = Placement::Kind::Spacing;
      p.spacing = float(m.number({"spacing", "Global: Poisson-disk vertices of the procedure's first level at least this far apart, in world units (default: 1.8 × radius for a berry, 2.5 × footprint for a mushroom, else 0.3)."}, defaultSpacing, 1e-6, 1e6));
    }
    if (m.has("control_vertices")) {
      if (m.boolean({"control_vertices", "Global: true puts a seed at every vertex of the control mesh."}, true)) p.kind = Placement::Kind::ControlVertices;
    }
    if (auto pts = m.get({"points", "Local: [[x, y, z], ...], each projected to the surface."})) {
      p.kind = Placement::Kind::Points;
      for (const YNode& q : pts->items())
        if (auto v = q.asVec3(diags_, "a seed point")) p.points.push_back(*v);
      if (p.points.empty()) pts->error(diags_, "'points' must be a list of [x, y, z]");
    }
    if (auto faces = m.get({"faces", "Local: [[face, u, v], ...], the bilinear point (u, v) of a control quad, then as `points`."})) {
      p.kind = Placement::Kind::Points;
      for (const YNode& q : faces->items()) facePoint(q, p.points);
      if (p.points.empty()) faces->error(diags_, "'faces' must be a list of [face, u, v]");
    }
    m.finish();
    return p;
  }

  /// [face, u, v] of a control quad: the bilinear point of its corners (projected to the
  /// surface when the seed is placed).
  void facePoint(const YNode& q, std::vector<Vec3>& out) {
    auto items = q.items();
    std::optional<int64_t> f;
    std::optional<double> u, v;
    if (items.size() == 3) {
      f = items[0].asInteger(diags_, "a face", 0, int64_t(spec_.base.faceCount()) - 1);
      u = items[1].asNumber(diags_, "u", 0.0, 1.0);
      v = items[2].asNumber(diags_, "v", 0.0, 1.0);
    } else {
      q.error(diags_, "a face seed is [face, u, v]");
    }
    if (!f || !u || !v) return;
    size_t first = 0;
    for (int64_t i = 0; i < *f; ++i) first += spec_.base.faceSizes[size_t(i)];
    if (spec_.base.faceSizes[size_t(*f)] != 4) {
      q.error(diags_, "face " + std::to_string(*f) + " is not a quad: (u, v) seeds need quads");
      return;
    }
    const auto corner = [&](int i) { return spec_.base.positions[spec_.base.faceVertices[first + size_t(i)]]; };
    const float a = float(*u), b = float(*v);
    out.push_back((1 - a) * (1 - b) * corner(0) + a * (1 - b) * corner(1) + a * b * corner(2) + (1 - a) * b * corner(3));
  }

  // ---- blend, modify, shader ----
  void readBlend(const YNode& node) {
    MapReader m(node, diags_, "blend");
    for (const YNode& item : m.sequence({"detail", "Shape B: detail procedures, summed, blended over shape A (`organism.detail`) by `alpha`."})) readProcedure(item, spec_.blendDetail);
    if (auto c = m.get({"color", "Surface colour where alpha is 1, mixed in by alpha elsewhere (default: none, the render colour)."})) {
      if (auto v = c->asColor(diags_, "'color'")) spec_.blendColor = *v;
    }
    readBlendSurface(m, {"roughness", "Roughness where alpha is 1 (0 mirror-like, 1 matte), mixed in by alpha elsewhere (default: the render's `roughness`)."}, spec_.blendRoughness);
    readBlendSurface(m, {"specular", "Specular reflectance where alpha is 1, mixed in by alpha elsewhere (default: the render's `specular`)."}, spec_.blendSpecular);
    readBlendSurface(m, {"metallic", "How metallic the surface is where alpha is 1 (0 dielectric, 1 metal), mixed in by alpha elsewhere (default: the render's `metallic`)."}, spec_.blendMetallic);
    m.markRequired("alpha");
    if (auto a = m.get({"alpha", "Where shape B replaces shape A, per level: d_l = (1 − α_l)·d^A_l + α_l·d^B_l; `plane`, `noise` or `painted`."})) readAlpha(*a);
    else m.node().error(diags_, "missing required key 'alpha' in blend (e.g. alpha: {plane: {normal: [1, 2, 0]}})");
    m.finish();
  }

  /// One of the blend's surface values in [0, 1]; left unset when absent.
  void readBlendSurface(MapReader& m, Key key, std::optional<float>& out) {
    const double v = m.number(key, std::numeric_limits<double>::quiet_NaN(), 0.0, 1.0);
    if (!std::isnan(v)) out = float(v);
  }

  void readAlpha(const YNode& node) {
    std::optional<std::pair<YNode, YNode>> one = single(node, "alpha", {"plane", "noise", "painted"});
    if (!one) return;
    const auto& [key, value] = *one;
    describeHelp(value, kindHelp("alpha", key.scalar()));
    MapReader m(value, diags_, key.scalar());
    if (key.scalar() == "plane") {
      auto plane = std::make_shared<PlaneAlpha>();
      plane->normal = m.vec3({"normal", "Normal of the blend plane (not zero; the paper's [1, 2, 0]): alpha rises to 1 on its side."}, Vec3(1, 2, 0));
      if (glm::length(plane->normal) == 0) value.error(diags_, "the blend plane's 'normal' must not be zero");
      plane->offset = float(m.number({"offset", "Position of the plane along its normal, in world units."}, 0.0));
      plane->speed = float(m.number({"speed", "The plane moves by speed·time (time 0 to 1 over the animation)."}, 0.0));
      plane->width = float(m.number({"width", "Width c of the transition across the plane, in world units."}, 0.5, 0.0));
      plane->sharp = m.choice({"transition", "`sharp`: the transition narrows to c/2^(l−1) at level l (Fig. 12, 13a); `soft`: width c at every level (Fig. 13b)."}, "sharp", {"sharp", "soft"}) == "sharp";
      spec_.animated |= plane->speed != 0;
      spec_.alpha = plane;
    } else if (key.scalar() == "painted") {
      // The base's vertex paint: one channel (or the luminance) of its linear colours.
      const std::string channel = m.choice({"channel", "Which channel of the base's linear vertex colours is the paint m (luminance: Rec. 709)."}, "luminance", {"red", "green", "blue", "luminance"});
      auto painted = std::make_shared<PaintedAlpha>();
      painted->width = float(m.number({"width", "Width of the transition around m = 1/2, in units of paint."}, 1.0, 1e-3, 1e3));
      painted->sharp = m.choice({"transition", "`sharp`: the transition narrows by half per level; `soft`: the same width at every level."}, "sharp", {"sharp", "soft"}) == "sharp";
      if (baseColors_.empty() && !spec_.base.faceSizes.empty()) {
        key.error(diags_, "a painted alpha needs a base mesh with vertex colours (a mesh or species base whose "
                          "vertices carry colours); this base has none");
      } else {
        const Vec3 weights = channel == "red"     ? Vec3(1, 0, 0)
                             : channel == "green" ? Vec3(0, 1, 0)
                             : channel == "blue"  ? Vec3(0, 0, 1)
                                                  : Vec3(0.2126f, 0.7152f, 0.0722f);  // Rec. 709
        for (const Vec3& col : baseColors_) painted->control.push_back(std::clamp(glm::dot(weights, col), 0.0f, 1.0f));
      }
      spec_.alpha = painted;
    } else {
      // A procedural alpha: smoothstep of noise of the reference position, the transition
      // narrowing per level like a sharp plane.
      const double frequency = m.number({"frequency", "Noise frequency, per world unit of the reference surface."}, 1.0, 1e-6);
      const double width = m.number({"width", "Width of the transition in noise units at level 1, halving per level."}, 0.3, 1e-6);
      const double threshold = m.number({"threshold", "Noise value where alpha is 1/2."}, 0.0, -1.0, 1.0);
      const uint64_t seed = uint64_t(m.integer({"seed", "Seed of the noise."}, 1, 0));
      auto noise = std::make_shared<textures::PerlinNoise>(seed);
      auto f = std::make_shared<FunctionAlpha>();
      f->f = [noise, frequency, width, threshold](const Vec3& p, int level, double) {
        const double w = width / double(1u << unsigned(std::max(0, level - 1)));
        const double s = ((*noise)(frequency * DVec3(p)) - threshold) / w + 0.5;
        const double x = std::clamp(s, 0.0, 1.0);
        return float(x * x * (3 - 2 * x));
      };
      spec_.alpha = f;
    }
    m.finish();
  }

  void readModification(const YNode& node) {
    MapReader m(node, diags_, "modify entry");
    Modification mod;
    mod.center = m.vec3({"center", "The modification centres on the vertex nearest this point."}, mod.center);
    mod.radius = float(m.number({"radius", "Reach R, in world units along the surface (edge hops × the level's mean edge length), with a cubic drop-off."}, mod.radius, 1e-6));
    m.markRequired("gains");
    if (auto g = m.get({"gains", "Gain g_l of each level's detail from level 0, each in [-100, 100]: 0 removes it, 1 keeps it, 2 doubles it."})) {
      for (const YNode& x : g->items())
        if (auto v = x.asNumber(diags_, "a gain", -100.0, 100.0)) mod.gains.push_back(float(*v));
      if (mod.gains.empty()) g->error(diags_, "'gains' must be a list of numbers, one per level from 0");
      if (mod.gains.size() > size_t(spec_.levels) + 1)
        g->error(diags_, "'gains' lists " + std::to_string(mod.gains.size()) + " levels, the organism has 0.." +
                             std::to_string(spec_.levels));
    } else {
      m.node().error(diags_, "missing required key 'gains' in modify entry");
    }
    m.finish();
    spec_.modifications.push_back(mod);
  }

  void readShader(const YNode& node) {
    std::optional<std::pair<YNode, YNode>> one = single(node, "shader", {"planet"});
    if (!one) return;
    describeHelp(one->second, kindHelp("shader", "planet"));
    MapReader m(one->second, diags_, "planet");
    PlanetShader s;
    s.relief = float(m.number({"relief", "Displacement along the normal per unit of scalar h: relief·max(h, sea_level)."}, s.relief));
    s.seaLevel = float(m.number({"sea_level", "Scalar value of the sea: lower points stay flat and take `ocean`."}, s.seaLevel));
    s.mountain = float(m.number({"mountain", "Scalar value above which the colour is `highland`."}, s.mountain));
    s.snow = float(m.number({"snow", "Scalar value above which the colour is `ice`."}, s.snow));
    s.bands = readBands(m, s.bands);
    if (auto second = m.section({"second", "The second planet's own bands (`ocean`, `lowland`, `highland`, `ice`), where the blend's alpha is 1; alpha mixes the two sets. Without it, alpha shifts the bands towards `tint`."})) {
      MapReader b(*second, diags_, "second");
      s.second = readBands(b, s.bands);
      b.finish();
    }
    s.tint = m.color({"tint", "Without `second`: the colour the blend's alpha shifts the bands towards."}, s.tint);
    s.tintStrength = float(m.number({"tint_strength", "Without `second`: how far alpha = 1 shifts the colours towards `tint`."}, s.tintStrength, 0.0, 1.0));
    m.finish();
    spec_.planet = s;
  }

  static PlanetBands readBands(MapReader& m, const PlanetBands& def) {
    PlanetBands b;
    b.ocean = m.color({"ocean", "Colour below `sea_level` (darker when deeper)."}, def.ocean);
    b.lowland = m.color({"lowland", "Colour between `sea_level` and `mountain`."}, def.lowland);
    b.highland = m.color({"highland", "Colour between `mountain` and `snow`."}, def.highland);
    b.ice = m.color({"ice", "Colour above `snow`."}, def.ice);
    return b;
  }

  size_t errorCount() const {
    return size_t(std::count_if(diags_.items().begin(), diags_.items().end(),
                                [](const Diagnostic& d) { return d.severity == Severity::Error; }));
  }

  std::optional<std::pair<YNode, YNode>> single(const YNode& node, const std::string& what,
                                                const std::vector<std::string>& names) {
    return singleKey(node, diags_, what, names);
  }

  DiagnosticList& diags_;
  OrganismSpec& spec_;
  const PathPolicy& policy_;
  std::vector<Vec3> baseColors_;  // a mesh or species base's vertex colours (painted alpha)
  std::string baseName_;          // " 'file'" of a mesh or species base, for messages
  bool captureGiven_ = false;  // a failed capture: 'captured' entries add no second error
};

}  // namespace

Vec3 planetColor(const PlanetShader& s, float h, float a) {
  const auto band = [&](const PlanetBands& b) {
    Vec3 c = h < s.seaLevel ? b.ocean : h < s.mountain ? b.lowland : h < s.snow ? b.highland : b.ice;
    if (h < s.seaLevel) c *= 0.6f + 0.4f * std::clamp(1.0f + (h - s.seaLevel) * 10.0f, 0.0f, 1.0f);  // deeper, darker
    return c;
  };
  const Vec3 first = band(s.bands);
  if (s.second) return glm::mix(first, band(*s.second), a);
  return glm::mix(first, first * (1.0f - s.tintStrength) + s.tint * s.tintStrength, a);
}

namespace {

/// An organism: one synthesis per time.
class OrganismModel final : public KindModel {
 public:
  explicit OrganismModel(const OrganismSpec& spec) : spec_(spec) {}

  bool hasSurface() const override { return true; }
  Stage finalStage() const override {
    Stage s;
    s.time = 1;
    return s;
  }
  Stage stageFromIndex(int k) const override {
    if (k < 0 || k >= spec_.frames)
      throw UsageError("this organism has stages 0.." + std::to_string(spec_.frames - 1) + " (times 0..1), not " +
                       std::to_string(k));
    Stage s;
    s.time = spec_.frames > 1 ? double(k) / double(spec_.frames - 1) : 1.0;
    return s;
  }
  std::vector<Stage> stripStages(int count) const override {
    if (!spec_.animated) return {finalStage()};
    return evenTimes(count);
  }
  std::vector<Stage> animationFrames(int framesPerStage, int, int) const override {
    return evenTimes(std::max(1, spec_.frames * std::max(1, framesPerStage)));
  }
  std::string stageName(const Stage& stage) const override {
    if (!spec_.animated) return {};
    char buf[32];
    std::snprintf(buf, sizeof buf, "time %.2f", timeOf(stage));
    return buf;
  }
  int stageNumber(const Stage& stage) const override { return int(std::lround(timeOf(stage) * 100)); }

  Box3 frameBox() override {
    if (!frame_) {
      // The final stage's box (time 0 is never larger for growing features).
      Box3 box = surface(1.0).mesh.bounds();
      frame_ = box.empty() ? Box3{Vec3(-1.0f), Vec3(1.0f)} : box;
    }
    return *frame_;
  }

  BuiltStage build(const Stage& stage, GeometryMode mode, const SpeciesRender& look) override {
    if (mode == GeometryMode::Skeleton) throw UsageError("organisms have no skeleton: use --mode exact or mesh");
    BuiltStage out;
    const auto t0 = std::chrono::steady_clock::now();
    render::MeshPart part;
    part.mesh = mesh(timeOf(stage), look.surface.baseColor);
    part.material = look.surface;
    part.vertexSurfaces = organismSurfaces(spec_, *cached_, surfaceOf(look.surface));
    out.figures.triangles = part.mesh.triangleCount();
    out.figures.primitives = spec_.base.faceCount();
    out.geometry.parts.push_back(std::move(part));
    out.figures.buildSeconds = secondsSince(t0);
    return out;
  }

  Mesh buildMesh(const Stage& stage, float, bool, ModelFigures& figures) override {
    Mesh m = mesh(timeOf(stage), Vec3(0.72f, 0.60f, 0.48f));
    figures.triangles = m.triangleCount();
    figures.primitives = spec_.base.faceCount();
    return m;
  }

  std::vector<ExportPart> exportParts(const Stage& stage, float, bool, const SpeciesRender& look, const MeshCleanOptions&,
                                      ModelFigures& figures) override {
    ExportPart part;
    part.name = "organism";
    part.mesh = mesh(timeOf(stage), look.surface.baseColor);
    part.material = {"organism", look.surface.baseColor, look.surface.roughness, false};
    part.material.metallic = look.surface.metallic;
    figures.triangles = part.mesh.triangleCount();
    figures.primitives = spec_.base.faceCount();
    std::vector<ExportPart> parts = splitBlendSurface(std::move(part), look.surface);
    for (ExportPart& p : parts) atlasVertexColors(p);  // the shader's colours, interpolated as the renderer does, unclamped
    return parts;
  }

  /// LOD0 of an organism within 250,000 triangles (docs/MESHES.md "Levels of detail").
  size_t lodBudget() const override { return 250000; }

  GalleryMotion galleryMotion(bool) override {
    GalleryMotion m;
    m.turntable = !spec_.animated;
    m.framesPerStage = 1;
    return m;
  }

 private:
  static double timeOf(const Stage& s) { return s.time < 0 ? 1.0 : s.time; }
  static Vec3 surfaceOf(const render::Material& m) { return Vec3(m.roughness, m.specular, m.metallic); }

  /// glTF carries roughness and metallic per material only: with the blend's own surface,
  /// the triangles whose mean alpha exceeds 1/2 become a second part, "organism_blend",
  /// with the blend's values (docs/MESHES.md); otherwise the one part as it is.
  std::vector<ExportPart> splitBlendSurface(ExportPart whole, const render::Material& look) const {
    const std::vector<float>& alpha = cached_->alpha;
    Mesh& m = whole.mesh;
    if (!(spec_.blendRoughness || spec_.blendSpecular || spec_.blendMetallic) || alpha.size() != m.vertexCount())
      return {std::move(whole)};
    m.materials.resize(m.triangleCount());
    for (size_t t = 0; t < m.triangleCount(); ++t) {
      const glm::uvec3& tri = m.triangles[t];
      m.materials[t] = alpha[tri.x] + alpha[tri.y] + alpha[tri.z] > 1.5f ? 1u : 0u;
    }
    std::vector<ExportPart> out;
    for (auto& [side, piece] : splitByMaterial(m)) {
      ExportPart p;
      p.name = side ? "organism_blend" : "organism";
      p.mesh = std::move(piece);
      p.material = whole.material;
      p.material.name = p.name;
      if (side) {
        p.material.roughness = spec_.blendRoughness.value_or(look.roughness);
        p.material.metallic = spec_.blendMetallic.value_or(look.metallic);
      }
      out.push_back(std::move(p));
    }
    return out;
  }

  /// n stages at evenly spaced times from 0 to 1 (one stage: time 1).
  static std::vector<Stage> evenTimes(int n) {
    std::vector<Stage> out(size_t(std::max(1, n)));
    for (size_t i = 0; i < out.size(); ++i) out[i].time = out.size() > 1 ? double(i) / double(out.size() - 1) : 1.0;
    return out;
  }

  /// The surface at time; the last one is kept (framing and the render of the final stage
  /// use the same synthesis).
  const OrganismSurface& surface(double time) {
    if (!cached_ || cachedTime_ != time) {
      if (!subdivision_) subdivision_.emplace(spec_.base, spec_.levels);  // the topology never changes
      cached_ = buildOrganismSurface(spec_, *subdivision_, time);
      cachedTime_ = time;
    }
    return *cached_;
  }

  Mesh mesh(double time, const Vec3& baseColor) {
    Mesh m = surface(time).mesh;
    m.colors = organismColors(spec_, *cached_, baseColor);
    return m;
  }

  const OrganismSpec& spec_;
  std::optional<Box3> frame_;
  std::optional<OrganismSurface> cached_;
  std::optional<Subdivision> subdivision_;
  double cachedTime_ = 0;
};

}  // namespace

size_t finestFaceCount(const ControlMesh& base, int levels) {
  size_t faces = 0;
  for (uint32_t n : base.faceSizes) faces += n;  // level 1: one quad per corner
  return faces << (2 * (levels - 1));
}

OrganismSurface buildOrganismSurface(const OrganismSpec& spec, const Subdivision& sub, double time) {
  SynthesisInput in;
  in.shapeA = spec.detail;
  in.shapeB = spec.blendDetail;
  in.alpha = spec.alpha;
  in.modifications = spec.modifications;
  SynthesisOptions options;
  options.time = time;
  SynthesisResult r = synthesize(sub, spec.base.positions, in, options);
  // The planet shader displaces along the surface's normals by the relief of the height
  // above the sea (oceans stay flat at the sea level).
  if (spec.planet && !r.scalar.empty()) {
    std::vector<Frame> frames(r.positions.size());
    computeFrames(sub.topology(sub.levels()), r.positions, frames);
    for (size_t v = 0; v < r.positions.size(); ++v)
      r.positions[v] += frames[v].n * (spec.planet->relief * std::max(r.scalar[v], spec.planet->seaLevel));
  }
  OrganismSurface out;
  out.mesh = limitMesh(sub, r.positions);
  out.alpha = std::move(r.alpha);
  out.scalar = std::move(r.scalar);
  return out;
}

std::vector<Vec3> organismColors(const OrganismSpec& spec, const OrganismSurface& s, const Vec3& baseColor) {
  const size_t n = s.mesh.vertexCount();
  std::vector<Vec3> colors(n, baseColor);
  if (spec.planet) {
    for (size_t v = 0; v < n; ++v)
      colors[v] = planetColor(*spec.planet, s.scalar.empty() ? 0.0f : s.scalar[v], s.alpha.empty() ? 0.0f : s.alpha[v]);
  } else if (spec.blendColor && !s.alpha.empty()) {
    for (size_t v = 0; v < n; ++v) colors[v] = glm::mix(baseColor, *spec.blendColor, s.alpha[v]);
  }
  return colors;
}

std::vector<Vec3> organismSurfaces(const OrganismSpec& spec, const OrganismSurface& s, const Vec3& renderSurface) {
  if (!(spec.blendRoughness || spec.blendSpecular || spec.blendMetallic) || s.alpha.empty()) return {};
  const Vec3 blend(spec.blendRoughness.value_or(renderSurface.x), spec.blendSpecular.value_or(renderSurface.y),
                   spec.blendMetallic.value_or(renderSurface.z));
  std::vector<Vec3> out(s.mesh.vertexCount());
  // (1 − α)·render + α·blend: exactly one or the other where alpha is 0 or 1.
  for (size_t v = 0; v < out.size(); ++v) out[v] = (1.0f - s.alpha[v]) * renderSurface + s.alpha[v] * blend;
  return out;
}

Mesh buildOrganismMesh(const OrganismSpec& spec, double time, const Vec3& baseColor) {
  OrganismSurface s = buildOrganismSurface(spec, Subdivision(spec.base, spec.levels), time);
  s.mesh.colors = organismColors(spec, s, baseColor);
  return std::move(s.mesh);
}

std::shared_ptr<const KindSpec> readOrganismSpec(MapReader& top, Species& species, DiagnosticList& diags) {
  std::optional<YNode> section = top.section({"organism", "The subdivision organism: base mesh, levels, per-level detail procedures, blend, local modifications, shader and animation (docs/ORGANISMS.md)."});
  if (!section) {
    if (!top.has("organism")) top.node().error(diags, "missing required key 'organism' in species file");
    return nullptr;
  }
  auto spec = std::make_shared<OrganismSpec>();
  spec->loc = section->loc();
  const size_t before = diags.items().size();
  OrganismReader(diags, *spec, species.policy).read(*section);
  for (size_t i = before; i < diags.items().size(); ++i)
    if (diags.items()[i].severity == Severity::Error) return nullptr;
  if (spec->base.faceSizes.empty()) return nullptr;
  return spec;
}

std::string OrganismSpec::checkSummary(const Species& species) const {
  const size_t faces = finestFaceCount(base, levels);
  return " '" + species.name + "', " + std::to_string(base.faceCount()) + " control faces, " + std::to_string(levels) +
         " levels (" + std::to_string(faces) + " faces)";
}

std::unique_ptr<KindModel> OrganismSpec::makeModel(const Species&, const ModelOptions&) const {
  return std::make_unique<OrganismModel>(*this);
}

}  // namespace sprig
