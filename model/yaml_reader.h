#pragma once
/// A checked YAML reader on yaml-cpp 0.7 for species files and the sections other
/// parts of Sprig own (`tree:`, `shell:`, `blob:`, ...).
///
/// yaml-cpp alone is lenient in ways that hide mistakes: its marks are 0-based, duplicate
/// keys pass silently (both pairs are kept), `.nan`/`.inf` read as numbers, a missing key
/// throws without a position, and anchors/aliases can expand a tiny file into billions of
/// nodes. This reader closes each hole:
///
/// - YamlFile::load / YamlFile::parse read the text, convert yaml-cpp parse errors to
///   `file:line:col` (1-based), and walk the whole document once with a cap on nodes
///   visited (defeats alias bombs and self-referencing aliases). Duplicate keys in any
///   map are reported during that walk.
/// - YNode is a yaml-cpp node plus its file: loc() gives the 1-based SourceLoc, and the
///   typed accessors (asNumber, asInteger, ...) report wrong types, NaN/inf and range
///   errors into a DiagnosticList.
/// - MapReader reads one YAML map key by key with defaults, remembers which keys were
///   read, and finish() reports every key nobody asked for, with "did you mean".
///
/// Every error is collected, not thrown: call DiagnosticList::throwIfErrors() once the
/// whole file is read so the user sees all of them together.
///
/// Typical use:
/// ```
///   DiagnosticList diags;
///   auto file = YamlFile::load("species/fern.yaml", diags);   // nullptr on syntax error
///   MapReader top(file->rootNode(), diags, "species file");
///   int steps = top.integer("steps", 5, 0, 1000);
///   if (auto t = top.section("turtle")) {
///     MapReader turtle(*t, diags, "turtle");
///     double angle = turtle.number("angle", 25.0, -360.0, 360.0);
///     turtle.finish();
///   }
///   top.finish();
///   diags.throwIfErrors();
/// ```
///
/// Messages (tests/bad_inputs checks them verbatim):
///   unknown key 'stpes' in species file (did you mean 'steps'?)
///   duplicate key 'seed' (first defined at line 3)
///   'steps' must be an integer, got 'abc'
///   'steps' must be a map / a sequence / a string / true or false / [x, y, z]
///   'angle' must be a finite number, got '.nan'
///   'steps' is 5000, out of range [0, 1000]
///   YAML document has more than N nodes (alias bomb?)

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "core/diagnostics.h"
#include "core/types.h"

namespace sprig {

class YNode;
namespace detail {
struct KeySchema;
}

/// Options for loading a YAML file.
struct YamlLoadOptions {
  /// Cap on nodes visited while walking the document (aliases count each time they are
  /// reached). Real species files have a few hundred nodes.
  int64_t maxNodes = 1'000'000;
  /// Files larger than this are refused before parsing.
  std::uintmax_t maxBytes = 64u << 20;
};

/// One parsed YAML document with the text it came from (for source lines in diagnostics).
class YamlFile {
 public:
  /// Reads and parses `path`. `displayPath` (default: path as given) is what diagnostics
  /// print. Returns nullptr after adding diagnostics when the file cannot be read or
  /// parsed, or is too large / too deep / an alias bomb; duplicate keys are added to
  /// diags but the file is still returned.
  static std::shared_ptr<const YamlFile> load(const std::filesystem::path& path, DiagnosticList& diags,
                                              const YamlLoadOptions& options = {});
  /// Parses in-memory text as if it were the file `displayPath` (tests, inline sections).
  static std::shared_ptr<const YamlFile> parse(std::string text, std::string displayPath, DiagnosticList& diags,
                                               const YamlLoadOptions& options = {});

  const std::filesystem::path& path() const { return path_; }
  const std::string& displayPath() const { return displayPath_; }
  const std::string& text() const { return text_; }
  const YAML::Node& root() const { return root_; }
  /// The root as a YNode (needs the shared_ptr that owns this file).
  YNode rootNode() const;

  /// 1-based location of a yaml-cpp mark in this file.
  SourceLoc loc(const YAML::Mark& mark) const;
  /// Text of 1-based line `line`, for carets.
  std::string sourceLine(int line) const { return lineOf(text_, line); }
  /// Adds an error at mark.
  void error(DiagnosticList& diags, const YAML::Mark& mark, std::string message) const;

