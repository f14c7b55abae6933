#include "render/scene.h"

#include "render/detail/scene_impl.h"

#include <algorithm>
#include <cmath>
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

Vec3 toVec3(const DVec3& v) { return Vec3(static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)); }

}  // namespace

uint32_t Scene::Impl::attach(RTCGeometry geometry, GeometryRecord record) {
  rtcCommitGeometry(geometry);
  uint32_t id = static_cast<uint32_t>(records.size());
  rtcAttachGeometryByID(scene, geometry, id);
  rtcReleaseGeometry(geometry);
  records.push_back(std::move(record));
  if (!error.empty()) throw std::runtime_error(error);
  return id;
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

std::vector<uint32_t> Scene::addSkeleton(const lsystem::Skeleton& skeleton, const SkeletonStyle& style) {
  if (impl_->committed) throw std::logic_error("Scene::addSkeleton after commit");
  std::vector<uint32_t> ids;
  const auto& nodes = skeleton.internodes;
  DBox3 box = skeleton.bounds();
  double minRadius = box.empty() ? 0.0 : style.minRadiusFraction * glm::length(box.size());
  auto radius = [&](double r) { return static_cast<float>(std::max(r * style.radiusScale, minRadius)); };

  if (!nodes.empty()) {
    // Chain each internode with the first child that starts where it ends, so joints are
    // shared vertices of one curve rather than two overlapping caps.
    std::vector<int32_t> next(nodes.size(), -1);
    std::vector<char> continues(nodes.size(), 0);
    // First pass: continuations of the same branch order; second pass: any child.
    for (int pass = 0; pass < 2; ++pass) {
      for (size_t i = 0; i < nodes.size(); ++i) {
        int32_t p = nodes[i].parent;
        if (p < 0 || static_cast<size_t>(p) >= nodes.size() || next[p] >= 0 || continues[i]) continue;
        if (pass == 0 && nodes[i].order != nodes[p].order) continue;
        double tol = 1e-6 * std::max(1.0, nodes[p].length());
        if (glm::length(nodes[i].start - nodes[p].end) <= tol) {
          next[p] = static_cast<int32_t>(i);
          continues[i] = 1;
        }
      }
    }
    std::vector<glm::vec4> vertices;
    std::vector<uint32_t> segments;
    std::vector<uint8_t> flags;
    for (size_t i = 0; i < nodes.size(); ++i) {
      if (continues[i]) continue;
      const auto& first = nodes[i];
      vertices.emplace_back(toVec3(first.start), radius(first.baseRadius));
      bool firstInChain = true;
      for (int32_t k = static_cast<int32_t>(i); k >= 0; k = next[k]) {
        const auto& n = nodes[k];
        double tip = next[k] >= 0 ? 0.5 * (n.tipRadius + nodes[next[k]].baseRadius) : n.tipRadius;
        segments.push_back(static_cast<uint32_t>(vertices.size() - 1));
        vertices.emplace_back(toVec3(n.end), radius(tip));
        uint8_t f = 0;
        if (!firstInChain) f |= RTC_CURVE_FLAG_NEIGHBOR_LEFT;
        if (next[k] >= 0) f |= RTC_CURVE_FLAG_NEIGHBOR_RIGHT;
        flags.push_back(f);
        firstInChain = false;
      }
    }
    RTCGeometry g = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                                          4 * sizeof(float), vertices.size()));
    for (size_t i = 0; i < vertices.size(); ++i) {
      for (int c = 0; c < 4; ++c) v[4 * i + c] = vertices[i][c];
      impl_->bounds.extend(Box3{Vec3(vertices[i]) - vertices[i].w, Vec3(vertices[i]) + vertices[i].w});
    }
    auto* s = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT,
                                                             sizeof(uint32_t), segments.size()));
    std::copy(segments.begin(), segments.end(), s);
    auto* fl = static_cast<uint8_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_FLAGS, 0, RTC_FORMAT_UCHAR,
                                                             sizeof(uint8_t), flags.size()));
    std::copy(flags.begin(), flags.end(), fl);
    impl_->stats.curveSegments += segments.size();
    GeometryRecord rec;
    rec.kind = GeometryRecord::Kind::Curves;
    rec.material = addMaterial(style.wood);
    ids.push_back(impl_->attach(g, std::move(rec)));
  }
  if (!style.organs) return ids;

  auto organColor = [&](const lsystem::Organ& o, const Material& fallback) {
    return o.color > 0 && static_cast<size_t>(o.color) < style.palette.size() ? style.palette[o.color] : fallback.baseColor;
  };
  // Polygons and named surfaces: one triangle geometry with per-triangle colors.
  GeometryRecord leaves;
  leaves.material = addMaterial(style.leaf);
  auto addPolygon = [&](const std::vector<Vec3>& pts, const Vec3& color) {
    if (pts.size() < 3) return;
    Vec3 normal(0);
    for (size_t k = 0; k < pts.size(); ++k) normal += glm::cross(pts[k], pts[(k + 1) % pts.size()]);  // Newell
    float len = glm::length(normal);
    if (!(len > 0)) return;
    normal /= len;
    uint32_t base = static_cast<uint32_t>(leaves.positions.size());
    for (const Vec3& p : pts) {
      leaves.positions.push_back(p);
      leaves.normals.push_back(normal);
    }
    for (uint32_t k = 1; k + 1 < pts.size(); ++k) {
      leaves.triangles.emplace_back(base, base + k, base + k + 1);
      leaves.primitiveColors.push_back(color);
    }
  };
  double surfaceScale = box.empty() ? 1.0 : 0.02 * glm::length(box.size());
  for (const auto& o : skeleton.organs) {
    if (o.kind == lsystem::Organ::Kind::Polygon) {
      std::vector<Vec3> pts;
      for (const auto& p : o.points) pts.push_back(toVec3(p));
      addPolygon(pts, organColor(o, style.leaf));
    } else if (o.kind == lsystem::Organ::Kind::Surface) {
      // A named surface is drawn as a diamond leaf in the turtle's heading-left plane.
      double s = o.radius > 0 ? o.radius : surfaceScale;
      DVec3 h = o.heading * s, l = o.left * (0.35 * s);
      addPolygon({toVec3(o.position), toVec3(o.position + 0.5 * h + l), toVec3(o.position + h),
                  toVec3(o.position + 0.5 * h - l)},
                 organColor(o, style.leaf));
    }
  }
  if (!leaves.triangles.empty()) ids.push_back(impl_->addTriangles(std::move(leaves)));

  // Spheres: Embree sphere points with per-primitive colors.
  std::vector<glm::vec4> spheres;
  GeometryRecord balls;
  balls.kind = GeometryRecord::Kind::Spheres;
  for (const auto& o : skeleton.organs) {
    if (o.kind != lsystem::Organ::Kind::Sphere || !(o.radius > 0)) continue;
    spheres.emplace_back(toVec3(o.position), static_cast<float>(o.radius * style.radiusScale));
    balls.primitiveColors.push_back(organColor(o, style.fruit));
  }
  if (!spheres.empty()) {
    balls.material = addMaterial(style.fruit);
    RTCGeometry g = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                                          4 * sizeof(float), spheres.size()));
    for (size_t i = 0; i < spheres.size(); ++i) {
      for (int c = 0; c < 4; ++c) v[4 * i + c] = spheres[i][c];
      impl_->bounds.extend(Box3{Vec3(spheres[i]) - spheres[i].w, Vec3(spheres[i]) + spheres[i].w});
    }
    impl_->stats.spheres += spheres.size();
    ids.push_back(impl_->attach(g, std::move(balls)));
  }
  return ids;
}

