/// The Python module `sprig._sprig` (python/sprig/__init__.py re-exports it; docs/PYTHON.md).
///
/// Each function calls the library functions the `sprig` command calls (app/cmd_*.cpp):
/// loadSpecies and SpeciesModel, renderModel, SpeciesModel::exportParts and writeParts,
/// GrowthEngine, animationStages; so a result equals the command's for the same options,
/// byte for byte. Arrays go out as numpy arrays (copies). Long calls run through runLong
/// (python/long_call.h): GIL released, progress callback, Ctrl-C cancels.

#include <pybind11/eval.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/diagnostics.h"
#include "core/image.h"
#include "core/json_writer.h"
#include "core/mesh_io.h"
#include "core/paths.h"
#include "core/progress.h"
#include "lsystem/derive.h"
#include "model/animate.h"
#include "model/growth.h"
#include "model/kind_name.h"
#include "model/lod.h"
#include "model/mesh_parts.h"
#include "model/model.h"
#include "model/species.h"
#include "model/tree_kind.h"
#include "model/wind_export.h"
#include "python/long_call.h"

namespace py = pybind11;

namespace sprig::python {

namespace {

/// A species loaded from Python: the species, the overrides it was loaded with, and its
/// model (made when loaded, as every command makes one).
struct PySpecies {
  Species species;
  lsystem::GrammarOverrides extra;
  std::unique_ptr<SpeciesModel> model;
};

/// A numpy array of shape with a copy of count elements at data.
template <class T>
py::array_t<T> copyArray(const void* data, std::vector<py::ssize_t> shape) {
  py::array_t<T> a(shape);
  if (a.size() > 0) std::memcpy(a.mutable_data(), data, sizeof(T) * static_cast<size_t>(a.size()));
  return a;
}

const char* severityText(Severity s) {
  return s == Severity::Error ? "error" : s == Severity::Warning ? "warning" : "note";
}

/// `-D NAME=VALUE` for each entry of defines, `--steps` and `--seed` (app/cmd_common.cpp's
/// commandLineOverrides, from Python values).
lsystem::GrammarOverrides overridesFrom(const std::map<std::string, double>& defines, std::optional<int> steps,
                                        std::optional<int64_t> seed) {
  lsystem::GrammarOverrides o;
  for (const auto& [name, value] : defines) {
    const std::string text = "-D " + name + "=" + json::number(value);
    o.defines.push_back(lsystem::DefineOverride{name, value, SourceLoc{text, 0, 0}});
  }
  if (steps) {
    if (*steps < 0) throw UsageError("steps must not be negative");
    o.derivationLength = *steps;
  }
  if (seed) {
    if (*seed < 0) throw UsageError("seed must not be negative");
    o.seed = static_cast<uint64_t>(*seed);
  }
  return o;
}

/// The stage `--stage`, `--fraction` and `--age` name (app/cmd_common.cpp's StageFlags::resolve).
Stage resolveStage(const SpeciesModel& model, std::optional<int> stage, double fraction, std::optional<double> age) {
  if (fraction < 0 || fraction > 1) throw UsageError("fraction must lie in [0, 1]");
  Stage s = stage ? model.stageFromIndex(*stage) : model.finalStage();
  s.fraction = fraction;
  if (age) s.age = model.stageAtAge(*age).age;
  return s;
}

/// An image as 8-bit sRGB bytes (H, W, channels): the values `sprig render` writes to PNG.
py::array_t<uint8_t> imageBytes(const Image& image, int channels) {
  const std::vector<uint8_t> bytes = toSrgb8(image, channels);
  return copyArray<uint8_t>(bytes.data(), {image.height, image.width, channels});
}

/// An image's linear RGBA floats (H, W, 4).
py::array_t<float> imageFloats(const Image& image) {
  return copyArray<float>(image.pixels.data(), {image.height, image.width, 4});
}

/// What Species.render and the animation frames return: bytes, or linear floats.
py::object imageResult(const Image& image, bool alpha, bool linear) {
  if (linear) return imageFloats(image);
  return imageBytes(image, alpha ? 4 : 3);
}

// ---- Loading and checking ----------------------------------------------------------

std::shared_ptr<PySpecies> load(const std::filesystem::path& path, const std::map<std::string, double>& overrides,
                                std::optional<int64_t> seed, std::optional<int> steps, const std::string& root,
                                bool allowOutside, const py::object& progress) {
  auto s = std::make_shared<PySpecies>();
  s->extra = overridesFrom(overrides, steps, seed);
  PathPolicy policy;
  policy.root = root;
  policy.allowOutside = allowOutside;
  return runLong(
      [&] {
        s->species = loadSpecies(path, policy);
        s->model = std::make_unique<SpeciesModel>(s->species, s->extra);
        return s;
      },
      progress);
}

/// Every diagnostic of the species: its notes and warnings, then the errors `sprig check`
/// finds beyond reading (KindSpec::checkSummary may build the final stage).
std::vector<Diagnostic> check(PySpecies& s, const py::object& progress) {
  return runLong(
      [&] {
        std::vector<Diagnostic> out = s.species.notes;
        try {
          s.species.spec->checkSummary(s.species);
        } catch (const InputError& e) {
          out.insert(out.end(), e.diagnostics().begin(), e.diagnostics().end());
        }
        return out;
      },
      progress);
}

/// What `sprig check` prints after "FILE: ok (": the kind and its summary.
std::string summary(PySpecies& s) {
  return s.species.kind + (s.species.bareGrammar ? " grammar" : " species") + s.species.spec->checkSummary(s.species);
}

/// A tree's grammar as loaded (its own overrides, then sprig.load's): every `#define` in file
/// order with its value, and the derivation length. Other kinds have neither.
std::pair<std::vector<std::pair<std::string, double>>, std::optional<int>> grammarParameters(PySpecies& s) {
  if (s.species.kind != "tree") return {};
  return runLong(
      [&] {
        const lsystem::Grammar g = speciesGrammar(s.species, s.extra);
        std::vector<std::pair<std::string, double>> defines;
        for (const std::string& name : g.defineNames()) defines.emplace_back(name, g.define(name).value_or(0));
        return std::make_pair(defines, std::optional<int>(g.derivationLength()));
      },
      py::none());
}

// ---- derive --------------------------------------------------------------------------

/// `sprig derive`'s string and skeleton at one step.
struct Derivation {
  int steps = 0;
  uint64_t seed = 0;
  std::string string;
  lsystem::Skeleton skeleton;
};

py::dict derivationDict(const Derivation& d) {
  const auto& nodes = d.skeleton.internodes;
  const auto n = static_cast<py::ssize_t>(nodes.size());
  py::array_t<double> starts({n, py::ssize_t(3)}), ends({n, py::ssize_t(3)}), baseRadii(n), tipRadii(n);
  py::array_t<int32_t> parents(n), orders(n), steps(n);
  auto st = starts.mutable_unchecked<2>(), en = ends.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < n; ++i) {
    const lsystem::Internode& k = nodes[static_cast<size_t>(i)];
    for (int c = 0; c < 3; ++c) st(i, c) = k.start[c], en(i, c) = k.end[c];
    baseRadii.mutable_at(i) = k.baseRadius;
    tipRadii.mutable_at(i) = k.tipRadius;
    parents.mutable_at(i) = k.parent;
    orders.mutable_at(i) = k.order;
    steps.mutable_at(i) = k.step;
  }
  py::dict out;
  out["string"] = d.string;
  out["steps"] = d.steps;
  out["seed"] = d.seed;
  out["starts"] = starts;
  out["ends"] = ends;
  out["base_radii"] = baseRadii;
  out["tip_radii"] = tipRadii;
  out["parents"] = parents;
  out["orders"] = orders;
  out["created_at_step"] = steps;
  return out;
}

py::dict derive(PySpecies& s, std::optional<int> stage, const py::object& progress) {
  Derivation d = runLong(
      [&] {
        GrowthEngine engine(s.species, GrowthOptions{s.extra, -1, "derive " + s.species.name});
        Derivation r;
        r.steps = stage ? *stage : engine.lastStep();
        if (r.steps < 0 || r.steps > engine.lastStep())
          throw UsageError("stage " + std::to_string(r.steps) + " is beyond the species' " +
                           std::to_string(engine.lastStep()) + " steps");
        r.seed = engine.seed();
        r.string = lsystem::formatModuleString(engine.modulesAt(r.steps), engine.symbols(), speciesStringFormat(s.species));
        r.skeleton = engine.skeletonAt(r.steps);
        return r;
      },
      progress);
  return derivationDict(d);
}

// ---- render ----------------------------------------------------------------------------

struct RenderRequest {
  int width = 0, height = 0, spp = 0;
  std::string mode = "exact";
  std::optional<int> stage;
  double fraction = 1;
  std::optional<double> age;
  std::optional<std::vector<double>> view;
};

/// `--view AZ,EL[,FOV]` (app/cmd_common.cpp's parseView ranges).
void applyView(const std::vector<double>& v, render::ViewSpec& view) {
  const bool ok = (v.size() == 2 || v.size() == 3) && v[0] >= -360 && v[0] <= 360 && v[1] >= -89 && v[1] <= 89 &&
                  (v.size() == 2 || (v[2] >= 1 && v[2] <= 150));
  if (!ok) throw UsageError("view: expected (azimuth, elevation[, fov]) in degrees (elevation in [-89, 89], fov in [1, 150])");
  view.azimuthDeg = v[0];
  view.elevationDeg = v[1];
  if (v.size() == 3) view.fovYDeg = v[2];
}

Image renderImage(PySpecies& s, const RenderRequest& r) {
  if ((r.width != 0 && (r.width < 16 || r.width > 16384)) || (r.height != 0 && (r.height < 16 || r.height > 16384)))
    throw UsageError("width and height must lie in [16, 16384]");
  if (r.spp < 0 || r.spp > 4096) throw UsageError("spp must lie in [1, 4096]");
  SpeciesRender look = s.species.render;
  if (r.view) applyView(*r.view, look.view);
  RenderJob job;
  job.width = r.width;
  job.height = r.height;
  job.samples = r.spp;
  job.mode = geometryModeNamed(r.mode);
  job.stage = resolveStage(*s.model, r.stage, r.fraction, r.age);
  job.progress = true;
  job.progressLabel = "render " + s.species.name;
  return renderModel(*s.model, look, job);
}

// ---- mesh and export ----------------------------------------------------------------------

struct MeshRequest {
  std::optional<int> stage;
  double fraction = 1;
  std::optional<double> age;
  double cell = 0;
  double minVolume = MeshCleanOptions{}.minVolumeFraction;
  std::optional<double> simplify;
};

/// `sprig mesh`'s parts (app/cmd_mesh.cpp): exportParts, simplifyParts when asked, then
/// finishExportParts (degenerate triangles removed, the model placed at the origin).
std::vector<ExportPart> meshParts(PySpecies& s, const MeshRequest& r, Vec3* offset = nullptr) {
  if (r.cell < 0) throw UsageError("cell must be positive (0 = automatic)");
  if (r.minVolume < 0 || r.minVolume > 1) throw UsageError("min_volume must lie in [0, 1]");
  if (r.simplify && (*r.simplify < 0 || *r.simplify > 0.1)) throw UsageError("simplify must lie in [0, 0.1]");
  const Stage stage = resolveStage(*s.model, r.stage, r.fraction, r.age);
  MeshCleanOptions clean;
  clean.minVolumeFraction = r.minVolume;
  ModelFigures fig;
  std::vector<ExportPart> parts = s.model->exportParts(stage, static_cast<float>(r.cell), true, clean, &fig);
  const double simplify = r.simplify ? *r.simplify : s.species.render.simplify;
  if (simplify > 0) simplifyParts(parts, simplify);
  const ExportFinish finish = finishExportParts(parts);
  if (offset) *offset = finish.offset;
  return parts;
}

/// wind= of Species.mesh and Species.export: the species' own wind (value unset) or
/// (speed m/s, direction degrees), checked as `sprig mesh --wind` checks them.
std::optional<std::pair<double, double>> windValue(const std::optional<std::vector<double>>& v) {
  if (!v) return std::nullopt;
  const bool ok = (v->size() == 1 || v->size() == 2) && (*v)[0] >= 0 && (*v)[0] <= 60 &&
                  (v->size() == 1 || ((*v)[1] >= -360 && (*v)[1] <= 360));
  if (!ok) throw UsageError("wind: expected speed or (speed, direction) with 0 <= speed <= 60 (m/s) and -360 <= direction <= 360 (degrees)");
  return std::make_pair((*v)[0], v->size() == 2 ? (*v)[1] : 0.0);
}

/// An explicit wind for a kind without one is an error, as `sprig mesh --wind` makes it.
void requireWind(SpeciesModel& model, const Stage& stage, const std::optional<std::pair<double, double>>& wind) {
  if (wind && !model.windSource(stage)) throw UsageError("wind sways trees; " + speciesOfKind(model.species().kind) + " has no wind");
}

/// A part's wind (addModelWind's, as the .glb's LOD0 has it): `wind` holds the morph
/// targets (names, targets (K, N, 3) displacements, times (F,), weights (K, F)) or None
/// when the part does not sway; `wind_attribute` is `_WIND` (N, 4), or None.
void addWindEntries(py::dict& d, const ExportPart& p) {
  d["wind"] = py::none();
  d["wind_attribute"] = py::none();
  const auto nv = static_cast<py::ssize_t>(p.mesh.vertexCount());
  for (const VertexAttribute& a : p.attributes)
    if (a.name == "_WIND") d["wind_attribute"] = copyArray<float>(a.values.data(), {nv, 4});
  if (!p.morph) return;
  const PartMorph& m = *p.morph;
  const auto nk = static_cast<py::ssize_t>(m.targets.size()), nf = static_cast<py::ssize_t>(m.times.size());
  py::array_t<float> targets({nk, nv, py::ssize_t(3)}), weights({nk, nf});
  for (py::ssize_t k = 0; k < nk; ++k) {
    std::memcpy(targets.mutable_data(k), m.targets[size_t(k)].data(), sizeof(float) * 3 * size_t(nv));
    std::memcpy(weights.mutable_data(k), m.weights[size_t(k)].data(), sizeof(float) * size_t(nf));
  }
  py::dict w;
  w["animation"] = m.animation;
  w["names"] = m.names;
  w["targets"] = targets;
  w["times"] = copyArray<float>(m.times.data(), {nf});
  w["weights"] = weights;
  w["loop_seconds"] = kWindLoopSeconds;
  d["wind"] = w;
}

py::dict partDict(const ExportPart& p) {
  const Mesh& m = p.mesh;
  const auto nv = static_cast<py::ssize_t>(m.vertexCount()), nt = static_cast<py::ssize_t>(m.triangleCount());
  py::dict d;
  d["name"] = p.name;
  d["positions"] = copyArray<float>(m.positions.data(), {nv, 3});
  d["triangles"] = copyArray<uint32_t>(m.triangles.data(), {nt, 3});
  d["normals"] = m.normals.empty() ? py::object(py::none()) : copyArray<float>(m.normals.data(), {nv, 3});
  d["colors"] = m.colors.empty() ? py::object(py::none()) : copyArray<float>(m.colors.data(), {nv, 3});
  d["uvs"] = m.uvs.empty() ? py::object(py::none()) : copyArray<float>(m.uvs.data(), {nv, 2});
  d["material_ids"] = m.materials.empty() ? py::object(py::none()) : copyArray<uint32_t>(m.materials.data(), {nt});
  d["material"] = p.material.name;
  d["base_color"] = py::make_tuple(p.material.baseColor.x, p.material.baseColor.y, p.material.baseColor.z);
  d["roughness"] = p.material.roughness;
  d["double_sided"] = p.material.doubleSided;
  d["alpha_cutoff"] = p.material.alphaCutoff >= 0 ? py::object(py::float_(p.material.alphaCutoff)) : py::none();
  d["texture"] = py::none();
  d["texture_corner_uvs"] = py::none();
  if (p.material.texture) {
    d["texture"] = imageFloats(p.material.texture->pixels());
    const auto& atlas = p.material.texture->atlas;
    if (p.material.texture->isAtlas()) {
      py::array_t<float> uv({nt, py::ssize_t(3), py::ssize_t(2)});
      auto a = uv.mutable_unchecked<3>();
      for (py::ssize_t t = 0; t < nt; ++t)
        for (int c = 0; c < 3; ++c) {
          const Vec2 v = atlas.values[atlas.index[static_cast<size_t>(t * 3 + c)]];
          a(t, c, 0) = v.x;
          a(t, c, 1) = v.y;
        }
      d["texture_corner_uvs"] = uv;
    }
  }
  addWindEntries(d, p);
  return d;
}

/// Species.mesh: meshParts, and with wind (wind true: the species' own, or windAt) the
/// wind `sprig mesh` puts on a .glb's LOD0 (addModelWind) on these parts.
py::list mesh(PySpecies& s, const MeshRequest& r, bool wind, const std::optional<std::pair<double, double>>& windAt,
              const py::object& progress) {
  const std::vector<ExportPart> parts = runLong(
      [&] {
        const Stage stage = resolveStage(*s.model, r.stage, r.fraction, r.age);
        requireWind(*s.model, stage, windAt);
        Vec3 offset(0.0f);
        std::vector<LodLevel> levels(1);
        levels[0].parts = meshParts(s, r, &offset);
        if (wind || windAt) addModelWind(*s.model, stage, levels, offset, windAt);
        return std::move(levels[0].parts);
      },
      progress);
  py::list out;
  for (const ExportPart& p : parts)
    if (!p.mesh.triangles.empty()) out.append(partDict(p));
  return out;
}

/// `sprig mesh SPECIES -o path`: the parts written with their levels of detail (model/lod.h
/// writeLevels, the kind's default budget), or a solid's volume mesh.
void exportMesh(PySpecies& s, const std::filesystem::path& path, const MeshRequest& r,
                const std::optional<std::pair<double, double>>& wind, const py::object& progress) {
  const std::string ext = lowerExtension(path);
  const bool volume = ext == ".msh" || ext == ".vtu" || ext == ".mesh";
  if (!volume && ext != ".ply" && ext != ".obj" && ext != ".glb")
    throw UsageError(path.string() + ": unknown mesh extension '" + path.extension().string() +
                     "' (use .ply, .obj, .glb; solids also .msh, .vtu, .mesh)");
  if (wind && ext != ".glb") throw UsageError("wind writes a tree's sway into glTF: give a .glb name");
  runLong(
      [&] {
        requireWind(*s.model, resolveStage(*s.model, r.stage, r.fraction, r.age), wind);
        if (volume) {
          if (r.simplify && *r.simplify > 0)
            throw UsageError("simplify applies to the surface parts written as .ply, .obj or .glb, not to volume meshes");
          s.model->writeVolumeMesh(resolveStage(*s.model, r.stage, r.fraction, r.age), path, true);
        } else {
          Vec3 offset(0.0f), moved(0.0f);  // as `sprig mesh`: levels of detail, a tree's wind in .glb
          std::vector<LodLevel> levels = lodLevels(meshParts(s, r, &offset), s.model->lodBudget(), &moved);
          if (ext == ".glb")
            addModelWind(*s.model, resolveStage(*s.model, r.stage, r.fraction, r.age), levels, offset + moved, wind);
          writeLevels(levels, path);
        }
        return 0;
      },
      progress);
}

// ---- animate ---------------------------------------------------------------------------

/// The frames of `sprig animate` (model/animate.h animationStages), rendered one per next().
struct Frames {
  std::shared_ptr<PySpecies> species;
  std::unique_ptr<SpeciesModel> model;  ///< derived up to the animation's last stage, as the command's
  std::vector<Stage> stages;
  SpeciesRender look;
  GeometryMode mode = GeometryMode::Exact;
  int width = 0, height = 0;
  size_t next = 0;
  bool alpha = true, linear = false;
  py::object progress;
};

struct AnimateRequest {
  int framesPerStage = 6;
  std::optional<int> first, last;
  int width = 0, height = 0, samples = 0;
  double fps = 12, windSpeed = 0, windDirectionDeg = 0, windSeconds = 4;
};

std::unique_ptr<Frames> animate(const std::shared_ptr<PySpecies>& s, const AnimateRequest& r, bool alpha, bool linear,
                                const py::object& progress) {
  if (r.framesPerStage < 1) throw UsageError("frames_per_stage must be at least 1");
  if (!(r.fps > 0)) throw UsageError("fps must be positive");
  if (!(r.windSpeed >= 0 && r.windSpeed <= 60) || !(r.windSeconds >= 0))
    throw UsageError("wind speed must lie in [0, 60] m/s and wind_seconds must not be negative");
  AnimateOptions opt;
  opt.extra = s->extra;
  opt.framesPerStage = r.framesPerStage;
  opt.fps = r.fps;
  opt.samples = r.samples;
  if (r.first) opt.firstStage = *r.first;
  if (r.last) opt.lastStage = *r.last;
  opt.windSpeed = r.windSpeed;
  opt.windDirectionDeg = r.windDirectionDeg;
  opt.windSeconds = r.windSeconds;
  auto f = std::make_unique<Frames>();
  f->species = s;
  f->look = s->species.render;
  if (r.samples > 0) f->look.image.spp = r.samples;
  // The image size as `sprig animate` takes it: one side given keeps the species' aspect.
  const int w = f->look.image.width, h = f->look.image.height;
  f->width = r.width > 0 ? r.width : r.height > 0 ? std::max(16, w * r.height / h) : w;
  f->height = r.height > 0 ? r.height : r.width > 0 ? std::max(16, h * r.width / w) : h;
  f->alpha = alpha;
  f->linear = linear;
  f->progress = progress;
  f->stages = runLong(
      [&] {
        f->model = std::make_unique<SpeciesModel>(s->species, opt.extra, opt.lastStage);
        f->mode = f->model->defaultMode();
        AnimateResult result;
        return animationStages(*f->model, opt, result);
      },
      progress);
  return f;
}

py::object nextFrame(Frames& f) {
  if (f.next >= f.stages.size()) throw py::stop_iteration();
  const Stage stage = f.stages[f.next];
  Image image = runLong(
      [&] {
        RenderJob job;  // as animateModel renders each frame
        job.width = f.width;
        job.height = f.height;
        job.mode = f.mode;
        job.stage = stage;
        job.progress = true;
        job.progressLabel = "frame " + std::to_string(f.next);
        return renderModel(*f.model, f.look, job);
      },
      f.progress);
  ++f.next;
  return imageResult(image, f.alpha, f.linear);
}

}  // namespace

