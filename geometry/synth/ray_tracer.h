#pragma once
// A thin RAII wrapper around an Embree device and scene: one triangle geometry per
// object (its geometry id maps back to the caller's object index), built once and then
// queried read-only, so intersect/occluded are safe to call from many threads.
#include <Eigen/Core>
#include <limits>
#include <memory>
#include <vector>

#include "geometry/synth/mesh.h"

namespace saresgs::synth {

struct TraceHit {
  bool hit = false;
  float t = 0;         // ray parameter: hit = origin + t * dir
  int object = -1;     // the caller's object index
  int triangle = -1;   // face index within that object's mesh
  float u = 0, v = 0;  // barycentrics: p = (1-u-v) v0 + u v1 + v v2
};

class RayTracer {
 public:
  // meshes[k] becomes object object_ids[k] (object_ids empty: k). The meshes are copied.
  // Throws std::runtime_error when Embree fails.
  explicit RayTracer(const std::vector<const TriangleMesh*>& meshes, std::vector<int> object_ids = {});
  ~RayTracer();
  RayTracer(const RayTracer&) = delete;
  RayTracer& operator=(const RayTracer&) = delete;

  // First hit of origin + t * dir for t in (tmin, tmax); tmin below 0 counts as 0.
  TraceHit intersect(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float tmin = 0,
                     float tmax = std::numeric_limits<float>::infinity()) const;
  // Any hit of origin + t * dir for t in (tmin, tmax).
  bool occluded(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float tmin, float tmax) const;
  bool empty() const { return geom_to_object_.empty(); }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<int> geom_to_object_;
};

}  // namespace saresgs::synth
