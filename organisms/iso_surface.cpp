#include "organisms/iso_surface.h"

#include <algorithm>
#include <stdexcept>

#include <openvdb/openvdb.h>
#include <openvdb/tools/VolumeToMesh.h>

namespace sprig::organisms {

PolyMesh isoSurface(const ScalarVolume& volume, double iso) {
  openvdb::initialize();
  const auto [lo, hi] = std::minmax_element(volume.values.begin(), volume.values.end());
  if (volume.values.empty() || *hi <= iso || *lo > iso)
    throw std::invalid_argument("the iso value " + std::to_string(iso) + " does not cross the volume (its values lie in " +
                                std::to_string(*lo) + ".." + std::to_string(*hi) + ")");
  // Level-set convention: negative inside. Outside the volume lies the background, the
  // farthest value above 0 any voxel has, so the surface closes at the volume's border.
  const float background = std::max(1.0f, float(iso - *lo));
  auto grid = openvdb::FloatGrid::create(background);
  openvdb::math::Mat4d m = openvdb::math::Mat4d::identity();
  m.preScale(openvdb::Vec3d(volume.voxel[0], volume.voxel[1], volume.voxel[2]));
  m.postTranslate(openvdb::Vec3d(volume.origin[0], volume.origin[1], volume.origin[2]));
  grid->setTransform(openvdb::math::Transform::createLinearTransform(m));
  // An accessor the tree does not register (IsSafe = false): the grid is filled here and
  // nobody else holds it, so registration would only cost.
  openvdb::tree::ValueAccessor<openvdb::FloatTree, false> acc(grid->tree());
  for (int k = 0; k < volume.dims[2]; ++k)
    for (int j = 0; j < volume.dims[1]; ++j)
      for (int i = 0; i < volume.dims[0]; ++i) acc.setValue(openvdb::Coord(i, j, k), float(iso - volume.at(i, j, k)));

  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(*grid, points, triangles, quads, 0.0, 0.0, true);

  PolyMesh mesh;
  mesh.positions.reserve(points.size());
  for (const auto& p : points) mesh.positions.push_back(Vec3(p.x(), p.y(), p.z()));
  for (const auto& q : quads) {
    mesh.faceSizes.push_back(4);
    for (int c = 0; c < 4; ++c) mesh.faceVertices.push_back(q[c]);
  }
  for (const auto& t : triangles) {
    mesh.faceSizes.push_back(3);
    for (int c = 0; c < 3; ++c) mesh.faceVertices.push_back(t[c]);
  }
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
