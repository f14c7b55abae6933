#pragma once
/// A JSON Schema (draft-07) for species files, so that editors complete and check them.
///
/// Generated, not written: the readers of the species keys (model/species.cpp and each
/// kind's reader) are run once per kind in describe mode (model/detail/key_recorder.h), and
/// what they ask for — each key, what it does (the reader's `Key` help, the hover text in
/// editors), its type, range, default and whether other keys are errors — becomes the
/// schema. Colours carry `errorMessage`/`patternErrorMessage`, the readable messages
/// yaml-language-server shows (docs/EDITORS.md). The schema and the reader cannot disagree about a key or a
/// range. What the readers check beyond one key (a pair of keys that exclude each other,
/// a referenced file that must exist, a grammar's text) stays with `sprig check`.

#include <string>

namespace sprig {

/// The schema as JSON text (deterministic: the same bytes for the same Sprig). Cost: a
/// few milliseconds (each kind's reader runs once on an empty document).
std::string speciesSchemaJson();

}  // namespace sprig