namespace {

// ---- Errors ------------------------------------------------------------------------------

/// sprig.InputError and sprig.Diagnostic, made in Python by bindErrors (the module holds them).
PyObject* gInputError = nullptr;
PyObject* gDiagnostic = nullptr;

py::object diagnosticObject(const Diagnostic& d) {
  return py::reinterpret_borrow<py::object>(gDiagnostic)(d.loc.file, d.loc.line, d.loc.col, severityText(d.severity), d.message, d.format());
}

/// Diagnostic (a plain Python class) and InputError (a ValueError whose attributes are the
/// first diagnostic's: file, line, column, severity, message; `diagnostics` holds all), and
/// the translation of Sprig's exceptions: InputError -> sprig.InputError, UsageError ->
/// ValueError, Cancelled -> KeyboardInterrupt.
void bindErrors(py::module_& m) {
  py::exec(R"py(
class Diagnostic:
    """One message about a species file or grammar: file, line and column (1-based, 0 when
    unknown), severity ('error', 'warning' or 'note') and message. str() is the text
    `sprig check` prints (with the source line and a caret when known)."""
    __slots__ = ("file", "line", "column", "severity", "message", "text")
    def __init__(self, file, line, column, severity, message, text):
        self.file, self.line, self.column = file, line, column
        self.severity, self.message, self.text = severity, message, text
    def __str__(self):
        return self.text
    def __repr__(self):
        return "Diagnostic(%r, %d, %d, %r, %r)" % (self.file, self.line, self.column, self.severity, self.message)

class InputError(ValueError):
    """Bad input in a species file or grammar. str() is sprig's `file:line:col: error: ...`
    text; file, line, column, severity and message are the first diagnostic's, and
    diagnostics holds every one."""
    def __init__(self, text, diagnostics=()):
        super().__init__(text)
        self.diagnostics = list(diagnostics)
        first = self.diagnostics[0] if self.diagnostics else None
        self.file = first.file if first else ""
        self.line = first.line if first else 0
        self.column = first.column if first else 0
        self.severity = first.severity if first else "error"
        self.message = first.message if first else text
)py",
           m.attr("__dict__"));
  gInputError = m.attr("InputError").ptr();
  gDiagnostic = m.attr("Diagnostic").ptr();
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      py::list diags;
      for (const Diagnostic& d : e.diagnostics()) diags.append(diagnosticObject(d));
      py::object err = py::reinterpret_borrow<py::object>(gInputError)(py::str(e.what()), diags);
      PyErr_SetObject(gInputError, err.ptr());
    } catch (const UsageError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const Cancelled&) {
      PyErr_SetNone(PyExc_KeyboardInterrupt);
    }
  });
}

