#include "lsystem/module_string.h"

#include <stdexcept>

namespace sprig::lsystem {

SymbolId SymbolTable::intern(std::string_view name) {
  const bool one = name.size() == 1;
  if (one && single_[static_cast<unsigned char>(name[0])] >= 0) return static_cast<SymbolId>(single_[static_cast<unsigned char>(name[0])]);
  auto it = ids_.find(std::string(name));
  if (it != ids_.end()) return it->second;
  if (names_.size() >= 65535) throw std::length_error("too many module symbols (at most 65535)");
  auto id = static_cast<SymbolId>(names_.size());
  names_.emplace_back(name);
  ids_.emplace(names_.back(), id);
  if (one) single_[static_cast<unsigned char>(name[0])] = id;
  return id;
}

int SymbolTable::find(std::string_view name) const {
  if (name.size() == 1 && single_[static_cast<unsigned char>(name[0])] >= 0) return single_[static_cast<unsigned char>(name[0])];
  auto it = ids_.find(std::string(name));
  return it == ids_.end() ? -1 : it->second;
}

}  // namespace sprig::lsystem
