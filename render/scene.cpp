#include "render/scene.h"

#include "render/detail/scene_impl.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>

namespace sprig::render {

using detail::GeometryRecord;

namespace {

void onEmbreeError(void* userPtr, RTCError code, const char* str) {
  auto* message = static_cast<std::string*>(userPtr);
  if (code != RTC_ERROR_NONE && message->empty()) *message = "Embree error " + std::to_string(code) + ": " + (str ? str : "");
}

uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

uint64_t floatBits(float f) {
  uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

/// A number in [0, 1) from ray i of a filter call and primitive prim: the same for the same
/// ray and primitive at any thread count.
float rayUnit(const RTCFilterFunctionNArguments* args, unsigned i, uint32_t prim) {
  uint64_t h = 0x9e3779b97f4a7c15ull ^ prim;
  for (float f : {RTCRayN_org_x(args->ray, args->N, i), RTCRayN_org_y(args->ray, args->N, i),
                  RTCRayN_org_z(args->ray, args->N, i), RTCRayN_dir_x(args->ray, args->N, i),
                  RTCRayN_dir_y(args->ray, args->N, i), RTCRayN_dir_z(args->ray, args->N, i)})
    h = mix64(h ^ floatBits(f));
  return static_cast<float>(h >> 40) * (1.0f / 16777216.0f);
}

/// True when Embree can trace the ray (its RayK::valid(): origin and direction within
/// ±1.8e18, tnear and tfar not NaN). Scene::intersect and Scene::occluded answer every other
/// ray with a miss rather than hand it on (Embree asserts on it).
bool traceable(const Vec3& origin, const Vec3& direction, float tnear, float tfar) {
  constexpr float kLarge = 1.844e18f;
  for (int a = 0; a < 3; ++a)
    if (!(std::abs(origin[a]) <= kLarge) || !(std::abs(direction[a]) <= kLarge)) return false;
  return !std::isnan(tnear) && !std::isnan(tfar) && tnear >= 0.0f;
}

/// Camera rays skip the hits an image map cuts out (alpha at or below its cutoff).
void imageIntersectFilter(const RTCFilterFunctionNArguments* args) {
  const auto* data = static_cast<const detail::ImageMapData*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    const float a = data->sample(RTCHitN_primID(args->hit, args->N, i), RTCHitN_u(args->hit, args->N, i),
                                 RTCHitN_v(args->hit, args->N, i)).a;
    if (!(a > data->map->alphaCutoff)) args->valid[i] = 0;
  }
}

/// Shadow and sky rays pass the hits an image map cuts out, and pass a partly covering hit
/// (alpha below 1) with probability 1 - alpha (a hash of the ray and the triangle).
void imageOcclusionFilter(const RTCFilterFunctionNArguments* args) {
  const auto* data = static_cast<const detail::ImageMapData*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    const uint32_t prim = RTCHitN_primID(args->hit, args->N, i);
    const float a = data->sample(prim, RTCHitN_u(args->hit, args->N, i), RTCHitN_v(args->hit, args->N, i)).a;
    if (!(a > data->map->alphaCutoff) || (a < 1.0f && rayUnit(args, i, prim) >= a)) args->valid[i] = 0;
  }
}

/// The record of a triangle mesh with one material (Scene::addMesh); throws as addMesh.
GeometryRecord meshRecord(const Scene::Impl& impl, const Mesh& mesh, uint32_t material,
                          const std::vector<Vec3>& triangleColors, const std::vector<Vec3>& vertexSurfaces);

}  // namespace

