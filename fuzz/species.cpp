/// Fuzz target: the species reader of one kind (SPRIG_FUZZ_KIND: tree, shell, blob,
/// organism, solid) as `sprig check` runs it; the input is the file without its `kind:`
/// line, which the target prepends. A species read without an error must have its kind's
/// value (check prints its summary); an organism small enough is also built (subdivided,
/// its detail synthesized), so degenerate base meshes reach the subdivision.
///
/// Files the species names travel in the input: after the YAML, each line `#%file NAME`
/// (a YAML comment; NAME 1 to 32 of a-z, 0-9, '_', '-', '.', not starting with '.')
/// starts a file that runs to the next such line or the end. They are written into a
/// private folder of this process (made once, emptied for every input) which is the
/// library root, and the species is read as FOLDER/s.yaml: a base mesh (`file: base.obj`),
/// an extrude_2d image (a PPM is text) or a grammar is reached, and nothing outside the
/// input ever is (the sandbox refuses every path outside the folder).
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "fuzz/fuzz.h"
#include "model/model.h"
#include "model/organism_kind.h"
#include "model/species.h"

namespace {

namespace fs = std::filesystem;

/// Finest faces an organism may have to be built here (a build of this size takes about a
/// millisecond).
constexpr size_t kMaxBuiltFaces = 4096;

/// The private folder, removed with everything in it when the process exits.
struct Sandbox {
  fs::path dir;
  Sandbox() {
    std::string pattern = (fs::temp_directory_path() / "sprig-fuzz-species-XXXXXX").string();
    if (!mkdtemp(pattern.data())) std::abort();
    dir = pattern;
  }
  ~Sandbox() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

const fs::path& sandbox() {
  static const Sandbox s;
  return s.dir;
}

bool validName(std::string_view name) {
  if (name.empty() || name.size() > 32 || name[0] == '.' || name == "s.yaml") return false;
  for (char c : name)
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-' || c == '.')) return false;
  return true;
}

/// Writes the files of text (after its first `#%file` line) into the sandbox; returns the
/// species text before them.
std::string_view writeFiles(std::string_view text) {
  constexpr std::string_view kMark = "#%file ";
  size_t at = text.rfind(kMark, 0) == 0 ? 0 : text.find("\n" + std::string(kMark));
  const std::string_view species = text.substr(0, at == std::string_view::npos ? text.size() : at);
  while (at != std::string_view::npos) {
    const size_t nameStart = at + (text[at] == '\n' ? 1 : 0) + kMark.size();
    const size_t lineEnd = text.find('\n', nameStart);
    if (lineEnd == std::string_view::npos) break;
    const std::string_view name = text.substr(nameStart, lineEnd - nameStart);
    const size_t next = text.find("\n" + std::string(kMark), lineEnd);
    const std::string_view body = text.substr(lineEnd + 1, next == std::string_view::npos ? std::string_view::npos : next - lineEnd - 1);
    if (validName(name)) {
      std::ofstream out(sandbox() / std::string(name), std::ios::binary | std::ios::trunc);
      out.write(body.data(), std::streamsize(body.size()));
    }
    at = next;
  }
  return species;
}

void buildSmallOrganism(const sprig::Species& s) {
  const auto* spec = dynamic_cast<const sprig::OrganismSpec*>(s.spec.get());
  if (!spec || sprig::finestFaceCount(spec->base, spec->levels) > kMaxBuiltFaces) return;
  sprig::SpeciesModel model(s);
  model.buildMesh(model.finalStage(), 0.0f, false);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > sprig::fuzz::kMaxInput) return 0;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(sandbox(), ec)) fs::remove(e.path(), ec);
  const std::string_view species = writeFiles(sprig::fuzz::text(data, size));
  std::string text = std::string("kind: ") + SPRIG_FUZZ_KIND + "\n";
  text += species;
  sprig::PathPolicy policy;
  policy.root = sandbox().string();
  try {
    const sprig::Species s = sprig::parseSpecies(std::move(text), (sandbox() / "s.yaml").string(), policy);
    // A species read without an error has its kind's value: `sprig check` prints its summary.
    if (!s.spec) std::abort();
    s.spec->checkSummary(s);
    buildSmallOrganism(s);
  } catch (const sprig::InputError&) {
  } catch (const sprig::UsageError&) {
  }
  return 0;
}
