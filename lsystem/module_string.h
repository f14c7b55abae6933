#pragma once
/// The module string: structure of arrays, no heap object per module.
///
/// Module i has symbol id symbols[i] and parameters params[offsets[i] .. offsets[i+1]).
/// Derivation rewrites one ModuleString into a second buffer each step (clear() keeps
/// capacity). Symbol ids index a SymbolTable: built-in turtle symbols first, then the
/// grammar's own symbols in order of appearance.
///
/// birthSteps is optional: empty unless the derivation was asked to track the step that
/// created each module (DeriveOptions::trackBirthSteps); then it has size() entries.

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace sprig::lsystem {

using SymbolId = uint16_t;

/// Names of every module symbol a grammar uses ("F", "+", "Apex", ...).
class SymbolTable {
 public:
  /// The id of name, adding it when new.
  SymbolId intern(std::string_view name);
  /// The id of name, or -1 when absent.
  int find(std::string_view name) const;
  const std::string& name(SymbolId id) const { return names_[id]; }
  size_t size() const { return names_.size(); }

 private:
  std::vector<std::string> names_;
  std::unordered_map<std::string, SymbolId> ids_;
  /// Ids of one-character names by their byte (-1: not interned), so the common symbol is
  /// found without hashing a string (an 8-million-module axiom interns every module).
  std::array<int32_t, 256> single_ = [] {
    std::array<int32_t, 256> a{};
    a.fill(-1);
    return a;
  }();
};

struct ModuleString {
  std::vector<SymbolId> symbols;
  std::vector<uint32_t> offsets{0};  ///< size() + 1 entries
  std::vector<double> params;
  std::vector<int32_t> birthSteps;  ///< empty, or the creating step of each module (0 = axiom)

  /// True when birthSteps holds one entry per module.
  bool hasBirthSteps() const { return !symbols.empty() && birthSteps.size() == symbols.size(); }
  /// The step that created module i, or 0 when birth steps are not tracked.
  int32_t birthStep(size_t i) const { return i < birthSteps.size() ? birthSteps[i] : 0; }
  size_t size() const { return symbols.size(); }
  bool empty() const { return symbols.empty(); }
  void clear() {
    symbols.clear();
    offsets.assign(1, 0);
    params.clear();
    birthSteps.clear();
  }
  void reserve(size_t modules, size_t parameters) {
    symbols.reserve(modules);
    offsets.reserve(modules + 1);
    params.reserve(parameters);
  }
  uint32_t paramCount(size_t i) const { return offsets[i + 1] - offsets[i]; }
  std::span<const double> paramsOf(size_t i) const { return {params.data() + offsets[i], paramCount(i)}; }
  /// Appends one module (birthSteps is left alone; callers tracking births push there too).
  void push(SymbolId s, std::span<const double> p = {}) {
    symbols.push_back(s);
    params.insert(params.end(), p.begin(), p.end());
    offsets.push_back(static_cast<uint32_t>(params.size()));
  }
};

}  // namespace sprig::lsystem
