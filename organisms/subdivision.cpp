#include "organisms/subdivision.h"

#include <opensubdiv/far/error.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <mutex>
#include <stdexcept>
#include <string>

namespace sprig::organisms {

namespace {

namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

/// A primvar as OpenSubdiv's refiner wants it (Clear + AddWithWeight).
struct PointVar {
  Vec3 p;
  void Clear(void* = nullptr) { p = Vec3(0.0f); }
  void AddWithWeight(const PointVar& src, float w) { p += w * src.p; }
};
struct ScalarVar {
  float v;
  void Clear(void* = nullptr) { v = 0.0f; }
  void AddWithWeight(const ScalarVar& src, float w) { v += w * src.v; }
};
static_assert(sizeof(PointVar) == sizeof(Vec3) && sizeof(ScalarVar) == sizeof(float));

// OpenSubdiv reports topology errors through one global callback; the adapter collects the
// message of the factory call in progress (calls are serialized by the mutex).
std::mutex gErrorMutex;
std::string* gErrorSink = nullptr;
void collectError(Far::ErrorType, const char* message) {
  if (gErrorSink) *gErrorSink += (gErrorSink->empty() ? "" : "; ") + std::string(message);
}

LevelTopology levelTopology(const Far::TopologyLevel& level) {
  LevelTopology t;
  const int faces = level.GetNumFaces(), verts = level.GetNumVertices();
  t.faceSizes.resize(size_t(faces));
  t.faceOffsets.resize(size_t(faces) + 1);
  t.faceVertices.reserve(size_t(level.GetNumFaceVertices()));
  for (int f = 0; f < faces; ++f) {
    auto fv = level.GetFaceVertices(f);
    t.faceSizes[size_t(f)] = uint32_t(fv.size());
    t.faceOffsets[size_t(f)] = uint32_t(t.faceVertices.size());
    for (int i = 0; i < fv.size(); ++i) t.faceVertices.push_back(uint32_t(fv[i]));
  }
  t.faceOffsets[size_t(faces)] = uint32_t(t.faceVertices.size());
  t.vertexFaceOffsets.resize(size_t(verts) + 1);
  t.boundaryVertex.assign(size_t(verts), 0);
  for (int v = 0; v < verts; ++v) {
    t.vertexFaceOffsets[size_t(v)] = uint32_t(t.vertexFaces.size());
    auto vf = level.GetVertexFaces(v);
    for (int i = 0; i < vf.size(); ++i) t.vertexFaces.push_back(uint32_t(vf[i]));
    t.boundaryVertex[size_t(v)] = level.IsVertexBoundary(v) ? 1 : 0;
  }
  t.vertexFaceOffsets[size_t(verts)] = uint32_t(t.vertexFaces.size());
  return t;
}

}  // namespace

struct Subdivision::Impl {
  std::unique_ptr<Far::TopologyRefiner> refiner;
  std::unique_ptr<Far::PrimvarRefiner> primvar;
};

Subdivision::Subdivision(const ControlMesh& mesh, int levels) : impl_(std::make_unique<Impl>()) {
  if (levels < 0 || levels > 10) throw std::invalid_argument("subdivision levels must be 0..10, got " + std::to_string(levels));
  if (mesh.faceSizes.empty()) throw std::invalid_argument("the control mesh has no faces");
  size_t corners = 0;
  for (size_t f = 0; f < mesh.faceSizes.size(); ++f) {
    if (mesh.faceSizes[f] < 3) throw std::invalid_argument("face " + std::to_string(f) + " has fewer than 3 vertices");
    corners += mesh.faceSizes[f];
  }
  if (corners != mesh.faceVertices.size())
    throw std::invalid_argument("the face sizes add up to " + std::to_string(corners) + " corners, the mesh lists " +
                                std::to_string(mesh.faceVertices.size()));
  for (uint32_t v : mesh.faceVertices)
    if (v >= mesh.positions.size())
      throw std::invalid_argument("a face uses vertex " + std::to_string(v) + " of " + std::to_string(mesh.positions.size()));

  std::vector<int> sizes(mesh.faceSizes.begin(), mesh.faceSizes.end());
  std::vector<int> indices(mesh.faceVertices.begin(), mesh.faceVertices.end());
  Far::TopologyDescriptor desc;
  desc.numVertices = int(mesh.positions.size());
  desc.numFaces = int(sizes.size());
  desc.numVertsPerFace = sizes.data();
  desc.vertIndicesPerFace = indices.data();

  Sdc::Options sdc;
  sdc.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);  // default NONE drops boundary faces
  sdc.SetFVarLinearInterpolation(Sdc::Options::FVAR_LINEAR_CORNERS_ONLY);
  using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
  std::string errors;
  {
    std::lock_guard lock(gErrorMutex);
    gErrorSink = &errors;
    Far::SetErrorCallback(collectError);
    impl_->refiner.reset(Factory::Create(desc, Factory::Options(Sdc::SCHEME_CATMARK, sdc)));
    if (impl_->refiner) {
      Far::TopologyRefiner::UniformOptions uniform(levels);
      uniform.fullTopologyInLastLevel = true;  // PrimvarRefiner::Limit needs it (else zeros)
      impl_->refiner->RefineUniform(uniform);
    }
    Far::SetErrorCallback(nullptr);
    gErrorSink = nullptr;
  }
  if (!impl_->refiner) throw std::invalid_argument("OpenSubdiv cannot refine the control mesh: " + errors);
  impl_->primvar = std::make_unique<Far::PrimvarRefiner>(*impl_->refiner);
  topology_.reserve(size_t(levels) + 1);
  for (int l = 0; l <= levels; ++l) topology_.push_back(levelTopology(impl_->refiner->GetLevel(l)));
}