 private:
  YamlFile() = default;
  static std::shared_ptr<const YamlFile> parseAt(std::string text, std::string displayPath,
                                                 const std::filesystem::path& path, DiagnosticList& diags,
                                                 const YamlLoadOptions& options);
  std::filesystem::path path_;
  std::string displayPath_;
  std::string text_;
  YAML::Node root_;
  std::weak_ptr<const YamlFile> self_;
};

/// A YAML node together with the file it came from.
class YNode {
 public:
  YNode(std::shared_ptr<const YamlFile> file, YAML::Node node) : file_(std::move(file)), node_(std::move(node)) {}

  const YAML::Node& node() const { return node_; }
  const YamlFile& file() const { return *file_; }
  const std::shared_ptr<const YamlFile>& fileHandle() const { return file_; }
  /// 1-based position of the node's first character.
  SourceLoc loc() const { return file_->loc(node_.Mark()); }
  /// Adds an error at this node.
  void error(DiagnosticList& diags, std::string message) const { file_->error(diags, node_.Mark(), std::move(message)); }

  bool isMap() const { return node_.IsMap(); }
  bool isSequence() const { return node_.IsSequence(); }
  bool isScalar() const { return node_.IsScalar(); }
  bool isNull() const { return node_.IsNull(); }
  /// True for a plain (unquoted) scalar; quoted scalars are always strings.
  bool isPlainScalar() const { return node_.IsScalar() && node_.Tag() != "!"; }
  /// The scalar text (empty for non-scalars).
  std::string scalar() const;
  /// Elements of a sequence (empty otherwise).
  std::vector<YNode> items() const;
  /// Key/value pairs of a map in file order, duplicates included (empty otherwise).
  std::vector<std::pair<YNode, YNode>> pairs() const;

  // Typed reads. `what` names the value in messages ("'steps'"); on error they add a
  // diagnostic at this node and return nullopt.
  /// A finite real number (plain scalar; .nan/.inf refused) within [min, max].
  std::optional<double> asNumber(DiagnosticList& diags, std::string_view what,
                                 double min = -std::numeric_limits<double>::infinity(),
                                 double max = std::numeric_limits<double>::infinity()) const;
  /// An integer (plain scalar, no fraction) within [min, max].
  std::optional<int64_t> asInteger(DiagnosticList& diags, std::string_view what,
                                   int64_t min = std::numeric_limits<int64_t>::min(),
                                   int64_t max = std::numeric_limits<int64_t>::max()) const;
  /// true/false (also yes/no, on/off).
  std::optional<bool> asBoolean(DiagnosticList& diags, std::string_view what) const;
  /// Any scalar as text (numbers too); null, maps and sequences are errors.
  std::optional<std::string> asString(DiagnosticList& diags, std::string_view what) const;
  /// `[x, y, z]` of finite numbers, each within [min, max].
  std::optional<Vec3> asVec3(DiagnosticList& diags, std::string_view what,
                             double min = -std::numeric_limits<double>::infinity(),
                             double max = std::numeric_limits<double>::infinity()) const;
  /// A colour in linear RGB: `[r, g, b]` in [0, 1] (linear) or `"#rrggbb"` (sRGB, converted to linear).
  std::optional<Vec3> asColor(DiagnosticList& diags, std::string_view what) const;

