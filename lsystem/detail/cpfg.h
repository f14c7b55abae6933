#pragma once
/// cpfg's turtle command symbols (CPFG reference manual, section 6): which ones Sprig reads
/// as one module and which it does not implement. Private to lsystem/; the scanner and the
/// grammar parser use it so that a command Sprig does not draw exactly as cpfg does is an
/// error naming it, never a different drawing (docs/GRAMMAR.md, "cpfg compatibility").

#include <optional>
#include <string>
#include <string_view>

namespace sprig::lsystem::detail {

/// Which notation a grammar is read in. `.lsys` files are Sprig's (ABOP's figures as
/// printed: `$` rolls to vertical, `!` alone thins by 0.7, `@O(r)` takes a radius); `.l`
/// files are cpfg's own (`$` ends a sub-L-system, `!`/`#` step the width by the view file's
/// increment, `@O(d)` takes a diameter, `'` is no command).
enum class Dialect { Sprig, Cpfg };

/// Dialect of a grammar file, chosen by its name: `*.l` is cpfg's, anything else Sprig's.
Dialect dialectOf(std::string_view fileName);

/// One of cpfg's multi-character command names (`@Gc`, `?P`, `@Ts`, ...), in the order the
/// tokenizer must know them (every name Sprig reads as one module, supported or not).
extern const char* const kCpfgMultiNames[];
extern const size_t kCpfgMultiNameCount;

/// Why a module written as `name` with `args` parameters (hasParens: written with `(...)`)
/// cannot be read, as the message to report at its position (`cpfg's '@Gr' (generalized
/// cylinder radius tangents) is not supported`), or nullopt when Sprig implements it (or it is no cpfg
/// command at all). `next` is the character after the name, for `@` and `?` followed by
/// an unknown letter.
std::optional<std::string> cpfgUnsupported(std::string_view name, size_t args, bool hasParens, char next,
                                           Dialect dialect);

}  // namespace sprig::lsystem::detail