Subdivision::~Subdivision() = default;
Subdivision::Subdivision(Subdivision&&) noexcept = default;
Subdivision& Subdivision::operator=(Subdivision&&) noexcept = default;

void Subdivision::interpolate(int level, std::span<const Vec3> coarse, std::span<Vec3> fine) const {
  if (level < 1 || level > levels() || coarse.size() != vertexCount(level - 1) || fine.size() != vertexCount(level))
    throw std::invalid_argument("Subdivision::interpolate: wrong level or array size");
  const auto* src = reinterpret_cast<const PointVar*>(coarse.data());
  auto* dst = reinterpret_cast<PointVar*>(fine.data());
  impl_->primvar->Interpolate(level, src, dst);
}

void Subdivision::interpolate(int level, std::span<const float> coarse, std::span<float> fine) const {
  if (level < 1 || level > levels() || coarse.size() != vertexCount(level - 1) || fine.size() != vertexCount(level))
    throw std::invalid_argument("Subdivision::interpolate: wrong level or array size");
  const auto* src = reinterpret_cast<const ScalarVar*>(coarse.data());
  auto* dst = reinterpret_cast<ScalarVar*>(fine.data());
  impl_->primvar->Interpolate(level, src, dst);
}

void Subdivision::limit(std::span<const Vec3> finest, std::span<Vec3> position, std::span<Vec3> du,
                        std::span<Vec3> dv) const {
  const size_t n = vertexCount(levels());
  if (finest.size() != n) throw std::invalid_argument("Subdivision::limit: wrong array size");
  if (levels() == 0) throw std::invalid_argument("Subdivision::limit needs at least one level");
  std::vector<Vec3> p(n), a(n), b(n);
  const auto* src = reinterpret_cast<const PointVar*>(finest.data());
  auto* pp = reinterpret_cast<PointVar*>(p.data());
  auto* pa = reinterpret_cast<PointVar*>(a.data());
  auto* pb = reinterpret_cast<PointVar*>(b.data());
  impl_->primvar->Limit(src, pp, pa, pb);
  if (!position.empty()) std::copy(p.begin(), p.end(), position.begin());
  if (!du.empty()) std::copy(a.begin(), a.end(), du.begin());
  if (!dv.empty()) std::copy(b.begin(), b.end(), dv.begin());
}

}  // namespace sprig::organisms