 private:
  std::shared_ptr<const YamlFile> file_;
  YAML::Node node_;
};

/// `'text'` for messages (appended piecewise: GCC 12 warns falsely on "'" + string + "'").
std::string quoted(std::string_view text);

/// Where referenced files (grammars, textures, ...) may come from.
struct PathPolicy {
  /// The library root: references must resolve inside it (`--root`). Empty: loadSpecies
  /// chooses defaultLibraryRoot of the species file.
  std::filesystem::path root = ".";
  /// `--allow-outside-paths`: accept absolute paths and escapes above the root.
  bool allowOutside = false;
};

/// The library root of a species given without `--root`: the nearest folder at or above
/// the species file's folder (a vlab object: the folder itself) that holds a `.sprig-root`
/// marker file or is the parent of a folder named `species` on the way up; else the species
/// file's own folder. Returned as a path relative to the species path's own spelling
/// (`species/oak.yaml` -> `.`), absolute when the species path is absolute.
std::filesystem::path defaultLibraryRoot(const std::filesystem::path& speciesPath);

/// The refusal of `resolved` (written `written` in a file) under policy: "" when it may be
/// read, else the message ("refusing absolute path ...", "refusing path ...: it leaves the
/// library root ..."). Absolute paths are refused before anything is resolved.
std::string pathRefusal(const std::string& written, const std::filesystem::path& resolved, const PathPolicy& policy);

/// Resolves `ref` (as written at `at`) relative to the folder of at's file. Refuses URI
/// schemes (`http://...`, `file:...`), absolute paths and paths that leave policy.root
/// unless policy.allowOutside; with mustExist, a missing file is an error too. Returns
/// the resolved path (relative to the current folder when possible) or nullopt after
/// adding a diagnostic at `at`.
std::optional<std::filesystem::path> resolveReference(const YNode& at, std::string_view ref, const PathPolicy& policy,
                                                      DiagnosticList& diags, bool mustExist = true);

/// A key of a map as a reader asks for it: its name and, optionally, what it does in one
/// sentence or two, e.g. `m.integer({"steps", "How many derivation steps to run."}, 5, 0, 1000)`.
/// The text costs nothing when reading; `sprig schema` writes it into the key's description,
/// beside the range and default the same call declares, and editors show it on hover. A help
/// that says "(default: ...)" in words stands for the default (the constant in the call is
/// then only the reader's placeholder). A bare name converts to a Key without help.
struct Key {
  std::string_view name;
  std::string_view help;
  Key(const char* keyName) : name(keyName) {}
  Key(std::string_view keyName) : name(keyName) {}
  Key(const std::string& keyName) : name(keyName) {}
  Key(std::string_view keyName, std::string_view keyHelp) : name(keyName), help(keyHelp) {}
};

/// Reads one YAML map key by key. Every getter marks its key as known; finish() reports
/// the keys of the map that no getter asked for. Getters return the default when the key
/// is absent and also when its value is wrong (after adding a diagnostic), so reading
/// can go on and collect every error of the file.
class MapReader {
 public:
  /// `node` should be a map (anything else adds "<context> must be a map"; an empty or
  /// null node reads as an empty map). `context` names the map in messages
  /// ("species file", "turtle").
  MapReader(YNode node, DiagnosticList& diags, std::string context);

  const YNode& node() const { return node_; }
  DiagnosticList& diagnostics() const { return *diags_; }
  /// True if the map has `key` (does not mark it as read).
  bool has(std::string_view key) const;
  /// The value node of `key` (marks it as known), nullopt when absent. Every getter below
  /// reads through get.
  std::optional<YNode> get(Key key);
  /// The key node of `key` (for locations of the key itself).
  std::optional<YNode> keyNode(std::string_view key) const;
  /// Marks keys as known without reading them (keys another reader handles, or reads only
  /// in some cases: a Key's help then still reaches `sprig schema`).
  void allow(std::initializer_list<Key> keys);

  /// A finite real number within [min, max]; `def` when absent.
  double number(Key key, double def, double min = -std::numeric_limits<double>::infinity(),
                double max = std::numeric_limits<double>::infinity());
  /// An integer within [min, max]; `def` when absent.
  int64_t integer(Key key, int64_t def, int64_t min = std::numeric_limits<int64_t>::min(),
                  int64_t max = std::numeric_limits<int64_t>::max());
  /// A scalar as text; `def` when absent.
  std::string string(Key key, std::string def = {});
  /// A required scalar: adds "missing required key 'K' in <context>" at the map when absent.
  std::optional<std::string> requiredString(Key key);
  /// Declares key required in this map for `sprig schema` (its `required` list); no effect
  /// when reading. For readers that check a required key's presence themselves.
  void markRequired(std::string_view key);
  /// true/false; `def` when absent.
  bool boolean(Key key, bool def);
  /// `[x, y, z]`; `def` when absent.
  Vec3 vec3(Key key, Vec3 def, double min = -std::numeric_limits<double>::infinity(),
            double max = std::numeric_limits<double>::infinity());
  /// A colour: `[r, g, b]` linear in [0, 1] or `"#rrggbb"` sRGB (returned linear); `def` when absent.
  Vec3 color(Key key, Vec3 def);
  /// One of `choices` (did-you-mean on a miss); `def` when absent.
  std::string choice(Key key, std::string def, const std::vector<std::string>& choices);
  /// A nested map; nullopt when absent or not a map (the latter adds an error).
  std::optional<YNode> section(Key key);
  /// A sequence's elements; empty when absent or not a sequence (the latter adds an error).
  std::vector<YNode> sequence(Key key);
  /// A file reference resolved with resolveReference; nullopt when absent or refused.
  std::optional<std::filesystem::path> path(Key key, const PathPolicy& policy, bool mustExist = true);

