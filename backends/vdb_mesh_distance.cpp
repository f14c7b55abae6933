/// solids/detail/mesh_distance_backend.h through OpenVDB's meshToSignedDistanceField.

#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/MeshToVolume.h>

#include <mutex>

#include "backends/backends.h"

namespace sprig::backends {

namespace {

using solids::detail::DistanceGrid;

class VdbDistanceGrid final : public DistanceGrid {
 public:
  explicit VdbDistanceGrid(openvdb::FloatGrid::Ptr grid) : grid_(std::move(grid)) {}

  void sample(const Vec3* points, size_t count, float* out) const override {
    openvdb::FloatGrid::ConstAccessor acc = grid_->getConstAccessor();
    openvdb::tools::GridSampler<openvdb::FloatGrid::ConstAccessor, openvdb::tools::BoxSampler> s(acc, grid_->transform());
    for (size_t i = 0; i < count; ++i) out[i] = s.wsSample(openvdb::Vec3d(points[i].x, points[i].y, points[i].z));
  }

 private:
  openvdb::FloatGrid::Ptr grid_;
};

std::unique_ptr<DistanceGrid> build(const std::vector<Vec3>& points, const std::vector<glm::uvec3>& triangles, double cell,
                                    const Vec3& origin, float bandVoxels) {
  {
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
  }
  std::vector<openvdb::Vec3s> vdbPoints;
  vdbPoints.reserve(points.size());
  for (const Vec3& p : points) vdbPoints.emplace_back(p.x, p.y, p.z);
  std::vector<openvdb::Vec3I> vdbTriangles;
  vdbTriangles.reserve(triangles.size());
  for (const glm::uvec3& t : triangles) vdbTriangles.emplace_back(t.x, t.y, t.z);
  auto xform = openvdb::math::Transform::createLinearTransform(cell);
  xform->postTranslate(openvdb::Vec3d(origin.x, origin.y, origin.z));
  std::vector<openvdb::Vec4I> quads;
  openvdb::FloatGrid::Ptr grid = openvdb::tools::meshToSignedDistanceField<openvdb::FloatGrid>(
      *xform, vdbPoints, vdbTriangles, quads, bandVoxels, bandVoxels);
  return std::make_unique<VdbDistanceGrid>(std::move(grid));
}

}  // namespace

const solids::detail::MeshDistanceBackend& vdbMeshDistance() {
  static const solids::detail::MeshDistanceBackend table{&build};
  return table;
}

}  // namespace sprig::backends