double detail::ImageMapData::texelsPerPixel(uint32_t prim, float u, float v) const {
  if (!view) return 0.0;
  using D3 = glm::dvec3;
  using D2 = glm::dvec2;
  const glm::uvec3& tri = triangles[prim];
  const D3 p0(positions[tri.x]), p1(positions[tri.y]), p2(positions[tri.z]);
  const D3 e1 = p1 - p0, e2 = p2 - p0;
  const D3 p = (1.0 - double(u) - double(v)) * p0 + double(u) * p1 + double(v) * p2;
  const D3 d = p - D3(view->eye);  // the view ray to the hit
  const double depth = glm::dot(d, D3(view->forward));
  const double a11 = glm::dot(e1, e1), a12 = glm::dot(e1, e2), a22 = glm::dot(e2, e2);
  const double det = a11 * a22 - a12 * a12;
  if (!(depth > 0.0) || !(det > 0.0)) return 0.0;
  const D3 n = glm::cross(e1, e2);
  const double nd = glm::dot(n, d);
  if (nd == 0.0) return std::numeric_limits<double>::infinity();
  const D2 size(map->width, map->height);
  const D2 duv1 = D2(uvs[tri.y] - uvs[tri.x]) * size, duv2 = D2(uvs[tri.z] - uvs[tri.x]) * size;
  const double pixel = double(view->pixelPerDepth) * depth;  // world size of a pixel at the hit's depth
  double rho = 0.0;
  for (const Vec3& axis : {view->right, view->up}) {
    // The neighbouring pixel's view ray meets the triangle's plane at p + dp (first order).
    const D3 step = pixel * D3(axis);
    const D3 dp = step - d * (glm::dot(n, step) / nd);
    // dp = a e1 + b e2 in the plane (normal equations), so its texel step is a duv1 + b duv2.
    const double b1 = glm::dot(e1, dp), b2 = glm::dot(e2, dp);
    const double a = (a22 * b1 - a12 * b2) / det, b = (a11 * b2 - a12 * b1) / det;
    rho = std::max(rho, glm::length(a * duv1 + b * duv2));
  }
  return rho;
}

Vec4 detail::ImageMapData::sample(uint32_t prim, float u, float v) const {
  const glm::uvec3& tri = triangles[prim];
  const Vec2 uv = (1.0f - u - v) * uvs[tri.x] + u * uvs[tri.y] + v * uvs[tri.z];
  return map->sample(uv, texelsPerPixel(prim, u, v));
}

uint32_t Scene::Impl::attach(RTCGeometry geometry, GeometryRecord record) {
  rtcCommitGeometry(geometry);
  uint32_t id = static_cast<uint32_t>(records.size());
  rtcAttachGeometryByID(scene, geometry, id);
  rtcReleaseGeometry(geometry);
  anyGeometry = true;
  records.push_back(std::move(record));
  if (!error.empty()) throw std::runtime_error(error);
  return id;
}

void Scene::Impl::setBallVertices(RTCGeometry geometry, const std::vector<Vec4>& balls) {
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                                        4 * sizeof(float), balls.size()));
  for (size_t i = 0; i < balls.size(); ++i) {
    const Vec4& c = balls[i];
    for (int k = 0; k < 4; ++k) v[4 * i + k] = c[k];
    bounds.extend(Box3{Vec3(c) - c.w, Vec3(c) + c.w});
  }
}

uint32_t Scene::Impl::addTriangles(GeometryRecord record) {
  RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                        3 * sizeof(float), record.positions.size()));
  for (size_t i = 0; i < record.positions.size(); ++i) {
    v[3 * i] = record.positions[i].x;
    v[3 * i + 1] = record.positions[i].y;
    v[3 * i + 2] = record.positions[i].z;
    bounds.extend(record.positions[i]);
  }
  auto* t = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                           3 * sizeof(uint32_t), record.triangles.size()));
  for (size_t i = 0; i < record.triangles.size(); ++i) {
    t[3 * i] = record.triangles[i].x;
    t[3 * i + 1] = record.triangles[i].y;
    t[3 * i + 2] = record.triangles[i].z;
  }
  stats.triangles += record.triangles.size();
  record.kind = GeometryRecord::Kind::Triangles;
  if (record.image && record.image->map->alphaCutoff >= 0.0f) {
    rtcSetGeometryUserData(g, const_cast<detail::ImageMapData*>(record.image.get()));
    rtcSetGeometryIntersectFilterFunction(g, imageIntersectFilter);
    rtcSetGeometryOccludedFilterFunction(g, imageOcclusionFilter);
  }
  return attach(g, std::move(record));
}

Scene::Scene() : impl_(std::make_unique<Impl>()) {
  impl_->device = rtcNewDevice(nullptr);
  if (!impl_->device) throw std::runtime_error("cannot create the Embree device");
  rtcSetDeviceErrorFunction(impl_->device, onEmbreeError, &impl_->error);
  impl_->scene = rtcNewScene(impl_->device);
  rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  impl_->materials.push_back(Material{});
}

