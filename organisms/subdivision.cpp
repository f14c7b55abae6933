#include "organisms/subdivision.h"

#include <opensubdiv/far/error.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <algorithm>
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

/// `width` interleaved floats of one item (F = float or const float), a primvar whose width
/// is known at run time only; Items addresses an array of them as the refiner wants.
template <class F>
struct FloatsVar {
  F* p;
  size_t width;
  void Clear(void* = nullptr) { std::fill_n(p, width, 0.0f); }
  template <class G>
  void AddWithWeight(const FloatsVar<G>& src, float w) {
    for (size_t i = 0; i < width; ++i) p[i] += w * src.p[i];
  }
};
template <class F>
struct Items {
  F* data;
  size_t width;
  FloatsVar<F> operator[](int i) const { return {data + size_t(i) * width, width}; }
};

/// Interpolates src (level - 1) into dst (level) as kind says.
template <class Src, class Dst>
void refine(const Far::PrimvarRefiner& refiner, Primvar kind, int level, const Src& src, Dst& dst) {
  switch (kind) {
    case Primvar::Vertex: refiner.Interpolate(level, src, dst); break;
    case Primvar::Varying: refiner.InterpolateVarying(level, src, dst); break;
    case Primvar::FaceVarying: refiner.InterpolateFaceVarying(level, src, dst); break;
  }
}

/// Throws unless level is 1..levels and coarse and fine hold `width` floats per item of
/// levels level - 1 and level.
void checkSizes(const Subdivision& sub, int level, Primvar kind, size_t coarse, size_t fine, size_t width) {
  auto items = [&](int l) {
    return kind == Primvar::FaceVarying ? sub.topology(l).faceVaryingCount : sub.vertexCount(l);
  };
  if (level < 1 || level > sub.levels() || width == 0 || coarse != width * items(level - 1) || fine != width * items(level))
    throw std::invalid_argument("Subdivision::interpolate: wrong level or array size");
}

// OpenSubdiv reports topology errors through one global callback; the adapter collects the
// message of the factory call in progress (calls are serialized by the mutex).
std::mutex gErrorMutex;
std::string* gErrorSink = nullptr;
void collectError(Far::ErrorType, const char* message) {
  if (gErrorSink) *gErrorSink += (gErrorSink->empty() ? "" : "; ") + std::string(message);
}
// Its warnings (a crease that is not an edge) would go to stderr; the constructor checks
// what they warn of and throws instead.
void ignoreWarning(const char*) {}

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
  if (level.GetNumFVarChannels() > 0) {
    t.faceVaryingCount = size_t(level.GetNumFVarValues());
    t.faceVaryingIndices.reserve(t.faceVertices.size());
    for (int f = 0; f < faces; ++f) {
      auto fv = level.GetFaceFVarValues(f);
      for (int i = 0; i < fv.size(); ++i) t.faceVaryingIndices.push_back(uint32_t(fv[i]));
    }
  }
  return t;
}

}  // namespace

struct Subdivision::Impl {
  std::unique_ptr<Far::TopologyRefiner> refiner;
  std::unique_ptr<Far::PrimvarRefiner> primvar;
};

namespace {

/// Throws std::invalid_argument unless mesh and options describe a refinable control mesh.
void checkControlMesh(const ControlMesh& mesh, int levels, const SubdivisionOptions& options) {
  if (levels < 0 || levels > 10) throw std::invalid_argument("subdivision levels must be 0..10, got " + std::to_string(levels));
  if (mesh.faceSizes.empty()) throw std::invalid_argument("the control mesh has no faces");
  const bool loop = options.scheme == SubdivisionScheme::Loop;
  size_t corners = 0;
  for (size_t f = 0; f < mesh.faceSizes.size(); ++f) {
    if (mesh.faceSizes[f] < 3) throw std::invalid_argument("face " + std::to_string(f) + " has fewer than 3 vertices");
    if (loop && mesh.faceSizes[f] != 3)
      throw std::invalid_argument("Loop subdivision needs triangles; face " + std::to_string(f) + " has " +
                                  std::to_string(mesh.faceSizes[f]) + " vertices");
    corners += mesh.faceSizes[f];
  }
  if (corners != mesh.faceVertices.size())
    throw std::invalid_argument("the face sizes add up to " + std::to_string(corners) + " corners, the mesh lists " +
                                std::to_string(mesh.faceVertices.size()));
  for (uint32_t v : mesh.faceVertices)
    if (v >= mesh.positions.size())
      throw std::invalid_argument("a face uses vertex " + std::to_string(v) + " of " + std::to_string(mesh.positions.size()));
  for (const auto& [a, b] : options.creases)
    if (a >= mesh.positions.size() || b >= mesh.positions.size())
      throw std::invalid_argument("the crease " + std::to_string(a) + "-" + std::to_string(b) + " is not an edge of the mesh");
  if (options.faceVaryingIndices.empty()) return;
  if (options.faceVaryingIndices.size() != corners)
    throw std::invalid_argument("the face-varying channel has " + std::to_string(options.faceVaryingIndices.size()) +
                                " indices for " + std::to_string(corners) + " corners");
  for (uint32_t i : options.faceVaryingIndices)
    if (i >= options.faceVaryingCount)
      throw std::invalid_argument("a corner uses face-varying value " + std::to_string(i) + " of " +
                                  std::to_string(options.faceVaryingCount));
}

}  // namespace

