#include "lsystem/expression.h"

#include <unordered_map>

#include "core/types.h"
#include "lsystem/detail/expression_parser.h"
#include "lsystem/detail/program.h"
#include "lsystem/detail/scanner.h"

namespace sprig::lsystem {

Expression::Expression() = default;
Expression::~Expression() = default;
Expression::Expression(const Expression&) = default;
Expression& Expression::operator=(const Expression&) = default;

Expression Expression::compile(std::string_view text, const std::vector<std::string>& variables, const SourceLoc& at,
                               const std::string& sourceLine) {
  if (variables.size() > size_t(detail::kMaxVars))
    throw InputError(at, "an expression takes at most " + std::to_string(detail::kMaxVars) + " variables", sourceLine);
  if (text.find('\n') != std::string_view::npos)
    throw InputError(at, "an expression must be on one line", sourceLine);
  static const std::unordered_map<std::string, double> kDefines = {{"pi", kPi}, {"deg", 180.0 / kPi}};
  detail::Scanner scanner(at.file);
  scanner.load(text);
  Expression e;
  e.variables_ = variables.size();
  detail::ExpressionParser parser(scanner, kDefines, e.code_);
  const detail::Span all{1, 0, int(text.size())};
  const bool ok = parser.compile(all, variables, "expression");
  if (ok && parser.usesRandom()) scanner.error(1, 0, "random draws (ran, nran) are not allowed in this expression");
  if (!ok || scanner.diagnostics().hasErrors()) {
    // Move the positions from the expression's own text into the user's file.
    std::vector<Diagnostic> ds;
    for (Diagnostic d : scanner.diagnostics().items()) {
      d.loc.line = at.line;
      d.loc.col = at.col + std::max(d.loc.col, 1) - 1;
      d.sourceLine = sourceLine;
      ds.push_back(std::move(d));
    }
    throw InputError(std::move(ds));
  }
  return e;
}

double Expression::operator()(std::initializer_list<double> values) const {
  double vars[detail::kMaxVars] = {};
  size_t i = 0;
  for (double v : values)
    if (i < size_t(detail::kMaxVars)) vars[i++] = v;
  return detail::evalCode(code_.data(), code_.data() + code_.size(), vars, nullptr);
}

}  // namespace sprig::lsystem