Scene::~Scene() {
  if (impl_->scene) rtcReleaseScene(impl_->scene);
  if (impl_->device) rtcReleaseDevice(impl_->device);
}

uint32_t Scene::addMaterial(const Material& m) {
  impl_->materials.push_back(m);
  return static_cast<uint32_t>(impl_->materials.size() - 1);
}

const Material& Scene::material(uint32_t id) const { return impl_->materials.at(id); }

namespace {

/// Shadow and sky rays pass a widened curve with probability 1 - opacity: a hash of the
/// ray and the segment, so the decision is the same at any thread count.
void thinOcclusionFilter(const RTCFilterFunctionNArguments* args) {
  const auto* data = static_cast<const detail::CurveData*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    const uint32_t prim = RTCHitN_primID(args->hit, args->N, i);
    const float u = RTCHitN_u(args->hit, args->N, i);
    const float opacity = data->opacity(prim, std::clamp(u, 0.0f, 1.0f));
    if (opacity >= 1.0f) continue;
    if (rayUnit(args, i, prim) >= opacity) args->valid[i] = 0;
  }
}

/// The pixel of camera in an image height rows tall.
detail::PixelView pixelViewOf(const Camera& camera, int height) {
  const CameraBasis b = camera.basis();
  return {camera.position, b.forward, b.right, b.up, camera.pixelPerDepth(height)};
}

}  // namespace

void Scene::setPixelFootprint(const Camera& camera, int width, int height, float minPixels) {
  if (impl_->anyGeometry) throw std::logic_error("Scene::setPixelFootprint after geometry was added");
  impl_->view.reset();
  impl_->footprint.reset();
  if (width < 1 || height < 1) return;
  const detail::PixelView v = pixelViewOf(camera, height);
  impl_->view = v;
  if (minPixels <= 0.0f) return;
  PixelFootprint f;
  f.eye = v.eye;
  f.forward = v.forward;
  f.pixelPerDepth = v.pixelPerDepth;
  f.minPixels = minPixels;
  impl_->footprint = f;
}

void Scene::setCellFootprint(const Camera& camera, int height) {
  if (impl_->anyGeometry) throw std::logic_error("Scene::setCellFootprint after geometry was added");
  impl_->cellView.reset();
  if (height < 1) return;
  impl_->cellView = pixelViewOf(camera, height);
}

void Scene::setExpectedSamples(const Camera& camera, int width, int height, int spp) {
  if (impl_->anyGeometry) throw std::logic_error("Scene::setExpectedSamples after geometry was added");
  impl_->expected.reset();
  if (width < 1 || height < 1 || spp < 1) return;
  detail::ExpectedSamples e;
  e.view = pixelViewOf(camera, height);
  e.width = width;
  e.height = height;
  e.spp = spp;
  impl_->expected = e;
}

uint32_t Scene::Impl::addCurveGeometry(std::shared_ptr<detail::CurveData> data, uint32_t material) {
  data->drawn = data->real;
  if (footprint) {
    followsCamera = true;  // another camera may widen other segments
    for (Vec4& v : data->drawn) {
      const float r = footprint->minRadius(Vec3(v));
      if (v.w < r) {
        v.w = r;
        data->widened = true;
      }
    }
  }
  RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE);
  setBallVertices(g, data->drawn);
  auto* s = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT,
                                                           sizeof(uint32_t), data->segments.size()));
  std::copy(data->segments.begin(), data->segments.end(), s);
  stats.curveSegments += data->segments.size();
  if (data->widened) {
    rtcSetGeometryUserData(g, data.get());
    rtcSetGeometryOccludedFilterFunction(g, thinOcclusionFilter);
  }
  GeometryRecord rec;
  rec.kind = GeometryRecord::Kind::Curves;
  rec.material = material;
  rec.curves = std::move(data);
  return attach(g, std::move(rec));
}

