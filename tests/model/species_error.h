#pragma once
/// The error text of a species file written inline in a test.

#include <string>

#include "core/diagnostics.h"
#include "model/species.h"

namespace sprig::test {

/// What parseSpecies throws for text read as the file displayPath (empty when it loads).
inline std::string speciesError(const std::string& text, const std::string& displayPath) {
  try {
    parseSpecies(text, displayPath);
  } catch (const InputError& e) {
    return e.what();
  }
  return {};
}

}  // namespace sprig::test
