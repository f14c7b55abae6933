// speciesSchemaJson: what editors read from the schema beside the keys (descriptions, the
// colour messages, values a reader checks itself). tests/cli/schema_test.sh validates the
// schema with ajv and tests/editor/run.py runs it in yaml-language-server.

#include <catch2/catch.hpp>

#include <algorithm>
#include <string>
#include <vector>

#include "model/schema.h"
#include "model/yaml_reader.h"

using namespace sprig;

namespace {

/// The JSON text of the first property `key` at or after `from` (its description up to
/// the end of its line: the schema puts one property per line).
std::string propertyLine(const std::string& schema, const std::string& key, size_t from = 0) {
  const size_t at = schema.find("\"" + key + "\": {\"description\"", from);
  if (at == std::string::npos) return "";
  return schema.substr(at, schema.find('\n', at) - at);
}

}  // namespace

TEST_CASE("speciesSchemaJson", "[model]") {
  const std::string schema = speciesSchemaJson();

  SECTION("a key's description says what it does, then its place, type, range and default") {
    const size_t tree = schema.find("\"tree\": {\"type\": \"object\"");
    REQUIRE(tree != std::string::npos);
    CHECK(propertyLine(schema, "max_modules", tree) ==
          "\"max_modules\": {\"description\": \"Module limit of the derivation: a grammar that grows past it stops "
          "with an error.\\n\\nmax_modules: an integer in [1, 4e+09]; default 50000000\", \"default\": 50000000, "
          "\"type\": \"integer\", \"minimum\": 1, \"maximum\": 4e+09},");
    // A default stated in words replaces the reader's placeholder constant.
    const std::string steps = propertyLine(schema, "steps", tree);
    CHECK(steps.find("Derivation steps (default: the grammar's `derivation length:`") != std::string::npos);
    CHECK(steps.find("steps: an integer in [0, 100000]\"") != std::string::npos);
    CHECK(steps.find("\"default\"") == std::string::npos);
    // A pigment key: its text, then the generated part.
    CHECK(propertyLine(schema, "cells").find("\"description\": \"Cells around the growing edge (periodic): the "
                                            "pattern's resolution across the whorl.\\n\\nshell.pigment.cells: an "
                                            "integer in [3, 4096]; default 160\"") != std::string::npos);
    // A one-key alternative (a blob node's kind, a distance field, a tool) says what it is.
    const size_t blobNode = schema.find("\"part_blob_node\": {");
    REQUIRE(blobNode != std::string::npos);
    CHECK(propertyLine(schema, "cone", blobNode).find("\"description\": \"Cone primitive (the tree paper's internode") !=
          std::string::npos);
    CHECK(propertyLine(schema, "hammer").find("\"description\": \"A blow (§3.1)") != std::string::npos);
    // A position holding a shared definition keeps its text beside the `$ref`.
    CHECK(propertyLine(schema, "child").find("\"description\": \"The blob node it acts on.\\n\\n") !=
          std::string::npos);
    // The one-line help of a shell part's key.
    CHECK(propertyLine(schema, "spacing").find("\"description\": \"Angle between successive varices") !=
          std::string::npos);
  }

  SECTION("every key of render: says what it does") {
    for (const char* key : {"width", "height", "samples", "sampler", "thin_min_pixels", "mesher", "simplify", "wind",
                            "view", "background", "background_color", "ground", "ground_color", "sun", "exposure",
                            "camera", "fill", "sky", "unlit_sky_samples", "color", "roughness", "specular", "wood",
                            "leaf", "fruit", "palette", "radius_scale", "organs"}) {
      const size_t render = schema.find("\"render\": {\"description\"");
      REQUIRE(render != std::string::npos);
      INFO(key);
      const std::string line = propertyLine(schema, key, render);
      const std::string generatedOnly = "\"" + std::string(key) + "\": {\"description\": \"render.";
      REQUIRE(!line.empty());
      CHECK(line.compare(0, generatedOnly.size(), generatedOnly) != 0);  // a text comes first
    }
  }

  SECTION("every key says what it does") {
    // Each property sits on a line of its own, indented 6 or more (the kinds' and the shared
    // parts' definitions sit at 4): `"key": {"description": "HELP\n\nplace: type; default"`.
    // A key whose reader gives no help has the generated part alone, without the blank line.
    std::vector<std::string> without;
    int keys = 0;
    size_t at = 0;
    while (at < schema.size()) {
      const size_t end = std::min(schema.find('\n', at), schema.size());
      const std::string line = schema.substr(at, end - at);
      at = end + 1;
      const size_t indent = line.find_first_not_of(' ');
      const size_t open = line.find("\": {\"description\": \"");
      if (indent == std::string::npos || indent < 6 || line[indent] != '"' || open == std::string::npos) continue;
      ++keys;
      const size_t text = open + 20;
      const std::string description = line.substr(text, line.find("\", \"", text) - text);
      if (description.find("\\n\\n") == std::string::npos) without.push_back(description);
    }
    CHECK(keys > 900);
    INFO("keys without help: " << without.size());
    for (const std::string& d : without) UNSCOPED_INFO(d);
    CHECK(without.empty());
  }

  SECTION("keys whose names are data: every entry's value is described") {
    // A solid's materials: each entry (its key the material's name) is a material, whose keys
    // are checked and have their texts.
    const size_t solid = schema.find("\"solid\": {\"type\": \"object\"");
    REQUIRE(solid != std::string::npos);
    const size_t materials = schema.find("\"materials\": {\"description\"", solid);
    REQUIRE(materials != std::string::npos);
    const std::string entry = propertyLine(schema, "additionalProperties", materials);
    CHECK(entry.find("\"description\": \"A material of this file, named by its key") != std::string::npos);
    CHECK(entry.find("materials.NAME (material 'NAME'): a map\", \"type\": \"object\"") != std::string::npos);
    CHECK(propertyLine(schema, "roughness", materials) ==
          "\"roughness\": {\"description\": \"Render roughness, 0 to 1.\\n\\nmaterials.NAME.roughness: a number in [0, "
          "1]; default 0.5\", \"default\": 0.5, \"type\": \"number\", \"minimum\": 0, \"maximum\": 1},");
    CHECK(propertyLine(schema, "select", materials).find("materials.NAME.select") != std::string::npos);
    // A tree's defines: any name, a number.
    const std::string define = propertyLine(schema, "additionalProperties", schema.find("\"defines\": {\"description\""));
    CHECK(define.find("defines.NAME: a number\", \"type\": \"number\"}") != std::string::npos);
    // A shell's generating primitives: a map with one key, point or cone, each closed.
    const size_t primitives = schema.find("\"primitives\": {\"description\"");
    REQUIRE(primitives != std::string::npos);
    const std::string item = schema.substr(primitives, schema.find("\"part_", primitives) - primitives);
    CHECK(item.find("\"minProperties\": 1, \"maxProperties\": 1, \"propertyNames\": {\"enum\": [\"point\", \"cone\"]}") !=
          std::string::npos);
    CHECK(propertyLine(schema, "point", primitives).find("A point primitive of the generating surface") != std::string::npos);
    CHECK(propertyLine(schema, "radius_a", primitives).find("shell.generating.primitives[].cone.radius_a: a number in "
                                                           "[0.0001, 100]; default 0.3\"") != std::string::npos);
  }

  SECTION("a colour is a pattern or a triple, each with a readable message") {
    const std::string wood = propertyLine(schema, "wood");
    CHECK(wood.find("\"pattern\": \"^\\\\s*#[0-9A-Fa-f]{6}\\\\s*$\"") != std::string::npos);
    CHECK(wood.find("\"patternErrorMessage\": \"Expected a colour: \\\"#rrggbb\\\" (six hex digits, sRGB) or [r, g, "
                    "b] (linear, each from 0 to 1).\"") != std::string::npos);
    CHECK(wood.find("\"errorMessage\": \"A colour's r, g and b are linear, each from 0 to 1.\"") != std::string::npos);
  }

  SECTION("a layer's thickness: a positive number or fill, as the reader checks it") {
    const std::string thickness = propertyLine(schema, "thickness");
    CHECK(thickness.find("a number > 0 or fill") != std::string::npos);
    CHECK(thickness.find("{\"type\": \"number\", \"exclusiveMinimum\": 0}, {\"enum\": [\"fill\"]}") !=
          std::string::npos);
  }

  SECTION("no union type lists (ajv's strict mode refuses them)") {
    CHECK(schema.find("\"type\": [") == std::string::npos);
  }
}

TEST_CASE("Key", "[model]") {
  // A help text changes nothing when reading: the same value, the same messages.
  DiagnosticList diags;
  auto file = YamlFile::parse("steps: 7\nwidth: 9000\n", "k.yaml", diags);
  REQUIRE(file);
  MapReader m(file->rootNode(), diags, "species file");
  CHECK(m.integer({"steps", "How many steps."}, 5, 0, 10) == 7);
  CHECK(m.integer({"width", "Image width."}, 800, 16, 8192) == 800);
  REQUIRE(diags.items().size() == 1);
  CHECK(diags.items()[0].message == "'width' is 9000, out of range [16, 8192]");
}
