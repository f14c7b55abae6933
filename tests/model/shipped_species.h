#pragma once
// The shipped species (species/*.yaml) for the hidden sweeps over all of them.

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fnmatch.h>
#include <sstream>
#include <string>
#include <vector>

namespace sprig::test {

// The stems of species/*.yaml under root, sorted. SPRIG_ALL_SPECIES, when set, keeps the
// stems that match one of its comma-separated shell globs (`SPRIG_ALL_SPECIES='solid_*,
// fig_solid_*'`, `SPRIG_ALL_SPECIES=shell_top,abop_2_8`).
inline std::vector<std::string> shippedSpecies(const std::string& root) {
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(root + "/species"))
    if (e.path().extension() == ".yaml") files.push_back(e.path().stem().string());
  std::sort(files.begin(), files.end());
  const char* only = std::getenv("SPRIG_ALL_SPECIES");
  if (!only || !*only) return files;
  std::vector<std::string> patterns;
  std::stringstream list(only);
  for (std::string p; std::getline(list, p, ',');)
    if (!p.empty()) patterns.push_back(p);
  files.erase(std::remove_if(files.begin(), files.end(),
                             [&](const std::string& stem) {
                               return std::none_of(patterns.begin(), patterns.end(),
                                                   [&](const std::string& p) { return fnmatch(p.c_str(), stem.c_str(), 0) == 0; });
                             }),
              files.end());
  return files;
}

}  // namespace sprig::test
