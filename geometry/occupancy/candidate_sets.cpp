#include "geometry/occupancy/candidate_sets.h"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "geometry/error.h"
#include "geometry/float_env.h"

namespace saresgs {

namespace {

void checkCamera(const Camera& cam) { validateCamera(cam, "candidate camera", "K/R/t"); }

// Start index of each 8^3 block in the (block-major) key array, plus a final end index.
std::vector<std::size_t> blockStarts(const std::vector<VoxelKey>& keys) {
  std::vector<std::size_t> starts;
  for (std::size_t i = 0; i < keys.size(); ++i)
    if (i == 0 || blockOfKey(keys[i]) != blockOfKey(keys[i - 1])) starts.push_back(i);
  starts.push_back(keys.size());
  return starts;
}

}  // namespace

DepthRange sceneDepthRange(const OccupancyGrids& grids, const Camera& cam) {
  checkCamera(cam);
  DepthRange r;
  const AABB b = grids.sceneVoxelBounds();
  if (b.empty()) return r;  // near = far = 0: empty
  double zmin = std::numeric_limits<double>::infinity(), zmax = -zmin;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d corner((c & 1) ? b.max.x() : b.min.x(), (c & 2) ? b.max.y() : b.min.y(),
                                 (c & 4) ? b.max.z() : b.min.z());
    const double z = cam.toCamera(corner).z();
    zmin = std::min(zmin, z);
    zmax = std::max(zmax, z);
  }
  // Clamp near to a positive depth: points on or behind the camera plane do not project.
  const double min_near = 1e-6 * b.size().norm();
  if (!(zmax > min_near)) return r;  // the box is behind the camera
  r.near = std::max(zmin, min_near);
  r.far = zmax;
  return r;
}

VoxelSet frustumSet(const OccupancyGrids& grids, const Camera& cam) {
  return frustumSet(grids, cam, sceneDepthRange(grids, cam));
}

VoxelSet frustumSet(const OccupancyGrids& grids, const Camera& cam, const DepthRange& range) {
  checkCamera(cam);
  if (!std::isfinite(range.near) || !std::isfinite(range.far))
    throw InputError("candidate camera", "near/far", "expected finite depths");
  const auto& keys = grids.sceneVoxels().keys();
  if (range.empty() || keys.empty()) return {};
  const auto planes = cam.frustumPlanes(range.near, range.far);
  const double h = grids.voxelSize();
  const Eigen::Vector3d& origin = grids.origin();
  // A block is skipped only when the box of its possible voxel centres lies farther than
  // this outside one plane; the margin dwarfs the rounding of the plane test, so a
  // skipped block never holds a centre that inFrustum accepts (exactness vs brute force).
  const double margin = 1e-6 * h;
  const std::vector<std::size_t> starts = blockStarts(keys);
  const std::size_t nblocks = starts.size() - 1;
  std::vector<std::uint8_t> inside(keys.size(), 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nblocks, 16), [&](const tbb::blocked_range<std::size_t>& br) {
    const FloatEnvGuard fenv;  // geometry/float_env.h
    for (std::size_t b = br.begin(); b != br.end(); ++b) {
      const Voxel base = unpackVoxel(keys[starts[b]] & ~VoxelKey{511});  // block corner
      const Eigen::Vector3d lo = origin + h * Eigen::Vector3d(base[0] + 0.5, base[1] + 0.5, base[2] + 0.5);
      const Eigen::Vector3d hi = lo + Eigen::Vector3d::Constant(7.0 * h);
      bool culled = false;
      for (const Plane& p : planes) {
        // The corner of the centre box farthest along the plane normal.
        const Eigen::Vector3d best((p.n.x() > 0 ? hi : lo).x(), (p.n.y() > 0 ? hi : lo).y(),
                                   (p.n.z() > 0 ? hi : lo).z());
        if (p.signedDistance(best) < -margin) {
          culled = true;
          break;
        }
      }
      if (culled) continue;
      for (std::size_t i = starts[b]; i < starts[b + 1]; ++i)
        inside[i] = cam.inFrustum(grids.voxelCenter(unpackVoxel(keys[i])), range.near, range.far);
    }
  });
  // Serial compaction in key order: sorted output, independent of the thread schedule.
  std::vector<VoxelKey> out;
  for (std::size_t i = 0; i < keys.size(); ++i)
    if (inside[i]) out.push_back(keys[i]);
  return VoxelSet::fromSortedKeys(std::move(out));
}

