#pragma once
/// Comparing a string Sprig derived with one the real cpfg wrote (`cpfg -str`), for the
/// parity tests (tests/assets/cpfg/parity/, tests/assets/cpfg/enviro/).

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/atomic_file.h"
#include "lsystem/derive.h"
#include "lsystem/grammar.h"

namespace sprig::test {

/// cpfg's string file: `%g` parameters, lines wrapped at 70 characters between any two
/// characters of cpfg's (so `?` and `P` of `?P` may be on two lines): the lines joined.
inline std::string readCpfgString(const std::string& path) {
  std::string text = readFile(path), out;
  for (char c : text)
    if (c != '\n' && c != '\r') out += c;
  return out;
}

/// Compares Sprig's string with cpfg's: the same modules, parameters within 1e-5 (relative
/// or absolute: cpfg prints 6 significant digits).
inline void checkSameAsCpfg(const lsystem::ModuleString& got, const lsystem::SymbolTable& symbols, const std::string& cpfg) {
  lsystem::SymbolTable table = symbols;
  const lsystem::ModuleString want = lsystem::parseModuleString(cpfg, table, "cpfg.l");  // read in cpfg's notation
  INFO("cpfg:  " << cpfg);
  INFO("Sprig: " << lsystem::formatModuleString(got, symbols, lsystem::FormatOptions{0, true}));
  REQUIRE(got.size() == want.size());
  for (size_t i = 0; i < got.size(); ++i) {
    INFO("module " << i);
    REQUIRE(symbols.name(got.symbols[i]) == table.name(want.symbols[i]));
    REQUIRE(got.paramCount(i) == want.paramCount(i));
    for (uint32_t k = 0; k < got.paramCount(i); ++k) {
      const double a = got.paramsOf(i)[k], b = want.paramsOf(i)[k];
      CHECK(std::fabs(a - b) <= 1e-5 * std::max(1.0, std::fabs(b)));
    }
  }
}

}  // namespace sprig::test
