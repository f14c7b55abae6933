/// `sprig mesh SPECIES -o OUT.{ply,obj,glb} [--cell SIZE] [--stage K]`: polygonizes a species' surface.

#include "app/cmd_mesh.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <cstdio>
#include <iostream>

#include "model/species.h"
#include "app/cmd_common.h"
#include "model/lod.h"
#include "model/mesh_parts.h"
#include "model/kind_name.h"
#include "model/wind_export.h"
#include "model/model.h"
#include "core/mesh_io.h"
#include "core/paths.h"
#include "core/phases.h"

namespace sprig {

namespace {

struct MeshArgs {
  std::string file;
  std::vector<std::string> outs;  ///< one or more -o; several only for surface meshes
  double cell = 0.0;
  StageFlags stage;
  GrowthFlags growth;
  bool interfaces = false;
  double minVolume = MeshCleanOptions{}.minVolumeFraction;
  std::string mesher;  ///< empty = the species' render.mesher
  double simplify = -1;  ///< < 0 = the species' render.simplify
  std::string wind;  ///< empty = the species' wind; else SPEED[,DIRECTION]
  std::string lod = "auto";  ///< auto (the kind's LOD0 budget), none (the full mesh alone) or a budget
};

/// LOD0's triangle budget of --lod (0: none, the full mesh alone). Throws UsageError for
/// anything but auto, none or a whole number of at least kLodMinBudget.
size_t lodBudget(const std::string& value, size_t kindBudget) {
  if (value == "auto") return kindBudget;
  if (value == "none") return 0;
  size_t budget = 0;
  bool digits = !value.empty() && value.size() <= 10;
  for (char c : value) digits = digits && c >= '0' && c <= '9';
  if (digits) budget = std::stoull(value);
  if (!digits || budget < kLodMinBudget)
    throw UsageError("--lod: '" + value + "' is not auto, none or a triangle budget (a whole number of at least " +
                     std::to_string(kLodMinBudget) + ")");
  return budget;
}

/// The note on the levels of detail written ("" for one level).
std::string lodNote(const std::vector<LodLevel>& levels, size_t budget, size_t fullTriangles, double seconds) {
  if (levels.size() < 2) return {};
  std::string text = "levels of detail (LOD0 budget " + std::to_string(budget) + " triangles, full mesh " +
                     std::to_string(fullTriangles) + "):";
  for (size_t k = 0; k < levels.size(); ++k) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%s LOD%zu %zu (screen coverage %g)", k ? "," : "", k, levels[k].triangles,
                  levels[k].screenCoverage);
    text += buf;
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, "; made in %.2f s", seconds);
  return text + buf;
}

/// The -o paths' extensions, and several -o only for surface meshes, each path once.
void checkOutputs(const MeshArgs& a) {
  for (const std::string& out : a.outs) requireExtension("-o", out, {".ply", ".obj", ".glb", ".msh", ".vtu", ".mesh"});
  if (a.outs.size() < 2) return;
  std::vector<std::filesystem::path> seen;
  for (const std::string& out : a.outs) {
    const std::string ext = lowerExtension(out);
    if (a.interfaces || (ext != ".ply" && ext != ".obj" && ext != ".glb"))
      throw UsageError("-o: several outputs are surface meshes (.ply, .obj, .glb) written from one build; '" + out +
                       "' is not" + (a.interfaces ? " (--interfaces writes one set of files)" : ""));
    const std::filesystem::path p = std::filesystem::weakly_canonical(out);
    if (std::find(seen.begin(), seen.end(), p) != seen.end()) throw UsageError("-o: '" + out + "' is given twice");
    seen.push_back(p);
  }
}

