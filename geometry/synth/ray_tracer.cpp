#include "geometry/synth/ray_tracer.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

namespace saresgs::synth {

struct RayTracer::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

void throwOnError(RTCDevice device, const char* what) {
  const RTCError err = rtcGetDeviceError(device);
  if (err != RTC_ERROR_NONE)
    throw std::runtime_error(std::string("Embree: ") + what + " failed with error " +
                             std::to_string(static_cast<int>(err)));
}

void setRay(RTCRay& ray, const Eigen::Vector3f& o, const Eigen::Vector3f& d, float tmin, float tmax) {
  ray.org_x = o.x();
  ray.org_y = o.y();
  ray.org_z = o.z();
  ray.dir_x = d.x();
  ray.dir_y = d.y();
  ray.dir_z = d.z();
  ray.tnear = std::max(tmin, 0.0f);
  ray.tfar = tmax;
  ray.time = 0;
  ray.mask = 0xFFFFFFFFu;
  ray.id = 0;
  ray.flags = 0;
}

}  // namespace

RayTracer::RayTracer(const std::vector<const TriangleMesh*>& meshes, std::vector<int> object_ids)
    : impl_(std::make_unique<Impl>()) {
  if (object_ids.empty())
    for (std::size_t k = 0; k < meshes.size(); ++k) object_ids.push_back(static_cast<int>(k));
  if (object_ids.size() != meshes.size()) throw std::invalid_argument("RayTracer: one object id per mesh expected");
  impl_->device = rtcNewDevice(nullptr);
  if (!impl_->device) throw std::runtime_error("Embree: rtcNewDevice failed");
  impl_->scene = rtcNewScene(impl_->device);
  // Robust mode makes the traversal watertight: no rays slip between adjacent triangles.
  rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  for (std::size_t k = 0; k < meshes.size(); ++k) {
    const TriangleMesh& m = *meshes[k];
    if (m.faces.empty()) continue;
    RTCGeometry g = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), m.vertices.size()));
    auto* f = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), m.faces.size()));
    if (!v || !f) {
      rtcReleaseGeometry(g);
      throwOnError(impl_->device, "buffer allocation");
      throw std::runtime_error("Embree: buffer allocation failed");
    }
    for (std::size_t i = 0; i < m.vertices.size(); ++i) std::memcpy(v + 3 * i, m.vertices[i].data(), 3 * sizeof(float));
    for (std::size_t i = 0; i < m.faces.size(); ++i)
      for (int c = 0; c < 3; ++c) f[3 * i + c] = static_cast<unsigned>(m.faces[i][c]);
    rtcCommitGeometry(g);
    const unsigned id = rtcAttachGeometry(impl_->scene, g);
    rtcReleaseGeometry(g);  // the scene holds its own reference
    if (geom_to_object_.size() <= id) geom_to_object_.resize(id + 1, -1);
    geom_to_object_[id] = object_ids[k];
  }
  rtcCommitScene(impl_->scene);
  throwOnError(impl_->device, "scene build");
}

RayTracer::~RayTracer() = default;

TraceHit RayTracer::intersect(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float tmin, float tmax) const {
  TraceHit out;
  if (geom_to_object_.empty() || !(tmax > std::max(tmin, 0.0f))) return out;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh;
  setRay(rh.ray, origin, dir, tmin, tmax);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &ctx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return out;
  out.hit = true;
  out.t = rh.ray.tfar;
  out.object = geom_to_object_[rh.hit.geomID];
  out.triangle = static_cast<int>(rh.hit.primID);
  out.u = rh.hit.u;
  out.v = rh.hit.v;
  return out;
}

bool RayTracer::occluded(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float tmin, float tmax) const {
  if (geom_to_object_.empty() || !(tmax > std::max(tmin, 0.0f))) return false;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRay ray;
  setRay(ray, origin, dir, tmin, tmax);
  rtcOccluded1(impl_->scene, &ctx, &ray);
  // Embree marks an occluded ray by setting tfar to -inf.
  return ray.tfar < 0;
}

}  // namespace saresgs::synth
