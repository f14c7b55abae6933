/// Helpers shared by the subcommands: output extension checks and `-D NAME=VALUE` parsing.

#include "app/cmd_common.h"

#include <iostream>
#include <sstream>

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <charconv>
#include <cmath>
#include <filesystem>

#include "core/paths.h"

namespace sprig {

void requireExtension(const std::string& flag, const std::string& path, std::initializer_list<const char*> allowed) {
  const std::string ext = lowerExtension(path);
  std::string list;
  for (const char* a : allowed) {
    if (ext == a) return;
    list += std::string(list.empty() ? "" : ", ") + a;
  }
  throw UsageError(flag + ": unknown output extension '" + std::filesystem::path(path).extension().string() +
                   "' for '" + path + "' (use " + list + ")");
}


lsystem::GrammarOverrides commandLineOverrides(const std::vector<std::string>& defines, int steps, int64_t seed) {
  lsystem::GrammarOverrides o;
  for (const std::string& d : defines) {
    size_t eq = d.find('=');
    std::string name = eq == std::string::npos ? std::string() : d.substr(0, eq);
    auto value = eq == std::string::npos ? std::nullopt : parseFiniteNumber(std::string_view(d).substr(eq + 1));
    bool nameOk = !name.empty() && std::all_of(name.begin(), name.end(), [](unsigned char c) {
      return std::isalnum(c) || c == '_';
    });
    if (!nameOk || !value)
      throw UsageError("-D " + d + ": expected NAME=VALUE with a finite number, e.g. -D LENGTH=2.5");
    o.defines.push_back(lsystem::DefineOverride{name, *value, SourceLoc{"-D " + d, 0, 0}});
  }
  if (steps >= 0) o.derivationLength = steps;
  if (seed >= 0) o.seed = static_cast<uint64_t>(seed);
  return o;
}

/// Parses `AZ,EL` or `AZ,EL,FOV` (degrees) into view.
void parseWind(const std::string& text, double& speed, double& direction) {
  const size_t comma = text.find(',');
  auto s = parseFiniteNumber(text.substr(0, comma));
  std::optional<double> d = 0.0;
  if (comma != std::string::npos) d = parseFiniteNumber(text.substr(comma + 1));
  if (!s || *s < 0 || *s > 60 || !d || *d < -360 || *d > 360)
    throw UsageError("--wind " + text + ": expected SPEED[,DIRECTION] with 0 <= SPEED <= 60 (m/s) and -360 <= DIRECTION <= 360 (degrees)");
  speed = *s;
  direction = *d;
}

void parseView(const std::string& text, render::ViewSpec& view) {
  std::vector<double> values;
  std::stringstream ss(text);
  std::string part;
  while (std::getline(ss, part, ',')) {
    auto v = parseFiniteNumber(part);
    if (!v) values.clear(), values.push_back(1e300);
    else values.push_back(*v);
  }
  bool ok = (values.size() == 2 || values.size() == 3) && values[0] >= -360 && values[0] <= 360 &&
            values[1] >= -89 && values[1] <= 89 && (values.size() == 2 || (values[2] >= 1 && values[2] <= 150));
  if (!ok)
    throw UsageError("--view " + text + ": expected AZIMUTH,ELEVATION[,FOV] in degrees (elevation in [-89, 89], fov in [1, 150])");
  view.azimuthDeg = values[0];
  view.elevationDeg = values[1];
  if (values.size() == 3) view.fovYDeg = values[2];
}

lsystem::GrammarOverrides GrowthFlags::overrides() const {
  lsystem::GrammarOverrides o = commandLineOverrides(defines, steps, seed);
  o.cpfgEnvironment = environment;
  o.cpfgEnvironmentTimeout = environmentTimeout;
  return o;
}

void addGrowthFlags(CLI::App& sub, GrowthFlags& flags) {
  sub.add_option("-e,--environment", flags.environment,
                 "cpfg's environment file (FILE.e): run its environmental program for the ?E modules");
  sub.add_option("--enviro-timeout", flags.environmentTimeout,
                 "seconds to wait for the environmental program to start or answer (default 60)")
      ->check(CLI::Range(0.1, 86400.0));
  sub.add_option("--steps", flags.steps, "derivation steps (trees; default: the species' or grammar's)")
      ->check(CLI::Range(0, 100000));
  sub.add_option("--seed", flags.seed, "random seed (trees; default: the species' or grammar's)")
      ->check(CLI::NonNegativeNumber);
  sub.add_option("-D,--define", flags.defines, "override a #define: NAME=VALUE (repeatable)");
}

void addStageFlags(CLI::App& sub, StageFlags& flags) {
  sub.add_option("--stage", flags.stage, "tree: derivation step; shell: number of whorls grown; solid: after the first k operations")
      ->check(CLI::Range(0, 100000));
  sub.add_option("--fraction", flags.fraction, "tree: growth of the stage's newest modules, 0..1 (default 1)")
      ->check(CLI::Range(0.0, 1.0));
  sub.add_option("--age", flags.age, "shell: age θ_end in degrees (default: the species' age)")
      ->check(CLI::Range(1.0, 1e6));
}

Stage StageFlags::resolve(const SpeciesModel& model) const {
  Stage s = stage >= 0 ? model.stageFromIndex(stage) : model.finalStage();
  s.fraction = fraction;
  if (age >= 0) s.age = model.stageAtAge(age).age;
  return s;
}

namespace {

/// The folder the output goes into must exist before any work starts (a folder output,
/// `frames/`, may itself be new: its parent must exist).
const CLI::Validator& outputFolderExists() {
  static const CLI::Validator v(
      [](std::string& value) -> std::string {
        std::string trimmed = value;
        while (trimmed.size() > 1 && trimmed.back() == '/') trimmed.pop_back();
        const std::filesystem::path parent = std::filesystem::path(trimmed).parent_path();
        std::error_code ec;
        if (parent.empty() || std::filesystem::is_directory(parent, ec)) return {};
        return "folder '" + parent.string() + "' does not exist";
      },
      "", "output folder exists");
  return v;
}

}  // namespace

void addInputOutput(CLI::App& sub, const char* name, std::string& file, std::string& out, const char* outputHelp) {
  sub.add_option(name, file, "species file (.yaml), grammar (.lsys, cpfg's .l) or vlab object folder")->required();
  sub.add_option("-o,--output", out, outputHelp)->required()->check(outputFolderExists());
}

void addInputOutputs(CLI::App& sub, const char* name, std::string& file, std::vector<std::string>& outs, const char* outputHelp) {
  sub.add_option(name, file, "species file (.yaml), grammar (.lsys, cpfg's .l) or vlab object folder")->required();
  sub.add_option("-o,--output", outs, outputHelp)->required()->allow_extra_args(false)->check(outputFolderExists());
}

void printNotes(const GlobalOptions& g, const Species& species) {
  if (g.strict) {
    std::vector<Diagnostic> errors;
    for (Diagnostic d : species.notes)
      if (d.severity == Severity::Warning) {
        d.severity = Severity::Error;
        errors.push_back(std::move(d));
      }
    if (!errors.empty()) throw InputError(std::move(errors));
  }
  if (g.quiet) return;
  for (const Diagnostic& d : species.notes) std::cerr << d.format() << "\n";
}

void note(const GlobalOptions& g, std::ostream& os, const char* format, ...) {
  if (g.quiet) return;
  char line[1024];
  va_list args;
  va_start(args, format);
  std::vsnprintf(line, sizeof line, format, args);
  va_end(args);
  os << line << "\n";
}

}  // namespace sprig