/// Simplifies the parts when asked (--simplify or the species' render.simplify); returns
/// the note's text ("" when not simplified).
std::string simplifyForMesh(std::vector<ExportPart>& parts, double simplify, const GlobalOptions& g) {
  std::string simplified;
  if (simplify <= 0) return simplified;
  std::vector<std::string> dropped;
  const std::vector<organisms::SimplifyReport> reports = simplifyParts(parts, simplify, &dropped);
  for (const std::string& name : dropped)
    note(g, std::cerr, "%s: simplified, so its texture atlas is dropped and its vertex colours kept", name.c_str());
  for (size_t i = 0; i < parts.size(); ++i) {
    if (reports[i].inputTriangles == 0) continue;
    char buf[160];
    std::snprintf(buf, sizeof buf, "%s%s %zu -> %zu (error %.3g)", simplified.empty() ? "" : ", ", parts[i].name.c_str(),
                  reports[i].inputTriangles, reports[i].faces, double(reports[i].absoluteError));
    simplified += buf;
  }
  return simplified;
}

/// The parts (comma-separated names, each once) whose levels carry a normal map on
/// coordinates of their own (normalMapOwnsUvs), which an OBJ cannot hold.
std::string ownUvNormalMaps(const std::vector<LodLevel>& levels) {
  std::string names;
  for (const ExportPart& p : levels.back().parts)
    if (normalMapOwnsUvs(p.material)) names += (names.empty() ? "" : ", ") + p.name;
  return names;
}

/// The notes on textures, creases and seams (written: the reports of one output) and on
/// cut-outs and clamped colours (glb: whether a .glb was written).
void noteParts(const std::vector<ExportPart>& parts, const std::vector<PartWriteReport>& written, bool glb, const GlobalOptions& g) {
  for (const PartWriteReport& r : written) {
    if (r.atlasCell > 0)
      note(g, std::cout, "%s: texture atlas %dx%d baked from the renderer's colours, %dx%d texels per triangle", r.name.c_str(),
           r.textureWidth, r.textureHeight, r.atlasCell, r.atlasCell);
    else if (r.textureWidth > 0)
      note(g, std::cout, "%s: texture %dx%d baked from the species' %s", r.name.c_str(), r.textureWidth, r.textureHeight,
           r.name == "wood"                                                                   ? "bark"
           : r.name.rfind("textured_leaves_", 0) == 0 || r.name.rfind("textured_wood_", 0) == 0 ? "cpfg texture"
                                                                                                : "shell texture");
    if (r.creaseVertices > 0 || r.seamCorners > 0)
      note(g, std::cout, "%s: %zu vertices split at creases (faces more than 90 degrees apart), %zu texture-seam uvs added",
           r.name.c_str(), r.creaseVertices, r.seamCorners);
  }
  for (const ExportPart& p : parts) {
    if (p.material.alphaCutoff < 0.0f || !p.material.texture || p.mesh.triangles.empty()) continue;
    const std::vector<float>& px = p.material.texture->pixels().pixels;
    size_t partial = 0;
    for (size_t i = 3; i < px.size(); i += 4) partial += px[i] > p.material.alphaCutoff && px[i] < 1.0f;
    note(g, std::cout, "%s: cut out where the texture's alpha is at or below %g (glTF alphaMode MASK, MTL map_d)%s", p.name.c_str(),
         p.material.alphaCutoff,
         partial ? (": " + std::to_string(partial) + " partly transparent texels are drawn opaque (renders blend them)").c_str() : "");
  }
  if (glb)
    for (const ExportPart& p : parts)
      if (size_t k = clampedColorChannels(p))
        note(g, std::cout, "%s: %zu vertex colour channels are brighter than the part's base colour and are clamped to it in COLOR_0",
             p.name.c_str(), k);
}

/// --wind's speed and direction (nullopt: not given, the species' wind). Throws UsageError
/// for a malformed value, or when no output is a .glb or with --interfaces.
std::optional<std::pair<double, double>> windFlag(const MeshArgs& a, bool anyGlb) {
  if (a.wind.empty()) return std::nullopt;
  double speed = 0, direction = 0;
  parseWind(a.wind, speed, direction);
  if (!anyGlb || a.interfaces)
    throw UsageError("--wind writes a tree's sway into glTF: give -o a .glb name (without --interfaces)");
  return std::make_pair(speed, direction);
}

