#include "organisms/iso_surface.h"

#include <algorithm>
#include <stdexcept>

#include "organisms/detail/volume_backend.h"

namespace sprig::organisms {

PolyMesh isoSurface(const ScalarVolume& volume, double iso) {
  const auto [lo, hi] = std::minmax_element(volume.values.begin(), volume.values.end());
  if (volume.values.empty() || *hi <= iso || *lo > iso)
    throw std::invalid_argument("the iso value " + std::to_string(iso) + " does not cross the volume (its values lie in " +
                                std::to_string(*lo) + ".." + std::to_string(*hi) + ")");
  // Level-set convention: negative inside. Outside the volume lies the background, the
  // farthest value above 0 any voxel has, so the surface closes at the volume's border.
  const float background = std::max(1.0f, float(iso - *lo));
  PolyMesh mesh = detail::volumeBackend().levelSetMesh(volume, iso, background);
  // Orient outward: the enclosed volume (divergence theorem over a fan of each face) must
  // be positive.
  double signedVolume = 0;
  size_t corner = 0;
  for (uint32_t n : mesh.faceSizes) {
    const uint32_t* v = mesh.faceVertices.data() + corner;
    for (uint32_t c = 1; c + 1 < n; ++c)
      signedVolume += glm::dot(glm::dvec3(mesh.positions[v[0]]),
                               glm::cross(glm::dvec3(mesh.positions[v[c]]), glm::dvec3(mesh.positions[v[c + 1]])));
    corner += n;
  }
  if (signedVolume < 0) {
    corner = 0;
    for (uint32_t n : mesh.faceSizes) {
      std::reverse(mesh.faceVertices.begin() + corner, mesh.faceVertices.begin() + corner + n);
      corner += n;
    }
  }
  return mesh;
}

}  // namespace sprig::organisms
