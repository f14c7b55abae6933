#include "model/schema.h"

#include <cmath>
#include <map>
#include <memory>
#include <sstream>

#include "model/detail/key_recorder.h"
#include "model/kinds.h"
#include "model/species.h"

namespace sprig {

namespace {

using detail::KeySchema;

/// Runs of each kind's reader (model/detail/key_recorder.h): enough that every branch on
/// presence or shape is taken both ways, and that each alternative of the one-key maps
/// (blob nodes, distance fields, layers, operations) is described a few levels deep.
constexpr int kPasses = 4096;

/// A map is closed (additionalProperties: false) in the schema only when its reader
/// finished it in this many passes: one-key alternatives nest (blob nodes, distance fields,
/// operations), and a position deep in them that few passes reached may not have had all of
/// its keys asked for; it stays open rather than reject a key the reader takes.
constexpr int kMinFinishes = 8;

/// The message editors show for a value that is not a colour, and for a component out of range.
constexpr const char* kColorMessage =
    "Expected a colour: \"#rrggbb\" (six hex digits, sRGB) or [r, g, b] (linear, each from 0 to 1).";
constexpr const char* kColorItemMessage = "A colour's r, g and b are linear, each from 0 to 1.";

std::string number(double v) {
  std::ostringstream o;
  o.precision(9);
  o << v;
  return o.str();
}

std::string rangeText(const KeySchema& k) {
  if (k.above) return " > " + number(*k.above) + (k.max ? " and <= " + number(*k.max) : "");
  if (k.min && k.max) return " in [" + number(*k.min) + ", " + number(*k.max) + "]";
  if (k.min) return " >= " + number(*k.min);
  if (k.max) return " <= " + number(*k.max);
  return "";
}

std::string rangeJson(const KeySchema& k) {
  std::string out;
  if (k.above) out += ", \"exclusiveMinimum\": " + number(*k.above);
  if (k.min && !k.above) out += ", \"minimum\": " + number(*k.min);
  if (k.max) out += ", \"maximum\": " + number(*k.max);
  return out;
}

/// JSON of one position; `path` is where it sits ("render.view.azimuth") for descriptions.
std::string emit(const KeySchema& k, const std::string& path, int depth);

std::string mapJson(const KeySchema& k, const std::string& path, int depth) {
  const std::string pad(2 * (depth + 1), ' ');
  std::string out = "{\"type\": \"object\"";
  if (!k.properties.empty()) {
    out += ", \"properties\": {";
    bool first = true;
    for (const auto& [name, child] : k.properties) {
      out += std::string(first ? "" : ",") + "\n" + pad + detail::jsonString(name) + ": " +
             emit(*child, path.empty() ? name : path + "." + name, depth + 1);
      first = false;
    }
    out += "}";
  }
  if (!k.required.empty()) {
    out += ", \"required\": [";
    bool first = true;
    for (const auto& r : k.required) out += std::string(first ? "" : ", ") + detail::jsonString(r), first = false;
    out += "]";
  }
  if (!k.oneKey.empty()) {
    out += ", \"minProperties\": 1, \"maxProperties\": 1, \"propertyNames\": {\"enum\": [";
    for (size_t i = 0; i < k.oneKey.size(); ++i) out += (i ? ", " : "") + detail::jsonString(k.oneKey[i]);
    out += "]}";
  } else if (k.entries) {  // keys the file names (describeEntry): each entry's value, on a line of its own as a key
    out += ",\n" + pad + "\"additionalProperties\": " + emit(*k.entries, path + ".NAME", depth + 1);
  } else if (k.closed && !k.dataKeys && k.finishes >= kMinFinishes) {
    out += ", \"additionalProperties\": false";
  }
  return out + "}";
}

std::string emit(const KeySchema& k, const std::string& path, int depth) {
  if (!k.ref.empty())  // a shared definition: what the key does, then its place and the definition's name
    return "{\"description\": " + detail::jsonString((k.help.empty() ? "" : k.help + "\n\n") + path + ": " + k.ref) +
           ", \"$ref\": \"#/definitions/part_" + k.ref + "\"}";
  std::vector<std::string> alternatives;
  std::string what;
  if (!k.choices.empty()) {
    std::string e = "{\"enum\": [";
    for (size_t i = 0; i < k.choices.size(); ++i) e += (i ? ", " : "") + detail::jsonString(k.choices[i]);
    alternatives.push_back(e + "]}");
    what = "one of the listed words";
  } else {
    for (const std::string& t : k.types) {
      if (t == "number") {
        alternatives.push_back("{\"type\": \"number\"" + rangeJson(k) + "}");
        what += (what.empty() ? "" : " or ") + std::string("a number") + rangeText(k);
      } else if (t == "integer") {
        if (k.types.count("number")) continue;
        alternatives.push_back("{\"type\": \"integer\"" + rangeJson(k) + "}");
        what += (what.empty() ? "" : " or ") + std::string("an integer") + rangeText(k);
      } else if (t == "boolean") {
        // The reader also takes YAML 1.1's words, which YAML 1.2 tools read as strings.
        alternatives.push_back("{\"type\": \"boolean\"}");
        alternatives.push_back(
            "{\"enum\": [\"yes\", \"Yes\", \"YES\", \"no\", \"No\", \"NO\", \"on\", \"On\", "
            "\"ON\", \"off\", \"Off\", \"OFF\"]}");
        what += (what.empty() ? "" : " or ") + std::string("true or false");
      } else if (t == "string") {
        // The reader takes any scalar as text (`name: 2.6`); a colour's hex string is above.
        // One alternative per type: a union `type` list is an error in ajv's strict mode.
        if (k.types.count("color")) continue;
        if (!k.words.empty()) {  // a number or one of these words (describeValue)
          std::string e = "{\"enum\": [";
          for (size_t i = 0; i < k.words.size(); ++i) e += (i ? ", " : "") + detail::jsonString(k.words[i]);
          alternatives.push_back(e + "]}");
          for (size_t i = 0; i < k.words.size(); ++i) what += (what.empty() ? "" : " or ") + k.words[i];
          continue;
        }
        alternatives.push_back("{\"type\": \"string\"}");
        for (const char* scalar : {"number", "boolean"})  // unless that type's own alternative is there
          if (!k.types.count(scalar)) alternatives.push_back(std::string("{\"type\": \"") + scalar + "\"}");
        what += (what.empty() ? "" : " or ") + std::string("text");
      } else if (t == "vec3") {
        if (k.types.count("color")) continue;
        std::string r = rangeJson(k);
        alternatives.push_back("{\"type\": \"array\", \"minItems\": 3, \"maxItems\": 3, \"items\": {\"type\": \"number\"" +
                               r + "}}");
        what += (what.empty() ? "" : " or ") + std::string("[x, y, z]") + rangeText(k);
      } else if (t == "color") {
        // errorMessage and patternErrorMessage: what yaml-language-server (and VS Code's
        // JSON support) say instead of "Incorrect type. Expected array".
        const std::string message = detail::jsonString(kColorMessage);
        alternatives.push_back(
            "{\"type\": \"array\", \"minItems\": 3, \"maxItems\": 3, \"errorMessage\": " + message +
            ", \"items\": {\"type\": \"number\", \"minimum\": 0, \"maximum\": 1, \"errorMessage\": " +
            detail::jsonString(kColorItemMessage) + "}}");
        alternatives.push_back("{\"type\": \"string\", \"pattern\": \"^\\\\s*#[0-9A-Fa-f]{6}\\\\s*$\", \"errorMessage\": " +
                               message + ", \"patternErrorMessage\": " + message + "}");
        what += (what.empty() ? "" : " or ") + std::string("a colour [r, g, b] (linear, 0..1) or \"#rrggbb\" (sRGB)");
      } else if (t == "map") {
        alternatives.push_back(mapJson(k, path, depth));
        what += (what.empty() ? "" : " or ") +
                std::string(k.oneKey.empty() ? "a map" : "a map with one key");
      } else if (t == "sequence") {
        std::string items = k.items ? ", \"items\": " + emit(*k.items, path + "[]", depth + 1) : "";
        alternatives.push_back("{\"type\": \"array\"" + items + "}");
        what += (what.empty() ? "" : " or ") + std::string("a list");
      }
    }
  }
  // What the key does (the reader's Key::help), then where it sits, what it takes and its
  // default: "Field of view ...\n\nrender.view.fov: a number in [1, 150]; default 35".
  std::string desc = k.help.empty() ? "" : k.help + "\n\n";
  desc += path;
  if (!k.context.empty() && k.context != path) desc += " (" + k.context + ")";
  desc += what.empty() ? "" : ": " + what;
  // A help that states the default in words ("(default: the grammar's ...)") replaces the
  // constant the reader passes for an absent key, which is then not the value used.
  const bool defaultInWords = k.help.find("(default: ") != std::string::npos;
  if (!k.defaultJson.empty() && !defaultInWords) desc += "; default " + k.defaultJson;
  std::string head = "{\"description\": " + detail::jsonString(desc);
  if (!k.defaultJson.empty() && !defaultInWords) head += ", \"default\": " + k.defaultJson;
  // Several alternatives go under anyOf.
  std::string joined;
  for (size_t i = 0; i < alternatives.size(); ++i) joined += (i ? ", " : "") + alternatives[i];
  if (alternatives.empty()) return head + "}";
  if (alternatives.size() == 1) return head + ", " + alternatives[0].substr(1);
  return head + ", \"anyOf\": [" + joined + "]}";
}

}  // namespace

std::string speciesSchemaJson() {
  std::string kinds, branches, defs;
  bool first = true;
  std::map<std::string, std::unique_ptr<KeySchema>> shared;  // one-key maps: blob nodes, fields, operations
  for (const KindEntry& kind : speciesKinds()) {
    KeySchema root;
    for (int pass = 0; pass < kPasses; ++pass) {
      detail::KeyRecorder recorder(root, pass);
      recorder.setDefinitions(&shared);
      try {
        parseSpecies(std::string("kind: ") + kind.name + "\n", "species.yaml");
      } catch (const InputError&) {
        // The empty document is not a valid species; only the keys asked for matter.
      }
    }
    root.property("name").defaultJson.clear();  // the file's stem, not a constant
    KeySchema& k = root.property("kind");
    k.types.clear();
    k.choices = {kind.name};
    root.required.insert("kind");
    const std::string name = kind.name;
    kinds += std::string(first ? "" : ", ") + detail::jsonString(name);
    branches += std::string(first ? "" : ",\n    ") + "{\"if\": {\"required\": [\"kind\"], \"properties\": {\"kind\": {\"const\": " +
                detail::jsonString(name) + "}}}, \"then\": {\"$ref\": \"#/definitions/" + name + "\"}}";
    defs += std::string(first ? "" : ",\n") + "    " + detail::jsonString(name) + ": " + mapJson(root, "", 2);
    first = false;
  }
  std::string out = "{\n";
  out += "  \"$schema\": \"http://json-schema.org/draft-07/schema#\",\n";
  out += "  \"title\": \"Sprig species file\",\n";
  out += "  \"description\": \"A Sprig species file (species/*.yaml), generated by `sprig schema` from the readers' own keys, types, ranges and defaults.\",\n";
  out += "  \"type\": \"object\",\n";
  out += "  \"required\": [\"kind\"],\n";
  out += "  \"properties\": {\"kind\": {\"description\": \"what the file describes\", \"enum\": [" + kinds + "]}},\n";
  out += "  \"allOf\": [\n    " + branches + "\n  ],\n";
  for (const auto& [name, def] : shared)
    defs += ",\n    " + detail::jsonString("part_" + name) + ": " + emit(*def, name, 2);
  out += "  \"definitions\": {\n" + defs + "\n  }\n}\n";
  return out;
}

}  // namespace sprig