/// The note on a tree's wind in its .glb (model/wind_export.h).
void noteWind(const std::vector<ExportPart>& top, const organisms::WindOptions& w, const GlobalOptions& g) {
  size_t targets = 0;
  for (const ExportPart& p : top) targets += p.morph ? p.morph->targets.size() : 0;
  if (w.speed > 0)
    note(g, std::cout, "wind %g m/s toward %g degrees: _WIND on every level's vertices; LOD0 sways in the animation 'wind' "
         "(%zu morph targets, a %g s loop at %d keyframes per second)", w.speed, w.directionDeg, targets, kWindLoopSeconds, kWindFps);
  else
    note(g, std::cout, "_WIND on every level's vertices (no wind: no sway animation; --wind SPEED[,DIRECTION] adds one)");
}

/// Which cell the wood was polygonized at for the levels (ModelFigures::lodCell), and why.
void noteWoodCell(const ModelFigures& fig, size_t meshTriangles, const GlobalOptions& g) {
  if (fig.lodCell > fig.autoCell)
    note(g, std::cout, "wood polygonized at cell %g (the automatic cell %g, at most %g) for about %zu triangles: LOD0 is simplified from it",
         double(fig.lodCell), double(fig.autoCell), double(fig.ceilingCell), meshTriangles);
  else if (fig.autoCell > 0)
    note(g, std::cout, "wood polygonized at the automatic cell %g (a coarser one for about %zu triangles would %s)", double(fig.autoCell),
         meshTriangles, fig.ceilingCell > fig.autoCell ? "give fewer than that" : "cut limbs it keeps whole");
}