Subdivision::Subdivision(const ControlMesh& mesh, int levels, const SubdivisionOptions& options)
    : impl_(std::make_unique<Impl>()) {
  checkControlMesh(mesh, levels, options);
  std::vector<int> sizes(mesh.faceSizes.begin(), mesh.faceSizes.end());
  std::vector<int> indices(mesh.faceVertices.begin(), mesh.faceVertices.end());
  Far::TopologyDescriptor desc;
  desc.numVertices = int(mesh.positions.size());
  desc.numFaces = int(sizes.size());
  desc.numVertsPerFace = sizes.data();
  desc.vertIndicesPerFace = indices.data();
  std::vector<int> creasePairs;
  for (const auto& [a, b] : options.creases) creasePairs.insert(creasePairs.end(), {int(a), int(b)});
  const std::vector<float> creaseWeights(options.creases.size(), Sdc::Crease::SHARPNESS_INFINITE);
  desc.numCreases = int(options.creases.size());
  desc.creaseVertexIndexPairs = creasePairs.data();
  desc.creaseWeights = creaseWeights.data();
  const std::vector<int> fvarIndices(options.faceVaryingIndices.begin(), options.faceVaryingIndices.end());
  Far::TopologyDescriptor::FVarChannel channel;
  channel.numValues = int(options.faceVaryingCount);
  channel.valueIndices = fvarIndices.data();
  desc.numFVarChannels = fvarIndices.empty() ? 0 : 1;
  desc.fvarChannels = &channel;

  Sdc::Options sdc;
  sdc.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);  // default NONE drops boundary faces
  sdc.SetFVarLinearInterpolation(Sdc::Options::FVAR_LINEAR_ALL);
  const Sdc::SchemeType scheme = options.scheme == SubdivisionScheme::Loop ? Sdc::SCHEME_LOOP : Sdc::SCHEME_CATMARK;
  using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
  std::string errors;
  {
    std::lock_guard lock(gErrorMutex);
    gErrorSink = &errors;
    Far::SetErrorCallback(collectError);
    Far::SetWarningCallback(ignoreWarning);
    impl_->refiner.reset(Factory::Create(desc, Factory::Options(scheme, sdc)));
    if (impl_->refiner) {
      Far::TopologyRefiner::UniformOptions uniform(levels);
      uniform.fullTopologyInLastLevel = true;  // PrimvarRefiner::Limit needs it (else zeros)
      impl_->refiner->RefineUniform(uniform);
    }
    Far::SetErrorCallback(nullptr);
    Far::SetWarningCallback(nullptr);
    gErrorSink = nullptr;
  }
  if (!impl_->refiner) throw std::invalid_argument("OpenSubdiv cannot refine the control mesh: " + errors);
  for (const auto& [a, b] : options.creases)
    if (impl_->refiner->GetLevel(0).FindEdge(int(a), int(b)) == Far::INDEX_INVALID)
      throw std::invalid_argument("the crease " + std::to_string(a) + "-" + std::to_string(b) + " is not an edge of the mesh");
  impl_->primvar = std::make_unique<Far::PrimvarRefiner>(*impl_->refiner);
  topology_.reserve(size_t(levels) + 1);
  for (int l = 0; l <= levels; ++l) topology_.push_back(levelTopology(impl_->refiner->GetLevel(l)));
}

Subdivision::~Subdivision() = default;
Subdivision::Subdivision(Subdivision&&) noexcept = default;
Subdivision& Subdivision::operator=(Subdivision&&) noexcept = default;

uint32_t Subdivision::parentFace(int level, uint32_t face) const {
  if (level < 1 || level > levels() || face >= topology(level).faceCount())
    throw std::invalid_argument("Subdivision::parentFace: wrong level or face");
  return uint32_t(impl_->refiner->GetLevel(level).GetFaceParentFace(int(face)));
}

void Subdivision::interpolate(int level, std::span<const Vec3> coarse, std::span<Vec3> fine) const {
  checkSizes(*this, level, Primvar::Vertex, coarse.size(), fine.size(), 1);
  const auto* src = reinterpret_cast<const PointVar*>(coarse.data());
  auto* dst = reinterpret_cast<PointVar*>(fine.data());
  refine(*impl_->primvar, Primvar::Vertex, level, src, dst);
}

void Subdivision::interpolate(int level, std::span<const float> coarse, std::span<float> fine) const {
  checkSizes(*this, level, Primvar::Vertex, coarse.size(), fine.size(), 1);
  const auto* src = reinterpret_cast<const ScalarVar*>(coarse.data());
  auto* dst = reinterpret_cast<ScalarVar*>(fine.data());
  refine(*impl_->primvar, Primvar::Vertex, level, src, dst);
}

void Subdivision::interpolate(int level, Primvar kind, std::span<const float> coarse, std::span<float> fine,
                              size_t width) const {
  checkSizes(*this, level, kind, coarse.size(), fine.size(), width);
  const Items<const float> src{coarse.data(), width};
  Items<float> dst{fine.data(), width};
  refine(*impl_->primvar, kind, level, src, dst);
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
