#pragma once
/// The parser of a whole `.lsys` file: its sections (headers, `#define`s, `module`
/// declarations, the main, decomposition and interpretation blocks) and its productions,
/// compiled into a Program. Private to lsystem/; lsystem/grammar.cpp is its only caller.

#include <memory>
#include <string>
#include <string_view>

#include "lsystem/detail/program.h"
#include "lsystem/grammar.h"

namespace sprig::lsystem::detail {

/// Parses and compiles text (named fileName in diagnostics) with overrides applied.
/// Collects every error and throws them together as one InputError.
std::shared_ptr<Program> compileGrammar(std::string_view text, const std::string& fileName, const GrammarOverrides& overrides);

/// Tokenizes text as a module string whose parameters are constant expressions,
/// interning new symbols into symbols. Throws InputError (positions in fileName).
ModuleString compileModuleString(std::string_view text, SymbolTable& symbols, const std::string& fileName);

}  // namespace sprig::lsystem::detail