int runMesh(const MeshArgs& a, const GlobalOptions& g) {
  checkOutputs(a);
  const std::string& out = a.outs.front();
  PhaseClock::declare({"read", "derive", "build", "polygonize", "levels", "write"});
  auto start = std::chrono::steady_clock::now();
  // Volume meshes (tetrahedra with materials) of kinds that have them, by extension.
  const std::string ext = lowerExtension(out);
  const bool volume = ext == ".msh" || ext == ".vtu" || ext == ".mesh";
  if (a.simplify > 0 && (a.interfaces || volume))
    throw UsageError("--simplify applies to the surface parts written as .ply, .obj or .glb, not to --interfaces or volume meshes");
  if (a.lod != "auto" && (a.interfaces || volume))
    throw UsageError("--lod applies to the surface parts written as .ply, .obj or .glb, not to --interfaces or volume meshes");
  lodBudget(a.lod, 0);  // a bad value fails before the build
  const bool anyGlb = std::any_of(a.outs.begin(), a.outs.end(), [](const std::string& o) { return lowerExtension(o) == ".glb"; });
  const std::optional<std::pair<double, double>> wind = windFlag(a, anyGlb);
  Species species = loadSpecies(a.file, g.pathPolicy());
  printNotes(g, species);
  if (!a.mesher.empty()) species.render.dualMesher = a.mesher == "dual";
  SpeciesModel model(species, a.growth.overrides());
  const Stage stage = a.stage.resolve(model);
  if (wind && !model.windSource(stage)) throw UsageError("--wind sways trees; " + speciesOfKind(species.kind) + " has no wind");
  if (a.interfaces) {
    if (volume)
      throw UsageError("--interfaces writes triangle meshes: give -o a .ply, .obj or .glb name");
    const std::filesystem::path outPath(out);
    for (auto& [name, mesh] : model.interfaceMeshes(stage)) {
      const std::filesystem::path path = outPath.parent_path() / (outPath.stem().string() + "_" + name + outPath.extension().string());
      MeshWriteOptions wopt;
      wopt.materialName = name;
      writeMesh(mesh, path, wopt);
      note(g, std::cout, "%s: %zu triangles, %zu vertices", path.string().c_str(), mesh.triangleCount(), mesh.vertexCount());
    }
    return kExitOk;
  }
  if (volume) {
    const std::string line = model.writeVolumeMesh(stage, out, !g.quiet);
    double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    note(g, std::cout, "%s (total %.2f s)", line.c_str(), total);
    return kExitOk;
  }
  ModelFigures fig;
  MeshCleanOptions clean;
  clean.minVolumeFraction = a.minVolume;
  // Built, cleaned and baked once, however many files are written.
  // With levels the full mesh is simplified away: polygonized at a coarser cell that still
  // gives LOD0 kLodCellMargin times its budget (not with --cell, nor --simplify's own error).
  const size_t budget = lodBudget(a.lod, model.lodBudget());
  const double simplify = a.simplify >= 0 ? a.simplify : species.render.simplify;
  const size_t meshTriangles = budget > 0 && !(a.cell > 0) && !(simplify > 0) ? budget * kLodCellMargin : 0;
  std::vector<ExportPart> parts = model.exportParts(stage, static_cast<float>(a.cell), !g.quiet, clean, &fig, meshTriangles);
  noteWoodCell(fig, meshTriangles, g);
  const std::string simplified = simplifyForMesh(parts, simplify, g);
  const ExportFinish finish = finishExportParts(parts);
  const size_t fullTriangles = partTriangles(parts);
  const auto lodStart = std::chrono::steady_clock::now();
  Vec3 moved(0.0f);  // LOD0 stood on the ground again
  LodMapReport maps;
  std::vector<LodLevel> levels = [&] {
    const Phase phase("levels");
    return lodLevels(std::move(parts), budget, &moved, &maps);
  }();
  const std::optional<organisms::WindOptions> windUsed =
      anyGlb ? addModelWind(model, stage, levels, finish.offset + moved, wind) : std::nullopt;
  const double lodSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - lodStart).count();
  const std::vector<ExportPart>& top = levels[0].parts;  // LOD0: the file's scene
  std::vector<PartWriteReport> written;
  std::string names, files, degenerate, lodFiles;
  bool glb = false;
  for (const std::string& o : a.outs) {
    std::vector<PartWriteReport> r = [&] {
      const Phase phase("write");
      return writeLevels(levels, o);
    }();
    if (written.empty() || lowerExtension(o) != ".ply") written = std::move(r);  // PLY has no textures to report
    files += (files.empty() ? "" : ", ") + o;
    if (levels.size() > 1)  // a .glb's LOD0 has its own file too (writeLevels)
      for (size_t k = lowerExtension(o) == ".glb" ? 0 : 1; k < levels.size(); ++k)
        lodFiles += (lodFiles.empty() ? "" : ", ") + lodPath(o, k).string();
    glb = glb || lowerExtension(o) == ".glb";
    if (const std::string own = ownUvNormalMaps(levels); lowerExtension(o) == ".obj" && !own.empty())
      note(g, std::cout, "%s: no normal maps for %s: OBJ gives a corner one uv, and their normal maps have coordinates of their own (TEXCOORD_1 in .glb)",
           o.c_str(), own.c_str());
  }
  double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  size_t vertices = 0, triangles = 0;
  for (size_t i = 0; i < top.size(); ++i) {
    const ExportPart& p = top[i];
    if (const DegenerateReport& d = finish.removed[i]; d.total() > 0)
      degenerate += (degenerate.empty() ? "" : ", ") + p.name + " " + std::to_string(d.total()) + " (" +
                    std::to_string(d.repeatedIndex) + " with a repeated corner)";
    if (p.mesh.triangles.empty()) continue;
    vertices += p.mesh.vertexCount();
    triangles += p.mesh.triangleCount();
    names += (names.empty() ? "" : ", ") + p.name + " " + std::to_string(p.mesh.triangleCount());
  }
  note(g, std::cout, "%s: %zu triangles, %zu vertices, %zu primitives, built in %.2f s (total %.2f s)", files.c_str(),
       triangles, vertices, fig.primitives, fig.buildSeconds, total);
  note(g, std::cout, "parts: %s", names.c_str());
  if (!simplified.empty()) note(g, std::cout, "simplified to %g of the model's extent: %s", simplify, simplified.c_str());
  const MeshCleanReport& c = fig.clean;
  if (c.componentsBefore > 0)
    note(g, std::cout, "cleaned: %zu components -> %zu (%zu specks, %zu voids, %zu triangles removed); %zu faces against their normals -> %zu (%zu normals fixed)",
         c.componentsBefore, c.componentsAfter, c.specks, c.voids, c.removedTriangles, c.facesAgainstBefore,
         c.facesAgainstAfter, c.fixedNormals);
  if (!degenerate.empty()) note(g, std::cout, "degenerate triangles removed (zero area or a repeated corner): %s", degenerate.c_str());
  note(g, std::cout, "placed: moved by (%g, %g, %g) to stand at the origin (lowest y = 0, centred in x and z; metres)",
       double(finish.offset.x + moved.x), double(finish.offset.y + moved.y), double(finish.offset.z + moved.z));
  if (const std::string t = lodNote(levels, budget, fullTriangles, lodSeconds); !t.empty()) {
    note(g, std::cout, "%s", t.c_str());
    note(g, std::cout, "each level's own file: %s%s", lodFiles.c_str(),
         glb ? "; the .glb holds every level (MSFT_lod); --lod none writes the full mesh alone" : "");
    if (maps.maps > 0)
      note(g, std::cout, "detail maps: %zu parts' levels got a normal map, and the full mesh's colours where they have no image of their own (%zu texels, %.1f%% on the full surface) in %.2f s",
           maps.maps, maps.texels, 100.0 * double(maps.hits) / double(std::max<size_t>(maps.texels, 1)), maps.seconds);
  }
  noteParts(top, written, glb, g);
  if (windUsed) noteWind(top, *windUsed, g);
  return kExitOk;
}

}  // namespace