uint32_t Scene::addCurves(const CurveSet& curves, uint32_t material) {
  if (impl_->committed) throw std::logic_error("Scene::addCurves after commit");
  if (material >= impl_->materials.size()) throw std::invalid_argument("Scene::addCurves: unknown material id");
  if (impl_->footprint) {
    // Widened curves: separate segments (a joined flag would fold the drawn tube's end
    // caps into its neighbours, which the opacity of each segment does not account for).
    auto data = std::make_shared<detail::CurveData>();
    data->real = curves.vertices;
    data->segments = curves.segments;
    return impl_->addCurveGeometry(std::move(data), material);
  }
  RTCGeometry g = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE);
  impl_->setBallVertices(g, curves.vertices);
  auto* s = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT,
                                                           sizeof(uint32_t), curves.segments.size()));
  std::copy(curves.segments.begin(), curves.segments.end(), s);
  auto* fl = static_cast<uint8_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_FLAGS, 0, RTC_FORMAT_UCHAR,
                                                           sizeof(uint8_t), curves.flags.size()));
  for (size_t i = 0; i < curves.flags.size(); ++i) {
    uint8_t f = 0;
    if (curves.flags[i] & CurveSet::kJoinedBefore) f |= RTC_CURVE_FLAG_NEIGHBOR_LEFT;
    if (curves.flags[i] & CurveSet::kJoinedAfter) f |= RTC_CURVE_FLAG_NEIGHBOR_RIGHT;
    fl[i] = f;
  }
  impl_->stats.curveSegments += curves.segments.size();
  GeometryRecord rec;
  rec.kind = GeometryRecord::Kind::Curves;
  rec.material = material;
  return impl_->attach(g, std::move(rec));
}

std::optional<uint32_t> Scene::addThinAxes(const CurveSet& axes, uint32_t material) {
  if (impl_->committed) throw std::logic_error("Scene::addThinAxes after commit");
  if (material >= impl_->materials.size()) throw std::invalid_argument("Scene::addThinAxes: unknown material id");
  if (!impl_->footprint || axes.empty()) return std::nullopt;
  impl_->followsCamera = true;  // another camera may need other stand-ins
  auto data = std::make_shared<detail::CurveData>();
  data->standIn = true;
  for (uint32_t first : axes.segments) {
    if (first + 1 >= axes.vertices.size()) throw std::invalid_argument("Scene::addThinAxes: segment index out of range");
    const Vec4 &a = axes.vertices[first], &b = axes.vertices[first + 1];
    const float need = 0.5f * (impl_->footprint->minRadius(Vec3(a)) + impl_->footprint->minRadius(Vec3(b)));
    if (0.5f * (a.w + b.w) >= need) continue;
    data->segments.push_back(static_cast<uint32_t>(data->real.size()));
    data->real.push_back(a);
    data->real.push_back(b);
  }
  if (data->segments.empty()) return std::nullopt;
  return impl_->addCurveGeometry(std::move(data), material);
}

uint32_t Scene::addSpheres(const SphereSet& spheres, uint32_t material) {
  if (impl_->committed) throw std::logic_error("Scene::addSpheres after commit");
  if (material >= impl_->materials.size()) throw std::invalid_argument("Scene::addSpheres: unknown material id");
  if (spheres.colors.size() != spheres.spheres.size())
    throw std::invalid_argument("Scene::addSpheres: one colour per sphere expected");
  GeometryRecord rec;
  rec.kind = GeometryRecord::Kind::Spheres;
  rec.material = material;
  rec.primitiveColors = spheres.colors;
  RTCGeometry g = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
  impl_->setBallVertices(g, spheres.spheres);
  impl_->stats.spheres += spheres.spheres.size();
  return impl_->attach(g, std::move(rec));
}

uint32_t Scene::Impl::addTextureTable(const TextureTable& table) {
  const uint32_t base = static_cast<uint32_t>(textures.size());
  for (const ColorTexture& t : table) {
    if (!t) throw std::invalid_argument("Scene::add: empty texture in a part's table");
    textures.push_back(t);
  }
  return base;
}

void Scene::setPrunedTapes(bool on) { impl_->prunedTapes = on; }

namespace {
std::atomic<bool> gPrunedTapesDefault{true};
}  // namespace

