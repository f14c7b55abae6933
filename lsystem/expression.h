#pragma once
/// Arithmetic expressions of named variables outside a grammar (a profile `r(t)` of a
/// surface of revolution), in the grammar's own expression language (docs/GRAMMAR.md:
/// operators, `sin`, `cos`, `sqrt`, `min`, ...; trigonometric functions take and return
/// degrees, as in cpfg). Two names are predefined: `pi` and `deg` (= 180/pi, so
/// `sin(deg*t)` is the sine of t radians).

#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include "core/diagnostics.h"

namespace sprig::lsystem {

namespace detail {
struct Instr;
}

/// A compiled expression of a fixed list of variables. Immutable; thread-safe to evaluate.
class Expression {
 public:
  /// Compiles text with the variables `variables` (in call order). `at` is where the text
  /// starts in the user's file (errors point into it: line at.line, column at.col + offset);
  /// sourceLine is that line, for the caret. Throws InputError for a syntax error, an
  /// unknown name, a random draw (`ran`, `nran`) or a constant that is not finite.
  static Expression compile(std::string_view text, const std::vector<std::string>& variables, const SourceLoc& at,
                            const std::string& sourceLine = {});

  /// The value at the variables' values (as many as compile's list). Not checked for
  /// finiteness: callers check what they need.
  double operator()(std::initializer_list<double> values) const;

  Expression();
  ~Expression();
  Expression(const Expression&);
  Expression& operator=(const Expression&);

 private:
  std::vector<detail::Instr> code_;
  size_t variables_ = 0;
};

}  // namespace sprig::lsystem