uint32_t Scene::addMesh(const Mesh& mesh, uint32_t material) {
  if (impl_->committed) throw std::logic_error("Scene::addMesh after commit");
  if (material >= impl_->materials.size()) throw std::invalid_argument("Scene::addMesh: unknown material id");
  GeometryRecord rec;
  rec.material = material;
  rec.positions = mesh.positions;
  rec.triangles = mesh.triangles;
  if (mesh.normals.size() == mesh.positions.size()) rec.normals = mesh.normals;
  if (mesh.colors.size() == mesh.positions.size()) rec.vertexColors = mesh.colors;
  if (mesh.uvs.size() == mesh.positions.size() && impl_->materials[material].texture >= 0) rec.uvs = mesh.uvs;
  if (mesh.materials.size() == mesh.triangles.size()) {
    for (uint32_t m : mesh.materials)
      if (m >= impl_->materials.size()) throw std::invalid_argument("Scene::addMesh: unknown per-triangle material id");
    rec.primitiveMaterials = mesh.materials;
  }
  for (const auto& t : mesh.triangles)
    if (t.x >= mesh.positions.size() || t.y >= mesh.positions.size() || t.z >= mesh.positions.size())
      throw std::invalid_argument("Scene::addMesh: triangle index out of range");
  return impl_->addTriangles(std::move(rec));
}

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

Vec3 Scene::attributeColor(const blobtree::Attributes& a, const Vec3& p, const Material& material) const {
  if (a.textureCount == 0 || impl_->textures.empty()) return material.baseColor;
  Vec3 sum(0);
  float wsum = 0;
  for (int i = 0; i < a.textureCount && i < blobtree::Attributes::kMaxTextures; ++i) {
    float w = a.textureWeights[i];
    if (!(w > 0)) continue;
    uint16_t id = a.textureIds[i];
    sum += w * (id < impl_->textures.size() ? impl_->textures[id](a.uv, p) : material.baseColor);
    wsum += w;
  }
  return wsum > 0 ? sum / wsum : material.baseColor;
}

void Scene::commit() {
  rtcCommitScene(impl_->scene);
  impl_->committed = true;
  if (!impl_->error.empty()) throw std::runtime_error(impl_->error);
}

Box3 Scene::bounds() const { return impl_->bounds; }

SceneStats Scene::stats() const { return impl_->stats; }

std::optional<SurfaceHit> Scene::intersect(const Vec3& origin, const Vec3& direction, float tnear, float tfar) const {
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
    hit.color = attributeColor(ih.attributes, ih.point, impl_->materials[hit.material]);
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
    }
    if (!rec.vertexColors.empty())
      hit.color = w * rec.vertexColors[tri.x] + u * rec.vertexColors[tri.y] + v * rec.vertexColors[tri.z];
    int tex = impl_->materials[hit.material].texture;
    if (!rec.uvs.empty() && tex >= 0 && static_cast<size_t>(tex) < impl_->textures.size())
      hit.color = impl_->textures[tex](w * rec.uvs[tri.x] + u * rec.uvs[tri.y] + v * rec.uvs[tri.z], hit.position);
  }
  if (!rec.primitiveColors.empty()) hit.color = rec.primitiveColors[prim];
  float len = glm::length(ng);
  hit.geometricNormal = len > 0 ? ng / len : -direction;
  if (rec.kind != GeometryRecord::Kind::Triangles || rec.normals.empty() || !(glm::length(hit.normal) > 0))
    hit.normal = hit.geometricNormal;
  return hit;
}

bool Scene::occluded(const Vec3& origin, const Vec3& direction, float tnear, float tfar) const {
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