  /// Reports every key of the map not read or allowed: "unknown key 'K' in <context>"
  /// plus "did you mean" among the known keys. Call once, after all getters.
  void finish();

 private:
  struct Entry {
    YNode key;
    YNode value;
  };
  YNode node_;
  DiagnosticList* diags_;
  std::string context_;
  std::vector<Entry> entries_;          // first occurrence of each key, file order
  std::map<std::string, size_t, std::less<>> index_;
  std::set<std::string, std::less<>> known_;
  detail::KeySchema* schema_ = nullptr;  // `sprig schema` only (model/detail/key_recorder.h)
};

/// Describe mode (`sprig schema`) only: records that node is a map with one key among names
/// and, when node is a placeholder, returns one of them (chosen per pass) with a
/// placeholder value bound to that key's schema, so the reader goes on to describe that
/// alternative's keys. Outside describe mode, or for a real node, nullopt. singleKey calls
/// it; readers that check their one key themselves (blob nodes) call it first.
/// With a definition name, every position described this way refers to one shared schema
/// of that name (`$ref`), so nested and recurring ones (a blob node's children) are checked
/// alike; singleKey uses its `what` ("distance field" -> distance_field).
std::optional<std::pair<YNode, YNode>> describeOneKey(const YNode& node, const std::vector<std::string>& names,
                                                      const std::string& definition = "");

/// Describe mode (`sprig schema`) only, for a map whose keys are names the file chooses (a
/// solid's `materials:`, a tree's `defines:`), which a reader walks with YNode::pairs():
/// records that every entry's value has one schema (additionalProperties), whose text is
/// help, and when map is a placeholder returns a made-up entry (the key `NAME`, a
/// placeholder value bound to that schema) for the reader to read as it reads each real
/// entry. Call it before pairs(). Outside describe mode, or for a real map, nullopt.
std::optional<std::pair<YNode, YNode>> describeEntry(const YNode& map, std::string_view help);

/// Describe mode (`sprig schema`) only, for a reader that checks a value itself rather
/// than through a typed read's range: the number at node must be above `above` (exclusive),
/// and `words` are the only texts it takes (`thickness: fill`). No effect when reading.
void describeValue(const YNode& node, std::optional<double> above, const std::vector<std::string>& words = {});

/// Describe mode (`sprig schema`) only: what the key holding `value` does, for a key no
/// MapReader getter reads and so no `Key` names: a one-key map's alternative (`{cone: {...}}`
/// from singleKey or describeOneKey). Call it on the alternative's value where the reader
/// takes that alternative; the first text given for a position stays. No effect when reading.
void describeHelp(const YNode& value, std::string_view help);

/// The texts of choices whose names a reader matches itself (a texture's kind, a field's
/// form, a tool), for `describeHelp` and `Key`s: name → what it does.
using HelpTable = std::map<std::string_view, std::string_view>;

/// name's text in table, or empty.
std::string_view helpIn(const HelpTable& table, std::string_view name);

/// A map with exactly one key among names (`{sphere: {...}}`): that key and its value.
/// Otherwise adds "WHAT must be a map with one key, one of: A, B" or "unknown WHAT 'K' (did
/// you mean ...)" at the node and returns nullopt.
std::optional<std::pair<YNode, YNode>> singleKey(const YNode& node, DiagnosticList& diags, const std::string& what,
                                                 const std::vector<std::string>& names);

}  // namespace sprig