std::vector<Eigen::Vector2d> samplePixels(const Intrinsics& K, int stride) {
  if (stride < 1) throw InputError("candidate camera", "pixel_stride", "expected >= 1, got " + std::to_string(stride));
  std::vector<Eigen::Vector2d> uv;
  if (K.width <= 0 || K.height <= 0) return uv;
  auto centres = [stride](int n) {
    std::vector<double> c;
    for (int i = 0; i * stride < n; ++i) c.push_back(0.5 * (i * stride + std::min((i + 1) * stride, n)));
    return c;
  };
  const auto us = centres(K.width), vs = centres(K.height);
  uv.reserve(us.size() * vs.size());
  for (double v : vs)
    for (double u : us) uv.emplace_back(u, v);
  return uv;
}

// ---------------------------------------------------------------- Embree tracer

// The tracer's user geometry: a member of VisibilityTracer::Impl, so a type with linkage
// (in a unity batch an unnamed namespace's type in a member is GCC's -Wsubobject-linkage).
struct VisibilityBoxes {
  std::vector<std::array<float, 3>> lower;  // voxel corner in local voxel units
};

namespace {

void boxBounds(const RTCBoundsFunctionArguments* args) {
  const auto* boxes = static_cast<const VisibilityBoxes*>(args->geometryUserPtr);
  const auto& l = boxes->lower[args->primID];
  RTCBounds* b = args->bounds_o;
  b->lower_x = l[0];
  b->lower_y = l[1];
  b->lower_z = l[2];
  b->upper_x = l[0] + 1.0f;
  b->upper_y = l[1] + 1.0f;
  b->upper_z = l[2] + 1.0f;
}

// Slab test in double (the float ray is widened, the box corners are exact). Returns
// the entry parameter clamped to tnear (a ray starting inside a box hits it at tnear),
// or NaN on a miss.
double slabEntry(const double o[3], const double d[3], const std::array<float, 3>& lower, double tnear, double tfar) {
  double t0 = tnear, t1 = tfar;
  for (int a = 0; a < 3; ++a) {
    const double lo = lower[a], hi = lower[a] + 1.0;
    if (d[a] == 0.0) {
      // Parallel to the slab: inside it or never (avoids 0 * inf = NaN).
      if (o[a] < lo || o[a] > hi) return std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    const double inv = 1.0 / d[a];
    double ta = (lo - o[a]) * inv, tb = (hi - o[a]) * inv;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return std::numeric_limits<double>::quiet_NaN();
  }
  return t0;
}

void boxIntersect(const RTCIntersectFunctionNArguments* args) {
  const auto* boxes = static_cast<const VisibilityBoxes*>(args->geometryUserPtr);
  const unsigned N = args->N;
  const unsigned prim = args->primID;
  RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, N);
  RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, N);
  for (unsigned i = 0; i < N; ++i) {
    if (args->valid[i] != -1) continue;
    const double o[3] = {RTCRayN_org_x(ray, N, i), RTCRayN_org_y(ray, N, i), RTCRayN_org_z(ray, N, i)};
    const double d[3] = {RTCRayN_dir_x(ray, N, i), RTCRayN_dir_y(ray, N, i), RTCRayN_dir_z(ray, N, i)};
    float& tfar = RTCRayN_tfar(ray, N, i);
    const double t = slabEntry(o, d, boxes->lower[prim], RTCRayN_tnear(ray, N, i), tfar);
    if (std::isnan(t)) continue;
    const auto tf = static_cast<float>(t);
    // Strictly closer wins; an exact tie (edges, corners) goes to the smaller index, so
    // the answer does not depend on the BVH traversal order.
    const unsigned cur_geom = RTCHitN_geomID(hit, N, i);
    const bool closer = tf < tfar;
    const bool tie = tf == tfar && cur_geom == args->geomID && prim < RTCHitN_primID(hit, N, i);
    if (!(closer || tie)) continue;
    tfar = tf;
    RTCHitN_geomID(hit, N, i) = args->geomID;
    RTCHitN_primID(hit, N, i) = prim;
    RTCHitN_instID(hit, N, i, 0) = args->context->instID[0];
    RTCHitN_u(hit, N, i) = 0.0f;
    RTCHitN_v(hit, N, i) = 0.0f;
    RTCHitN_Ng_x(hit, N, i) = 0.0f;
    RTCHitN_Ng_y(hit, N, i) = 0.0f;
    RTCHitN_Ng_z(hit, N, i) = 1.0f;
  }
}

}  // namespace

struct VisibilityTracer::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  VisibilityBoxes boxes;
  std::vector<VoxelKey> keys;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  double h = 1.0;
  Voxel base{0, 0, 0};  // voxel at local (0,0,0)
  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
  // World point -> local voxel units.
  Eigen::Vector3d local(const Eigen::Vector3d& p) const {
    return (p - origin) / h - Eigen::Vector3d(base[0], base[1], base[2]);
  }
};

