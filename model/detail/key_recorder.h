#pragma once
/// The key table of species files, as the reader itself declares it (model/schema.h).
///
/// Sprig's readers declare each key where they read it: `m.number("steps", 5, 0, 1000)`
/// names the key, its type, default and range, and MapReader::finish() knows the closed set
/// of keys of a map. Rather than copy those declarations into a second table that could
/// drift, `sprig schema` runs the readers once per kind in a describe mode: a KeyRecorder is
/// made active on the thread, and every MapReader getter and typed YNode read records what
/// it asks for into a tree of KeySchema nodes, one per position in the document. In that
/// mode an absent key reads as a placeholder node (or stays absent, see below) and an
/// absent sequence yields one placeholder element. Readers branch on presence (`has()`) and on shape (a scalar or a
/// map), so the generator runs each reader many times ("passes"): pass 0 answers `has()`
/// (and "is the key there?" in `get()`) with yes and makes every placeholder a map, pass 1
/// answers no, and later passes answer
/// and shape pseudo-randomly (a fixed hash of the pass and the question's number, so the
/// schema is the same every time). The union of what the passes saw is the key table. With
/// no recorder active (every real read) nothing here runs.
///
/// Only model/yaml_reader.cpp (the recording hooks), model/schema.cpp (the generator) and
/// model/blob_kind.cpp (a texture id's range is the file's list length, not a constant)
/// include this header.

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace sprig::detail {

/// What the readers asked of one position in a species file.
struct KeySchema {
  /// Types asked for: "number", "integer", "boolean", "string", "vec3", "color", "map",
  /// "sequence". Several = the reader accepts any of them there.
  std::set<std::string> types;
  std::optional<double> min, max;    ///< range of numbers (of each element for vec3)
  std::optional<double> above;       ///< numbers must exceed this (describeValue)
  std::vector<std::string> words;    ///< the only texts taken beside a number (describeValue)
  std::vector<std::string> choices;  ///< MapReader::choice's closed set
  std::vector<std::string> oneKey;   ///< singleKey: a map with exactly one of these keys
  std::string defaultJson;           ///< the default as JSON (empty: none / required)
  std::string context;               ///< the map's name in the reader's messages ("render.view")
  std::string help;                  ///< what the key does (Key::help), for the description
  bool closed = false;               ///< a map whose finish() ran: other keys are errors
  int finishes = 0;                  ///< passes whose reader finished this map (how well its keys are known)
  bool dataKeys = false;             ///< a map whose keys are names the file chooses (materials, defines)
  std::set<std::string> required;    ///< keys of this map that requiredString demands
  std::string ref;  ///< the position holds a shared definition (KeyRecorder::definition) of this name
  std::map<std::string, std::unique_ptr<KeySchema>> properties;  ///< a map's keys
  std::unique_ptr<KeySchema> items;                              ///< a sequence's elements
  /// dataKeys maps described by describeEntry: the value of every entry (the schema's
  /// additionalProperties), or null.
  std::unique_ptr<KeySchema> entries;

  KeySchema& property(const std::string& key) {
    auto& p = properties[key];
    if (!p) p = std::make_unique<KeySchema>();
    return *p;
  }
  KeySchema& item() {
    if (!items) items = std::make_unique<KeySchema>();
    return *items;
  }
  KeySchema& entry() {
    if (!entries) entries = std::make_unique<KeySchema>();
    return *entries;
  }
  /// Widens the range to hold [lo, hi] (infinite bounds mean none).
  void range(double lo, double hi);
};

/// Records the reader's requests while active on this thread (see the file comment).
class KeyRecorder {
 public:
  /// The recorder active on this thread, or null (always, outside `sprig schema`).
  static KeyRecorder* active();

  /// Makes this recorder active on the thread for its lifetime; `root` receives the next
  /// top-level map read.
  KeyRecorder(KeySchema& root, int pass);
  ~KeyRecorder();
  KeyRecorder(const KeyRecorder&) = delete;
  KeyRecorder& operator=(const KeyRecorder&) = delete;

  /// The schema node bound to a YAML node, or null. The first unbound map read becomes the root.
  KeySchema* schemaOf(const YAML::Node& node, bool asRoot = false);
  /// Binds node to schema (a child position: a key's value, a sequence's element).
  void bind(const YAML::Node& node, KeySchema& schema);
  /// A new node standing for an absent key: an empty map, or in some passes the scalar `0`
  /// (a number, an integer, a text and an expression at once) or an empty sequence.
  YAML::Node placeholder();
  /// What MapReader::has answers in this pass.
  bool answerHas();
  /// Which of n alternatives (a one-key map's names) this pass descends into, or nullopt
  /// when the pass has used its budget of descents (kMaxDescents: one-key maps nest, e.g.
  /// a blob node's children, a distance field's union, so a pass stops somewhere).
  std::optional<size_t> chooseAlternative(size_t n);
  /// The answer this pass already gave for an absent key at position `at` (a placeholder,
  /// or null for "absent"), so a reader asking twice gets the same answer; nullopt before
  /// the first time.
  std::optional<YAML::Node> answered(const KeySchema* at, bool& wasAbsent) const;
  /// Remembers the answer for `at` (an invalid node = absent).
  void remember(const KeySchema* at, std::optional<YAML::Node> answer);
  /// Shared definitions (one-key maps that recur at many positions and nest: blob nodes,
  /// distance fields, layers, operations), kept by the generator across passes and kinds;
  /// null until setDefinitions.
  void setDefinitions(std::map<std::string, std::unique_ptr<KeySchema>>* definitions) { definitions_ = definitions; }
  /// The shared definition of this name (created on first use), or null without definitions.
  KeySchema* definition(const std::string& name);
  /// Most one-key descents in one pass.
  static constexpr int kMaxDescents = 48;
  bool isPlaceholder(const YAML::Node& node) const;

 private:
  /// A pseudo-random number from the pass and a running count (splitmix64).
  uint64_t nextRandom();
  KeySchema* root_;
  int pass_;
  uint64_t questions_ = 0;
  int descents_ = 0;
  std::map<std::string, std::unique_ptr<KeySchema>>* definitions_ = nullptr;
  std::map<const KeySchema*, std::optional<YAML::Node>> answers_;
  std::vector<std::pair<YAML::Node, KeySchema*>> bound_;
  std::vector<YAML::Node> placeholders_;
  KeyRecorder* previous_;
};

/// text as a JSON string literal: quotes and backslashes escaped, newlines as \n, other
/// control characters as spaces (the schema's help texts and key defaults).
std::string jsonString(std::string_view text);

}  // namespace sprig::detail
