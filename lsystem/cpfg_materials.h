#pragma once
/// cpfg's materials file (`-M NAME.mat` on a vlab object's cpfg command line, written by
/// vlab's medit; irisGL.c, load_in_materials): records of 15 bytes, the material's colour
/// index, then its transparency, ambient, diffuse, emissive and specular red-green-blue and
/// its shininess, one byte each.

#include <string>
#include <string_view>
#include <vector>

#include "core/diagnostics.h"
#include "core/types.h"

namespace sprig::lsystem {

/// Bytes per record of a materials file.
inline constexpr size_t kCpfgMaterialRecord = 15;

/// The palette of a materials file's bytes (fileName for diagnostics): 256 entries, entry i
/// the diffuse colour of material i (byte / 255), cpfg's default material (diffuse white)
/// where no record names i; a later record of the same index replaces an earlier one. A
/// material with non-zero transparency adds a note to notes (Sprig draws it opaque). Throws
/// InputError at the file when bytes are empty or not a whole number of records.
std::vector<Vec3> parseCpfgMaterials(std::string_view bytes, const std::string& fileName, std::vector<Diagnostic>& notes);

}  // namespace sprig::lsystem
