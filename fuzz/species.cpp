/// Fuzz target: the species reader of one kind (SPRIG_FUZZ_KIND: tree, shell, blob,
/// organism, solid); the input is the file without its `kind:` line, which the target prepends.
///
/// File access is sandboxed: the species is read as /sprig-fuzz-sandbox/s.yaml with the
/// library root /sprig-fuzz-sandbox, a folder that does not exist, so every referenced file
/// (grammar, mesh base, texture, species base) is refused or missing and nothing outside
/// the input is ever read.
#include <string>

#include "fuzz/fuzz.h"
#include "model/species.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > sprig::fuzz::kMaxInput) return 0;
  std::string text = std::string("kind: ") + SPRIG_FUZZ_KIND + "\n";
  text += sprig::fuzz::text(data, size);
  sprig::PathPolicy policy;
  policy.root = "/sprig-fuzz-sandbox";
  try {
    sprig::parseSpecies(std::move(text), "/sprig-fuzz-sandbox/s.yaml", policy);
  } catch (const sprig::InputError&) {
  }
  return 0;
}
