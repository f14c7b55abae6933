#include "solids/tet_io.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <optional>
#include <stdexcept>

#include "core/atomic_file.h"

namespace sprig::solids {

namespace {

void appendf(std::string& s, const char* fmt, auto... args) {
  char buf[256];
  const int n = std::snprintf(buf, sizeof buf, fmt, args...);
  s.append(buf, size_t(std::max(0, n)));
}

/// Materials used, ascending, and each tetrahedron's index in that list.
std::vector<uint16_t> usedMaterials(const TetMesh& m) {
  std::vector<uint16_t> used(m.materials);
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  return used;
}

std::string msh(const TetMesh& m, const std::vector<Material>& materials) {
  std::string s = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  const std::vector<uint16_t> used = usedMaterials(m);
  // Physical tag and entity tag of material id k: its rank in `used` + 1.
  appendf(s, "$PhysicalNames\n%zu\n", used.size());
  for (size_t i = 0; i < used.size(); ++i) appendf(s, "3 %zu \"%s\"\n", i + 1, materials[used[i]].name.c_str());
  s += "$EndPhysicalNames\n";
  // Each volume entity's box: the box of its tetrahedra.
  std::vector<DBox3> boxes(used.size());
  std::vector<std::vector<size_t>> tetsOf(used.size());
  for (size_t t = 0; t < m.tets.size(); ++t) {
    const size_t e = size_t(std::lower_bound(used.begin(), used.end(), m.materials[t]) - used.begin());
    tetsOf[e].push_back(t);
    for (uint32_t v : m.tets[t]) boxes[e].extend(m.positions[v]);
  }
  appendf(s, "$Entities\n0 0 0 %zu\n", used.size());
  for (size_t e = 0; e < used.size(); ++e)
    appendf(s, "%zu %.9g %.9g %.9g %.9g %.9g %.9g 1 %zu 0\n", e + 1, boxes[e].lo.x, boxes[e].lo.y, boxes[e].lo.z,
            boxes[e].hi.x, boxes[e].hi.y, boxes[e].hi.z, e + 1);
  s += "$EndEntities\n";
  const size_t n = m.positions.size();
  appendf(s, "$Nodes\n1 %zu 1 %zu\n3 1 0 %zu\n", n, n, n);
  for (size_t v = 0; v < n; ++v) appendf(s, "%zu\n", v + 1);
  for (const DVec3& p : m.positions) appendf(s, "%.9g %.9g %.9g\n", p.x, p.y, p.z);
  s += "$EndNodes\n";
  appendf(s, "$Elements\n%zu %zu 1 %zu\n", used.size(), m.tets.size(), m.tets.size());
  size_t tag = 1;
  for (size_t e = 0; e < used.size(); ++e) {
    appendf(s, "3 %zu 4 %zu\n", e + 1, tetsOf[e].size());
    for (size_t t : tetsOf[e]) {
      const auto& q = m.tets[t];
      appendf(s, "%zu %u %u %u %u\n", tag++, q[0] + 1, q[1] + 1, q[2] + 1, q[3] + 1);
    }
  }
  s += "$EndElements\n";
  return s;
}

std::string vtu(const TetMesh& m) {
  std::string s = "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
                  "  <UnstructuredGrid>\n";
  appendf(s, "    <Piece NumberOfPoints=\"%zu\" NumberOfCells=\"%zu\">\n", m.positions.size(), m.tets.size());
  s += "      <Points>\n        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (const DVec3& p : m.positions) appendf(s, "%.9g %.9g %.9g\n", p.x, p.y, p.z);
  s += "        </DataArray>\n      </Points>\n      <Cells>\n"
       "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const auto& q : m.tets) appendf(s, "%u %u %u %u\n", q[0], q[1], q[2], q[3]);
  s += "        </DataArray>\n        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (size_t t = 0; t < m.tets.size(); ++t) appendf(s, "%zu\n", 4 * (t + 1));
  s += "        </DataArray>\n        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (size_t t = 0; t < m.tets.size(); ++t) s += "10\n";
  s += "        </DataArray>\n      </Cells>\n      <CellData Scalars=\"material\">\n"
       "        <DataArray type=\"Int32\" Name=\"material\" format=\"ascii\">\n";
  for (uint16_t k : m.materials) appendf(s, "%u\n", unsigned(k));
  s += "        </DataArray>\n      </CellData>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
  return s;
}

std::string medit(const TetMesh& m) {
  std::string s = "MeshVersionFormatted 2\nDimension 3\n";
  appendf(s, "Vertices\n%zu\n", m.positions.size());
  for (const DVec3& p : m.positions) appendf(s, "%.9g %.9g %.9g 0\n", p.x, p.y, p.z);
  appendf(s, "Tetrahedra\n%zu\n", m.tets.size());
  for (size_t t = 0; t < m.tets.size(); ++t) {
    const auto& q = m.tets[t];
    appendf(s, "%u %u %u %u %u\n", q[0] + 1, q[1] + 1, q[2] + 1, q[3] + 1, unsigned(m.materials[t]) + 1);
  }
  s += "End\n";
  return s;
}

}  // namespace

std::optional<TetFormat> tetFormatFor(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".msh") return TetFormat::Msh;
  if (ext == ".vtu") return TetFormat::Vtu;
  if (ext == ".mesh") return TetFormat::Medit;
  return std::nullopt;
}

std::string formatTetMesh(const TetMesh& mesh, const std::vector<Material>& materials, TetFormat format) {
  switch (format) {
    case TetFormat::Msh: return msh(mesh, materials);
    case TetFormat::Vtu: return vtu(mesh);
    case TetFormat::Medit: return medit(mesh);
  }
  return {};
}

void writeTetMesh(const TetMesh& mesh, const std::vector<Material>& materials, const std::filesystem::path& path) {
  const std::optional<TetFormat> f = tetFormatFor(path);
  if (!f) throw std::invalid_argument("'" + path.string() + "': tetrahedral meshes are written as .msh, .vtu or .mesh");
  writeFileAtomic(path, formatTetMesh(mesh, materials, *f));
}

}  // namespace sprig::solids