VisibilityTracer::VisibilityTracer(const OccupancyGrids& grids) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.keys = grids.sceneVoxels().keys();
  m.origin = grids.origin();
  m.h = grids.voxelSize();
  if (m.keys.empty()) return;  // no scene: every ray misses
  const std::vector<Voxel> vox = grids.sceneVoxels().voxels();
  m.base = vox.front();
  for (const Voxel& v : vox)
    for (int a = 0; a < 3; ++a) m.base[a] = std::min(m.base[a], v[a]);
  m.boxes.lower.reserve(vox.size());
  // Fine coordinates span at most 2^18 voxels per axis (OccupancyOptions check), so the
  // local corners are integers below 2^24: exact in float.
  for (const Voxel& v : vox)
    m.boxes.lower.push_back({static_cast<float>(v[0] - m.base[0]), static_cast<float>(v[1] - m.base[1]),
                             static_cast<float>(v[2] - m.base[2])});

  m.device = rtcNewDevice(nullptr);
  if (!m.device) throw std::runtime_error("Embree: rtcNewDevice failed");
  m.scene = rtcNewScene(m.device);
  // No accuracy-reducing traversal shortcuts: a ray grazing a box edge must still reach
  // the box callback (the DDA oracle test counts such rays).
  rtcSetSceneFlags(m.scene, RTC_SCENE_FLAG_ROBUST);
  RTCGeometry g = rtcNewGeometry(m.device, RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(g, static_cast<unsigned>(vox.size()));
  rtcSetGeometryUserData(g, &m.boxes);
  rtcSetGeometryBoundsFunction(g, boxBounds, nullptr);
  rtcSetGeometryIntersectFunction(g, boxIntersect);
  rtcCommitGeometry(g);
  rtcAttachGeometry(m.scene, g);
  rtcReleaseGeometry(g);
  rtcCommitScene(m.scene);
  const RTCError err = rtcGetDeviceError(m.device);
  if (err != RTC_ERROR_NONE)
    throw std::runtime_error("Embree: voxel scene build failed with error " + std::to_string(static_cast<int>(err)));
}

VisibilityTracer::~VisibilityTracer() = default;

std::size_t VisibilityTracer::voxelCount() const { return impl_->keys.size(); }

std::int64_t VisibilityTracer::firstHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir) const {
  const Impl& m = *impl_;
  if (!m.scene || !origin.allFinite() || !dir.allFinite() || dir.isZero()) return -1;
  const Eigen::Vector3f o = m.local(origin).cast<float>();
  const Eigen::Vector3f d = dir.normalized().cast<float>();
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh;
  rh.ray.org_x = o.x();
  rh.ray.org_y = o.y();
  rh.ray.org_z = o.z();
  rh.ray.dir_x = d.x();
  rh.ray.dir_y = d.y();
  rh.ray.dir_z = d.z();
  rh.ray.tnear = 0.0f;
  rh.ray.tfar = std::numeric_limits<float>::infinity();
  rh.ray.time = 0.0f;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(m.scene, &ctx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return -1;
  return static_cast<std::int64_t>(rh.hit.primID);
}

std::vector<std::int64_t> VisibilityTracer::tracePixels(const Camera& cam, int stride) const {
  checkCamera(cam);
  const std::vector<Eigen::Vector2d> uv = samplePixels(cam.K, stride);
  std::vector<std::int64_t> hits(uv.size(), -1);
  if (!impl_->scene) return hits;
  const Eigen::Vector3d c = cam.center();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, uv.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
    const FloatEnvGuard fenv;  // geometry/float_env.h
    for (std::size_t i = r.begin(); i != r.end(); ++i) hits[i] = firstHit(c, cam.rayDirection(uv[i]));
  });
  return hits;
}

VoxelSet VisibilityTracer::visibleSet(const Camera& cam, int stride) const {
  const std::vector<std::int64_t> hits = tracePixels(cam, stride);
  // Mark, then compact in key order: sorted without a sort, independent of threads.
  std::vector<std::uint8_t> seen(impl_->keys.size(), 0);
  for (std::int64_t h : hits)
    if (h >= 0) seen[static_cast<std::size_t>(h)] = 1;
  std::vector<VoxelKey> out;
  for (std::size_t i = 0; i < seen.size(); ++i)
    if (seen[i]) out.push_back(impl_->keys[i]);
  return VoxelSet::fromSortedKeys(std::move(out));
}

}  // namespace saresgs