void Scene::setPrunedTapesDefault(bool on) { gPrunedTapesDefault.store(on); }
bool Scene::prunedTapesDefault() { return gPrunedTapesDefault.load(); }

std::vector<uint32_t> Scene::add(const Geometry& geometry) {
  impl_->labels.insert(impl_->labels.end(), geometry.labels.begin(), geometry.labels.end());
  std::vector<uint32_t> ids;
  for (const GeometryPart& part : geometry.parts) {
    if (const auto* c = std::get_if<CurvesPart>(&part)) {
      ids.push_back(addCurves(c->curves, addMaterial(c->material)));
    } else if (const auto* sp = std::get_if<SpheresPart>(&part)) {
      ids.push_back(addSpheres(sp->spheres, addMaterial(sp->material)));
    } else if (const auto* m = std::get_if<MeshPart>(&part)) {
      const uint32_t base = impl_->addTextureTable(m->textures);
      Material material = m->material;
      if (material.texture >= 0) material.texture += static_cast<int>(base);
      if (!m->image) {
        ids.push_back(addMesh(m->mesh, addMaterial(material), m->triangleColors, m->vertexSurfaces));
        continue;
      }
      const ImageMap& map = *m->image;
      if (!map.sample || map.width < 1 || map.height < 1 || m->mesh.uvs.size() != m->mesh.positions.size())
        throw std::invalid_argument("Scene::add: a mesh part's image map needs a size, a sample function and one uv per vertex");
      GeometryRecord rec = meshRecord(*impl_, m->mesh, addMaterial(material), m->triangleColors, m->vertexSurfaces);
      auto data = std::make_shared<detail::ImageMapData>();
      data->map = m->image;
      data->positions = m->mesh.positions;
      data->triangles = m->mesh.triangles;
      data->uvs = m->mesh.uvs;
      data->view = impl_->view;
      if (impl_->view) impl_->followsCamera = true;  // texture filtering by the pixel's footprint
      rec.image = std::move(data);
      ids.push_back(impl_->addTriangles(std::move(rec)));
    } else if (const auto* im = std::get_if<ImplicitPart>(&part)) {
      const uint32_t base = impl_->addTextureTable(im->textures);
      const uint32_t material = addMaterial(im->material);
      const uint32_t id = addImplicit(*im->blob, material, im->options);
      impl_->records[id].textureBase = base;
      impl_->records[id].textureCount = static_cast<uint32_t>(im->textures.size());
      ids.push_back(id);
      addThinAxes(im->thinAxes, material);
    } else if (const auto* pm = std::get_if<PolygonizedPart>(&part)) {
      const uint32_t base = impl_->addTextureTable(pm->textures);
      const uint32_t material = addMaterial(pm->material);
      ids.push_back(addPolygonized(*pm->mesh, material, base, static_cast<uint32_t>(pm->textures.size())));
      addThinAxes(pm->thinAxes, material);
    }
  }
  return ids;
}

uint32_t Scene::addMesh(const Mesh& mesh, uint32_t material, const std::vector<Vec3>& triangleColors,
                        const std::vector<Vec3>& vertexSurfaces) {
  return impl_->addTriangles(meshRecord(*impl_, mesh, material, triangleColors, vertexSurfaces));
}

namespace {

GeometryRecord meshRecord(const Scene::Impl& impl, const Mesh& mesh, uint32_t material,
                          const std::vector<Vec3>& triangleColors, const std::vector<Vec3>& vertexSurfaces) {
  if (impl.committed) throw std::logic_error("Scene::addMesh after commit");
  if (material >= impl.materials.size()) throw std::invalid_argument("Scene::addMesh: unknown material id");
  GeometryRecord rec;
  rec.material = material;
  rec.positions = mesh.positions;
  rec.triangles = mesh.triangles;
  if (mesh.normals.size() == mesh.positions.size()) rec.normals = mesh.normals;
  if (mesh.colors.size() == mesh.positions.size()) rec.vertexColors = mesh.colors;
  if (!vertexSurfaces.empty()) {
    if (vertexSurfaces.size() != mesh.positions.size())
      throw std::invalid_argument("Scene::addMesh: one surface (roughness, specular, metallic) per vertex expected");
    rec.vertexSurfaces = vertexSurfaces;
  }
  if (mesh.uvs.size() == mesh.positions.size() && impl.materials[material].texture >= 0) rec.uvs = mesh.uvs;
  if (mesh.materials.size() == mesh.triangles.size()) {
    for (uint32_t m : mesh.materials)
      if (m >= impl.materials.size()) throw std::invalid_argument("Scene::addMesh: unknown per-triangle material id");
    rec.primitiveMaterials = mesh.materials;
  }
  if (!triangleColors.empty()) {
    if (triangleColors.size() != mesh.triangles.size())
      throw std::invalid_argument("Scene::addMesh: one colour per triangle expected");
    rec.primitiveColors = triangleColors;
  }
  for (const auto& t : mesh.triangles)
    if (t.x >= mesh.positions.size() || t.y >= mesh.positions.size() || t.z >= mesh.positions.size())
      throw std::invalid_argument("Scene::addMesh: triangle index out of range");
  return rec;
}

}  // namespace

