#pragma once
/// Helpers shared by the `sprig` subcommands.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "app/commands.h"
#include "lsystem/grammar.h"
#include "render/camera.h"

namespace sprig {

/// Overrides from `-D NAME=VALUE` flags, `--steps` (ignored when < 0) and `--seed`
/// (ignored when < 0). Throws UsageError for a malformed -D.
lsystem::GrammarOverrides commandLineOverrides(const std::vector<std::string>& defines, int steps, int64_t seed);

/// Parses `--view AZ,EL` or `AZ,EL,FOV` (degrees) into view. Throws UsageError.
void parseView(const std::string& text, render::ViewSpec& view);

}  // namespace sprig
