#include <algorithm>
#include <array>
#include <map>
#include <vector>

#include "solids/solid.h"

namespace sprig::solids {

SmoothStats smoothInterior(TetMesh& mesh, int rounds) {
  SmoothStats st;
  st.before = measureQuality(mesh);
  if (mesh.tets.empty()) return st;
  double total = 0;
  for (size_t t = 0; t < mesh.tets.size(); ++t) total += mesh.volume(t);
  const double ideal = total / double(mesh.tets.size());
  // Vertices on a face between two materials or on the visible interface stay where they
  // are, so every interface keeps its exact position and shape.
  std::vector<uint8_t> fixed(mesh.positions.size(), 0);
  for (const auto& t : visibleInterface(mesh))
    for (uint32_t v : t.v) fixed[v] = 1;
  for (const auto& t : materialInterfaces(mesh))
    for (uint32_t v : t.v) fixed[v] = 1;
  // Tetrahedra around each vertex (compressed rows).
  std::vector<uint32_t> start(mesh.positions.size() + 1, 0), around(mesh.tets.size() * 4);
  for (const auto& q : mesh.tets)
    for (uint32_t v : q) ++start[v + 1];
  for (size_t i = 0; i < mesh.positions.size(); ++i) start[i + 1] += start[i];
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  for (uint32_t t = 0; t < mesh.tets.size(); ++t)
    for (uint32_t v : mesh.tets[t]) around[fill[v]++] = t;

  auto worstAround = [&](uint32_t v) {
    double w = 1e9;
    for (uint32_t k = start[v]; k < start[v + 1]; ++k) {
      const auto& q = mesh.tets[around[k]];
      w = std::min(w, tetQuality(mesh.positions[q[0]], mesh.positions[q[1]], mesh.positions[q[2]], mesh.positions[q[3]], ideal));
    }
    return w;
  };
  // Sequential in vertex order (the same result at any thread count): move each free vertex
  // toward the centroid of its neighbours, halving the step until the worst tetrahedron
  // around it improves; keep the old position when no step does.
  for (int r = 0; r < rounds; ++r) {
    size_t moved = 0;
    for (uint32_t v = 0; v < mesh.positions.size(); ++v) {
      if (fixed[v] || start[v] == start[v + 1]) continue;
      DVec3 centroid(0.0);
      int n = 0;
      for (uint32_t k = start[v]; k < start[v + 1]; ++k)
        for (uint32_t u : mesh.tets[around[k]])
          if (u != v) centroid += mesh.positions[u], ++n;
      centroid /= double(n);
      const DVec3 old = mesh.positions[v];
      const double before = worstAround(v);
      bool accepted = false;
      for (double step = 1.0; step > 0.1 && !accepted; step *= 0.5) {
        mesh.positions[v] = old + step * (centroid - old);
        accepted = worstAround(v) > before;
      }
      if (accepted) ++moved;
      else mesh.positions[v] = old;
    }
    st.moved += moved;
    if (!moved) break;
  }
  st.after = measureQuality(mesh);
  return st;
}

}  // namespace sprig::solids
