/// `sprig schema [-o FILE]`: the JSON Schema of species files, for editors (model/schema.h).

#include <filesystem>
#include <iostream>

#include "app/cmd_common.h"
#include "core/atomic_file.h"
#include "model/schema.h"

namespace sprig {

namespace {

struct SchemaArgs {
  std::string out;
};

int runSchema(const SchemaArgs& a, const GlobalOptions& g) {
  const std::string json = speciesSchemaJson();
  if (a.out.empty() || a.out == "-") {
    std::cout << json;
    return kExitOk;
  }
  const std::filesystem::path parent = std::filesystem::path(a.out).parent_path();
  std::error_code ec;
  if (!parent.empty() && !std::filesystem::is_directory(parent, ec))
    throw UsageError("--output: folder '" + parent.string() + "' does not exist");
  writeFileAtomic(a.out, json);
  if (!g.quiet) std::cout << "wrote " << a.out << " (" << json.size() << " bytes)\n";
  return kExitOk;
}

}  // namespace

void addSchemaCommand(CLI::App& app, const GlobalOptions& global, CommandRun& run) {
  auto [sub, args] = subcommand<SchemaArgs>(
      app, global, run, "schema", "Write the JSON Schema (draft-07) of species files, for editors' YAML language servers",
      runSchema);
  sub->add_option("-o,--output", args->out, "output file (default: standard output)");
}

}  // namespace sprig