uint32_t Scene::addTexture(ColorTexture texture) {
  if (!texture) throw std::invalid_argument("Scene::addTexture: empty texture");
  impl_->textures.push_back(std::move(texture));
  return static_cast<uint32_t>(impl_->textures.size() - 1);
}

uint32_t Scene::addTextures(std::shared_ptr<const textures::TextureRegistry> registry) {
  if (!registry) throw std::invalid_argument("Scene::addTextures: null registry");
  uint32_t base = static_cast<uint32_t>(impl_->textures.size());
  for (textures::TextureId id = 0; id < registry->size(); ++id)
    impl_->textures.push_back([registry, id](Vec2 uv, const Vec3& p) { return registry->color(id, uv, p); });
  return base;
}

Vec3 blendedColor(const blobtree::Attributes& a, const Vec3& p, const Material& material, const ColorTexture* textures,
                  size_t count) {
  if (a.textureCount == 0 || count == 0) return material.baseColor;
  Vec3 sum(0);
  float wsum = 0;
  if (material.textureLayers) {
    // Each contributing primitive's texture at its own uv; the colours blended by weight.
    for (int i = 0; i < a.layerCount && i < blobtree::Attributes::kMaxLayers; ++i) {
      const blobtree::Attributes::Layer& l = a.layers[size_t(i)];
      if (!(l.weight > 0)) continue;
      sum += l.weight * (l.textureId < count ? textures[l.textureId](l.uv, p) : material.baseColor);
      wsum += l.weight;
    }
  } else {
    for (int i = 0; i < a.textureCount && i < blobtree::Attributes::kMaxTextures; ++i) {
      const float w = a.textureWeights[size_t(i)];
      if (!(w > 0)) continue;
      const uint16_t id = a.textureIds[size_t(i)];
      sum += w * (id < count ? textures[id](a.uv, p) : material.baseColor);
      wsum += w;
    }
  }
  if (!(wsum > 0)) return material.baseColor;
  return sum / wsum * static_cast<float>(1.0 - material.ridge.darkness(a.contact, p));
}

Vec3 Scene::attributeColor(const blobtree::Attributes& a, const Vec3& p, const Material& material,
                           uint32_t textureBase, uint32_t textureCount) const {
  const size_t count = textureCount == kAllTextures ? impl_->textures.size() : textureCount;
  return blendedColor(a, p, material, impl_->textures.data() + (count > 0 ? textureBase : 0), count);
}

void Scene::commit() {
  rtcCommitScene(impl_->scene);
  impl_->committed = true;
  if (!impl_->error.empty()) throw std::runtime_error(impl_->error);
}

Box3 Scene::bounds() const { return impl_->bounds; }

const std::vector<TextLabel>& Scene::labels() const { return impl_->labels; }

SceneStats Scene::stats() const { return impl_->stats; }

bool Scene::servesCamera(const Camera& camera, int width, int height) const {
  if (impl_->followsCamera) return false;
  if (impl_->followedCells.empty()) return true;
  if (width < 1 || height < 1 || !impl_->view || impl_->cellView) return false;
  const PixelScale pixels = camera.pixelScale(height);
  for (const Impl::FollowedCell& c : impl_->followedCells)
    if (pixelCellSize(c.ownCell, pixels, c.support) != c.usedCell) return false;
  return true;
}