void addMeshCommand(CLI::App& app, const GlobalOptions& global, CommandRun& run) {
  auto [sub, args] = subcommand<MeshArgs>(app, global, run, "mesh",
                                          "Polygonize a species' surface into a closed triangle mesh (.ply, .obj, .glb), or write a solid's tetrahedra (.msh, .vtu, .mesh)", runMesh);
  addInputOutputs(*sub, "SPECIES", args->file, args->outs,
                  "output mesh (.ply, .obj + .mtl, .glb; solids also .msh, .vtu, .mesh); give -o several times to write "
                  "several surface meshes from one build and bake");
  sub->add_option("--cell", args->cell, "cell edge length in model units (default: automatic, from the smallest feature)")
      ->check(CLI::PositiveNumber);
  sub->add_flag("--interfaces", args->interfaces,
                 "solids: write each interface between two materials, and each material's outer surface, as OUT_<A>_<B>.EXT "
                 "(triangles oriented out of A; B = outside for the visible interface)");
  sub->add_option("--mesher", args->mesher,
                  "polygonized surfaces: tetrahedra (marching tetrahedra, the reference) or dual (dual marching cubes, "
                  "about a third of the triangles); default: the species' render.mesher")
      ->check(CLI::IsMember({"tetrahedra", "dual"}));
  sub->add_option("--min-volume", args->minVolume,
                  "remove connected components of a polygonized surface whose enclosed volume is below this fraction of the model's "
                  "(specks outside, voids inside); 0 keeps them")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  sub->add_option("--simplify", args->simplify,
                  "collapse edges of the polygonized parts while the geometric error stays below this fraction of the model's "
                  "extent (meshoptimizer; e.g. 1e-3); closed parts stay closed and manifold; 0 keeps every triangle; "
                  "default: the species' render.simplify (0)")
      ->check(CLI::Range(0.0, 0.1));
  sub->add_option("--lod", args->lod,
                  "levels of detail: auto (trees 300000, shells and organisms 250000 triangles at LOD0, then a quarter "
                  "per level; blobs and solids none), none (the full mesh alone), or LOD0's triangle budget; writes "
                  "OUT_lod1.EXT, ... beside OUT and, in .glb, every level through MSFT_lod (docs/MESHES.md)")
      ->capture_default_str();
  sub->add_option("--wind", args->wind,
                  "SPEED[,DIRECTION]: trees in .glb: sway LOD0 in wind of SPEED m/s blowing toward azimuth DIRECTION degrees "
                  "(0 = toward +Z) as morph targets and a looping animation 'wind' (docs/MESHES.md \"Wind\"); default: the "
                  "species' wind; 0 writes no animation (every tree .glb carries the _WIND vertex attribute)");
  addStageFlags(*sub, args->stage);
  addGrowthFlags(*sub, args->growth);
}

}  // namespace sprig
