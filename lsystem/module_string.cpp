#include "lsystem/module_string.h"

#include <stdexcept>

namespace sprig::lsystem {

SymbolId SymbolTable::intern(std::string_view name) {
  auto it = ids_.find(std::string(name));
  if (it != ids_.end()) return it->second;
  if (names_.size() >= 65535) throw std::length_error("too many module symbols (at most 65535)");
  auto id = static_cast<SymbolId>(names_.size());
  names_.emplace_back(name);
  ids_.emplace(names_.back(), id);
  return id;
}

int SymbolTable::find(std::string_view name) const {
  auto it = ids_.find(std::string(name));
  return it == ids_.end() ? -1 : it->second;
}

}  // namespace sprig::lsystem