std::optional<SurfaceHit> Scene::intersect(const Vec3& origin, const Vec3& direction, float tnear, float tfar) const {
  if (!traceable(origin, direction, tnear, tfar)) return std::nullopt;
  detail::HitContext context;
  rtcInitIntersectContext(&context.base);
  RTCRayHit rh{};
  rh.ray.org_x = origin.x;
  rh.ray.org_y = origin.y;
  rh.ray.org_z = origin.z;
  rh.ray.dir_x = direction.x;
  rh.ray.dir_y = direction.y;
  rh.ray.dir_z = direction.z;
  rh.ray.tnear = tnear;
  rh.ray.tfar = tfar;
  rh.ray.mask = 0xffffffffu;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &context.base, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;

  const GeometryRecord& rec = impl_->records[rh.hit.geomID];
  const uint32_t prim = rh.hit.primID;
  SurfaceHit hit;
  hit.t = rh.ray.tfar;
  hit.position = origin + hit.t * direction;
  hit.geometry = rh.hit.geomID;
  hit.material = rec.primitiveMaterials.empty() ? rec.material : rec.primitiveMaterials[prim];
  hit.color = impl_->materials[hit.material].baseColor;
  Vec3 ng(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
  if (rec.kind == GeometryRecord::Kind::Implicit) {
    const blobtree::Hit& ih = context.implicitHit;
    hit.position = ih.point;
    hit.normal = hit.geometricNormal = ih.normal;
    const Material& m = impl_->materials[hit.material];
    if (m.ridge.tilts())
      hit.normal = m.ridge.shadingNormal(ih.normal, ih.attributes.contact, ih.attributes.contactGradient, ih.point);
    hit.color = attributeColor(ih.attributes, ih.point, impl_->materials[hit.material], rec.textureBase,
                               rec.textureCount);
    return hit;
  }
  if (rec.kind == GeometryRecord::Kind::Curves && rec.curves && rec.curves->widened) {
    // A widened curve: shaded with the normal of the true surface, with the segment's coverage.
    const detail::CurveData& cd = *rec.curves;
    const uint32_t i = cd.segments[prim];
    const Vec3 a(cd.real[i]), b(cd.real[i + 1]);
    const Vec3 axis = b - a;
    const float len2 = glm::dot(axis, axis);
    const float u = len2 > 0 ? std::clamp(glm::dot(hit.position - a, axis) / len2, 0.0f, 1.0f) : 0.0f;
    const Vec3 c = a + u * axis;
    Vec3 n = hit.position - c;
    const float nl = glm::length(n);
    n = nl > 0 ? n / nl : -direction;
    hit.opacity = cd.opacity(prim, u);
    // The hit stays on the drawn tube, outside what it stands for (a twig's blended
    // surface may be fatter than its cone near a junction, and a shading point inside it
    // would be shadowed by it).
    hit.normal = hit.geometricNormal = n;
    // Continue behind the drawn tube: the exit of the ray from the cylinder of the
    // segment's largest drawn radius (what the tube stands for lies inside it).
    const float R = std::max(cd.drawn[i].w, cd.drawn[i + 1].w);
    const Vec3 e = len2 > 0 ? axis / std::sqrt(len2) : Vec3(0, 1, 0);
    const Vec3 w = origin - a;
    const Vec3 dp = direction - glm::dot(direction, e) * e, wp = w - glm::dot(w, e) * e;
    const float A = glm::dot(dp, dp), B = 2.0f * glm::dot(dp, wp), C = glm::dot(wp, wp) - R * R;
    const float disc = B * B - 4.0f * A * C;
    float exit = hit.t + std::sqrt(len2) + 2.0f * R;
    if (A > 1e-12f * glm::dot(direction, direction) && disc >= 0.0f) exit = (-B + std::sqrt(disc)) / (2.0f * A);
    hit.behind = std::max(exit, hit.t) + 0.05f * R + 1e-5f * hit.t;  // past Embree's exit hit
    return hit;
  }
  if (rec.kind == GeometryRecord::Kind::Triangles) {
    const glm::uvec3& tri = rec.triangles[prim];
    const Vec3 &p0 = rec.positions[tri.x], &p1 = rec.positions[tri.y], &p2 = rec.positions[tri.z];
    ng = glm::cross(p1 - p0, p2 - p0);
    float u = rh.hit.u, v = rh.hit.v, w = 1.0f - u - v;
    hit.position = w * p0 + u * p1 + v * p2;
    if (!rec.normals.empty()) {
      Vec3 n = w * rec.normals[tri.x] + u * rec.normals[tri.y] + v * rec.normals[tri.z];
      float len = glm::length(n);
      hit.normal = len > 0 ? n / len : Vec3(0);
      const std::array<Vec3, 3> corners{p0, p1, p2};
      std::array<Vec3, 3> normals{rec.normals[tri.x], rec.normals[tri.y], rec.normals[tri.z]};
      hit.terminatorLift[0] = terminatorLift(corners, normals, Vec3(w, u, v));
      for (Vec3& nv : normals) nv = -nv;
      hit.terminatorLift[1] = terminatorLift(corners, normals, Vec3(w, u, v));
    }
    if (!rec.vertexColors.empty())
      hit.color = w * rec.vertexColors[tri.x] + u * rec.vertexColors[tri.y] + v * rec.vertexColors[tri.z];
    if (!rec.vertexSurfaces.empty()) {
      hit.ownSurface = true;
      // As an offset from the first corner: three equal corners give exactly their value
      // (roughness 1 stays 1, so no highlight creeps back).
      const Vec3& a = rec.vertexSurfaces[tri.x];
      hit.surface = a + u * (rec.vertexSurfaces[tri.y] - a) + v * (rec.vertexSurfaces[tri.z] - a);
    }
    int tex = impl_->materials[hit.material].texture;
    if (!rec.uvs.empty() && tex >= 0 && static_cast<size_t>(tex) < impl_->textures.size())
      hit.color = impl_->textures[tex](w * rec.uvs[tri.x] + u * rec.uvs[tri.y] + v * rec.uvs[tri.z], hit.position);
    if (rec.image) {
      const Vec4 c = rec.image->sample(prim, rh.hit.u, rh.hit.v);
      hit.color = Vec3(c);
      // Partial coverage (the intersect filter left out alpha at or below the cutoff): the
      // renderer blends the hit over what it sees from just past the triangle.
      if (rec.image->map->alphaCutoff >= 0.0f && c.a < 1.0f) {
        hit.opacity = c.a;
        hit.behind = hit.t + 1e-4f * hit.t + 1e-6f;
      }
    }
  }
  if (!rec.primitiveColors.empty()) hit.color = rec.primitiveColors[prim];
  float len = glm::length(ng);
  hit.geometricNormal = len > 0 ? ng / len : -direction;
  if (rec.kind != GeometryRecord::Kind::Triangles || rec.normals.empty() || !(glm::length(hit.normal) > 0))
    hit.normal = hit.geometricNormal;
  return hit;
}

Vec3 terminatorLift(const std::array<Vec3, 3>& corners, const std::array<Vec3, 3>& normals, const Vec3& barycentric) {
  const Vec3 p = barycentric.x * corners[0] + barycentric.y * corners[1] + barycentric.z * corners[2];
  Vec3 lift(0.0f);
  for (int i = 0; i < 3; ++i) {
    const float len = glm::length(normals[i]);
    if (!(len > 0.0f)) continue;
    const Vec3 n = normals[i] / len;
    lift += barycentric[i] * std::max(0.0f, -glm::dot(p - corners[i], n)) * n;
  }
  return lift;
}

bool Scene::occluded(const Vec3& origin, const Vec3& direction, float tnear, float tfar) const {
  if (!traceable(origin, direction, tnear, tfar)) return false;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray{};
  ray.org_x = origin.x;
  ray.org_y = origin.y;
  ray.org_z = origin.z;
  ray.dir_x = direction.x;
  ray.dir_y = direction.y;
  ray.dir_z = direction.z;
  ray.tnear = tnear;
  ray.tfar = tfar;
  ray.mask = 0xffffffffu;
  rtcOccluded1(impl_->scene, &context, &ray);
  return ray.tfar < 0.0f;
}

}  // namespace sprig::render
