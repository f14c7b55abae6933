#include "lsystem/grammar.h"

#include "core/atomic_file.h"
#include "lsystem/detail/grammar_parser.h"
#include "lsystem/detail/program.h"

namespace sprig::lsystem {

Grammar::Grammar() : program_(std::make_shared<detail::Program>()) {}

const std::string& Grammar::name() const { return program_->name; }
const std::string& Grammar::fileName() const { return program_->fileName; }
int Grammar::derivationLength() const { return program_->derivationLength; }
uint64_t Grammar::seed() const { return program_->seed; }
std::optional<double> Grammar::angleDeg() const {
  return program_->hasAngle ? std::optional<double>(program_->angleDeg) : std::nullopt;
}
const SymbolTable& Grammar::symbols() const { return program_->symbols; }
const ModuleString& Grammar::axiom() const { return program_->axiom; }
std::shared_ptr<const std::vector<std::string>> Grammar::strings() const {
  return std::shared_ptr<const std::vector<std::string>>(program_, &program_->strings);
}
std::optional<double> Grammar::define(std::string_view name) const {
  for (auto& [n, v] : program_->defines)
    if (n == name) return v;
  return std::nullopt;
}
std::vector<std::string> Grammar::defineNames() const {
  std::vector<std::string> names;
  for (auto& [n, v] : program_->defines) names.push_back(n);
  return names;
}
size_t Grammar::productionCount() const { return program_->productions.productions.size(); }
bool Grammar::hasInterpretation() const { return program_->anyInterpretation(); }
bool Grammar::cpfgNotation() const { return program_->dialect == detail::Dialect::Cpfg; }
bool Grammar::usesDefaultAngle() const { return program_->bareTurn; }
const std::vector<Diagnostic>& Grammar::warnings() const { return program_->warnings; }

Grammar parseGrammar(std::string_view text, const std::string& fileName, const GrammarOverrides& overrides) {
  Grammar g;
  g.program_ = detail::compileGrammar(text, fileName, overrides);
  return g;
}

Grammar loadGrammar(const std::string& path, const GrammarOverrides& overrides) {
  std::string text;
  try {
    text = readFile(path);
  } catch (const FileReadError& e) {
    throw InputError(SourceLoc{path, 0, 0}, e.reason());
  }
  return parseGrammar(text, path, overrides);
}

ModuleString parseModuleString(std::string_view text, SymbolTable& symbols, const std::string& fileName) {
  return detail::compileModuleString(text, symbols, fileName);
}

}  // namespace sprig::lsystem

