/// organisms/detail/volume_backend.h through OpenVDB's volumeToMesh.

#include <openvdb/openvdb.h>
#include <openvdb/tools/VolumeToMesh.h>

#include "backends/backends.h"

namespace sprig::backends {

namespace {

PolyMesh levelSetMesh(const ScalarVolume& volume, double iso, float background) {
  openvdb::initialize();
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
  return mesh;
}

}  // namespace

const organisms::detail::VolumeBackend& vdbVolume() {
  static const organisms::detail::VolumeBackend table{&levelSetMesh};
  return table;
}

}  // namespace sprig::backends
