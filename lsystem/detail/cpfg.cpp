#include "lsystem/detail/cpfg.h"

#include <algorithm>
#include <iterator>

namespace sprig::lsystem::detail {

namespace {

/// A cpfg command Sprig reads as one module but does not implement, with what it does.
struct Unsupported {
  const char* name;
  const char* what;
};

constexpr Unsupported kUnsupported[] = {
    {"@bo", "circle boundary"},
    {"@bc", "circle boundary"},
    {"@PS", "L-system defined surface patch"},
    {"@PC", "L-system defined surface patch"},
    {"@PD", "L-system defined surface patch"},
    {"@S", "system call"},
    {"@I", "rayshade object"},
    {"@J", "rayshade grid"},
    {"@mo", "rayshade object"},
    {"@mc", "conditional cut"},
    {"@;", "back-side color"},
    {"@,", "back-side color"},
};

}  // namespace

const char* const kCpfgMultiNames[] = {
    "@Gs", "@Gc", "@Ge", "@Gt", "@Gr", "@Ts", "@Ti", "@Td", "@Tp", "@Tf", "@Tx", "@bo", "@bc", "@PS",
    "@PC", "@PD", "@Di", "@Dd", "@mo", "@mc", "@O",  "@o",  "@c",  "@v",  "@R",  "@M",  "@L",  "@S",
    "@I",  "@J",  "@D",  "@#",  "@!",  "@;",  "@,",  "?P",  "?H",  "?L",  "?U",  "?E",
};
const size_t kCpfgMultiNameCount = std::size(kCpfgMultiNames);

Dialect dialectOf(std::string_view fileName) {
  return fileName.size() > 2 && fileName.substr(fileName.size() - 2) == ".l" ? Dialect::Cpfg : Dialect::Sprig;
}

std::optional<std::string> cpfgUnsupported(std::string_view name, size_t args, bool hasParens, char next,
                                           Dialect dialect) {
  auto notSupported = [&](std::string_view shown, const char* what) {
    return "cpfg's '" + std::string(shown) + "' (" + what + ") is not supported";
  };
  for (const Unsupported& u : kUnsupported)
    if (name == u.name) return notSupported(name, u.what);
  if (name == "@L" && dialect != Dialect::Cpfg) return notSupported(name, "label");
  if (name == "@Tx" && dialect != Dialect::Cpfg)
    return std::string("cpfg's '@Tx' (texture) is supported only in cpfg's notation (a .l file), with a view file's 'texture:' lines");
  if (name == "@") {
    std::string shown = "@";
    if (next && next != '(' && next != ' ' && next != '\t') shown += next;
    return "unknown cpfg command '" + shown + "'";
  }
  if (name == "?") {
    if (!hasParens || args == 0) {
      // cpfg's '?' without parameters: an ordinary module; its turtle reads the next module
      // as a query letter (Turtle, SubCall).
      if (dialect == Dialect::Cpfg && !hasParens) return std::nullopt;
      return notSupported("?", "a '?' without a query letter or a sub-L-system number");
    }
    if (args > 2) return std::string("cpfg's sub-L-system call '?(n, scale)' takes 1 or 2 parameters, got ") + std::to_string(args);
    if (dialect != Dialect::Cpfg)
      return std::string("cpfg's '?(n, scale)' (sub-L-system call) is supported only in cpfg's notation (a .l file), where '$' ends it");
    return std::nullopt;
  }
  if ((name == "{" || name == "}" || name == ".") && hasParens && args > 0)
    return notSupported(std::string(name) + "(type)", "generalized cylinder");
  // cpfg's cut with parameters (interpret.c and generate.c): during an environmental
  // program's pass `%(n)` saves the turtle, the next step moves the cut branch to the end
  // of the string behind a `%(n, t)`, whose turtle restores the saved one. Not implemented.
  if (name == "%" && hasParens && args == 1)
    return notSupported("%(n)", "a cut whose branch cpfg moves to the end of the string, with the turtle saved for it");
  if (name == "%" && hasParens && args > 1)
    return notSupported("%(n, t)", "a moved cut branch, drawn from the turtle saved for it");
  return std::nullopt;
}

}  // namespace sprig::lsystem::detail