// ---- Bindings ------------------------------------------------------------------------------

void bindSpecies(py::module_& m) {
  py::class_<PySpecies, std::shared_ptr<PySpecies>>(m, "Species", "A species loaded with sprig.load.")
      .def_property_readonly("name", [](const PySpecies& s) { return s.species.name; })
      .def_property_readonly("kind", [](const PySpecies& s) { return s.species.kind; })
      .def_property_readonly("description", [](const PySpecies& s) { return s.species.description; })
      .def_property_readonly("file", [](const PySpecies& s) { return s.species.file; })
      .def_property_readonly("has_surface", [](const PySpecies& s) { return s.model->hasSurfaceSettings(); })
      .def_property_readonly("render_size",
                             [](const PySpecies& s) {
                               return py::make_tuple(s.species.render.image.width, s.species.render.image.height);
                             })
      .def("check", [](PySpecies& s, const py::object& progress) {
             py::list out;
             for (const Diagnostic& d : check(s, progress)) out.append(diagnosticObject(d));
             return out;
           }, py::arg("progress") = py::none())
      .def("summary", [](PySpecies& s, const py::object& progress) { return runLong([&] { return summary(s); }, progress); },
           py::arg("progress") = py::none())
      .def("defines",
           [](PySpecies& s) {
             py::dict out;  // insertion-ordered: the file's order
             for (const auto& [name, value] : grammarParameters(s).first) out[py::str(name)] = value;
             return out;
           })
      .def_property_readonly("steps", [](PySpecies& s) { return grammarParameters(s).second; })
      .def("derive", &derive, py::arg("stage") = py::none(), py::arg("progress") = py::none())
      .def("_render",
           [](PySpecies& s, int width, int height, int spp, const std::string& mode, std::optional<int> stage,
              double fraction, std::optional<double> age, std::optional<std::vector<double>> view, bool alpha, bool linear,
              const py::object& progress) {
             const RenderRequest r{width, height, spp, mode, stage, fraction, age, std::move(view)};
             return imageResult(runLong([&] { return renderImage(s, r); }, progress), alpha, linear);
           },
           py::arg("width"), py::arg("height"), py::arg("spp"), py::arg("mode"), py::arg("stage"), py::arg("fraction"),
           py::arg("age"), py::arg("view"), py::arg("alpha"), py::arg("linear"), py::arg("progress"))
      .def_property_readonly("wind",
                             [](const PySpecies& s) -> py::object {
                               if (s.species.kind != "tree") return py::none();  // trees alone sway (KindModel::windSource)
                               return py::make_tuple(s.species.render.windSpeed, s.species.render.windDirectionDeg);
                             })
      .def("_mesh",
           [](PySpecies& s, std::optional<int> stage, double fraction, std::optional<double> age, double cell,
              double minVolume, std::optional<double> simplify, bool wind, std::optional<std::vector<double>> windAt,
              const py::object& progress) {
             return mesh(s, MeshRequest{stage, fraction, age, cell, minVolume, simplify}, wind, windValue(windAt), progress);
           })
      .def("_export",
           [](PySpecies& s, const std::filesystem::path& path, std::optional<int> stage, double fraction,
              std::optional<double> age, double cell, double minVolume, std::optional<double> simplify,
              std::optional<std::vector<double>> wind, const py::object& progress) {
             exportMesh(s, path, MeshRequest{stage, fraction, age, cell, minVolume, simplify}, windValue(wind), progress);
           })
      .def("_animate",
           [](const std::shared_ptr<PySpecies>& s, int framesPerStage, std::optional<int> first, std::optional<int> last,
              int width, int height, int samples, double fps, double windSpeed, double windDirectionDeg,
              double windSeconds, bool alpha, bool linear, const py::object& progress) {
             const AnimateRequest r{framesPerStage, first, last, width, height, samples, fps, windSpeed, windDirectionDeg,
                                    windSeconds};
             return animate(s, r, alpha, linear, progress);
           });

  py::class_<Frames>(m, "Frames", "The frames of Species.animate: an iterator of images, one render per step.")
      .def("__iter__", [](Frames& f) -> Frames& { return f; }, py::return_value_policy::reference_internal)
      .def("__next__", &nextFrame)
      .def("__len__", [](const Frames& f) { return f.stages.size(); })
      .def_property_readonly("size", [](const Frames& f) { return py::make_tuple(f.width, f.height); });

  m.def("_load", &load, py::arg("path"), py::arg("overrides"), py::arg("seed"), py::arg("steps"), py::arg("root"),
        py::arg("allow_outside_paths"), py::arg("progress"));
  m.def("_set_progress_bars", [](bool on) { ProgressSettings::setQuiet(!on); },
        "Draw Sprig's own progress bars on stderr when it is a terminal (off by default).");
}

}  // namespace

}  // namespace sprig::python

PYBIND11_MODULE(_sprig, m) {
  m.doc() = "Sprig's C++ library (the `sprig` package wraps it: see docs/PYTHON.md)";
  m.attr("__version__") = SPRIG_VERSION;
  m.attr("DEFAULT_MIN_VOLUME") = sprig::MeshCleanOptions{}.minVolumeFraction;
  sprig::ProgressSettings::setQuiet(true);  // Python shows progress through callbacks
  sprig::python::bindErrors(m);
  sprig::python::bindSpecies(m);
}
