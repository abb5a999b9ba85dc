#pragma once
// Ground-truth synthetic scenes: real or procedural meshes with textures, ray traced
// with Embree, with camera layouts that imitate the public benchmarks:
//   object     NeRF-synthetic-like: one object, upper hemisphere, 100 train + 50 test,
//              white background (pixels that miss are background, depth 0);
//   room360    Mip-NeRF-360-like: a textured room with several objects, an inward orbit at
//              varying radius and height, ~150 images, every 8th a test view;
//   unbalanced Deep-Blending-like: an irregular walk with dense clusters and sparse
//              stretches, several objects and occluders, ~150 images, every 8th a test view;
//   tworooms   two rooms joined by a doorway, real meshes (CGAL's animals and figures when
//              no mesh file is given), one walk through both rooms that also looks back
//              through the door, ~150 images, every 8th a test view;
//   corridor   three rooms in a row joined by doorways on opposite sides, procedural
//              objects, one walk of uneven density (a slow arc, a quick pass, a dense
//              cluster, a sparse arc), ~150 images, every 8th a test view.
// With no mesh or texture files given, the first three layouts use procedural objects and
// procedural textures (the built-in scene needs no files).
// Splits: object: train = the first 100 views, test = the last 50 (drawn independently,
// so test positions differ from train; with num_views = n: the first round(2n/3) train);
// room360, unbalanced, tworooms and corridor: index % 8 == 0 is a test view, the rest train.
// Files: mesh files replace the content objects (object layout: the first file only;
// rooms: cycled over the objects), normalised to unit radius with opts.up_axis turned to
// +z; photographs replace the content objects' textures (cycled). The room's faces,
// pillars and partition always keep their procedural textures. Implementation:
// procedural_meshes, texture, ray_tracer, layouts, synthetic_scene (.h/.cpp here).
#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "geometry/camera/camera.h"
#include "geometry/image/image.h"

namespace saresgs {

struct SyntheticOptions {
  std::string layout = "room360";  // object | room360 | unbalanced | tworooms | corridor
  int width = 256, height = 192;
  std::uint64_t seed = 0;
  int num_views = 0;                     // 0: the layout's default count (train + test)
  std::vector<std::string> meshes;       // OFF/PLY/OBJ files (CGAL IO); empty: procedural
  std::vector<std::string> textures;     // photographs (PNG/JPEG); empty: procedural
  std::string up_axis = "y";             // up axis of the given mesh files: x | y | z
  std::string projection = "triplanar";  // how photographs map: triplanar | spherical
};

struct RenderOptions {
  int samples_per_pixel = 4;  // supersampling; >= 4 (stratified, deterministic jitter)
  bool specular = false;      // adds a mild view-dependent highlight
};

// One ray's first hit.
struct SurfaceHit {
  bool hit = false;
  float distance = 0;  // along the unit ray direction
  Eigen::Vector3f point = Eigen::Vector3f::Zero();
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();  // unit, facing the ray origin
  int object = -1;                                   // index into SyntheticScene::objectNames()
};

struct SurfaceSample {
  Eigen::Vector3f point;
  Eigen::Vector3f normal;
  int object;
};

class SyntheticWorld;  // meshes, materials and the Embree scene (synthetic_scene.cpp)

// A built synthetic scene. Copies share the (immutable) world; all queries are
// thread-safe and deterministic.
class SyntheticScene {
 public:
  std::vector<Camera> cameras;          // all views, in order; names[i] belongs to cameras[i]
  std::vector<std::string> names;       // image file names, e.g. "0000.png"
  std::vector<int> train, test;         // indices into cameras
  Eigen::Vector3f background{1, 1, 1};  // colour of rays that miss (object layout)
  // Rooms: every ray meets a wall, so the data has no background (manifest null) and
  // their images are opaque; the object layout's misses are background.
  bool enclosed = false;
  nlohmann::json manifest;  // layout, seed, meshes, textures, sizes, light

  // First hit along origin + s * dir (dir need not be unit), s in (tmin, tmax).
  SurfaceHit intersect(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float tmin = 0.0f,
                       float tmax = std::numeric_limits<float>::infinity()) const;
  // True when something blocks the segment origin + s * dir, s in (tmin, tmax).
  bool occluded(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float tmin, float tmax) const;
  // Shaded colour (linear RGB in [0,1]) of a surface point seen from `eye`.
  Eigen::Vector3f shade(const SurfaceHit& hit, const Eigen::Vector3f& eye, bool specular = false) const;
  // Colour image (3 channels, [0,1]), supersampled. TBB-parallel over rows.
  ImageF render(const Camera& cam, const RenderOptions& opts = {}) const;
  // RGBA: colour of the surfaces alone (straight alpha) and the fraction of samples that
  // hit one, as NeRF-synthetic's images hold; composited on `background` it is render().
  ImageF renderRgba(const Camera& cam, const RenderOptions& opts = {}) const;
  // Depth along the camera z axis through each pixel centre; 0 where the ray misses.
  ImageF renderDepth(const Camera& cam) const;
  // `count` points uniformly distributed by area over all surfaces.
  std::vector<SurfaceSample> sampleSurface(std::size_t count, std::mt19937_64& rng) const;
  std::vector<std::string> objectNames() const;

 private:
  friend SyntheticScene makeSyntheticScene(const SyntheticOptions&);
  std::shared_ptr<const SyntheticWorld> world_;
};

// Builds a scene; throws InputError for an unknown layout, unreadable mesh or texture.
SyntheticScene makeSyntheticScene(const SyntheticOptions& opts);

// `layout` rendered at width x height with `seed` and `num_views` views (0: the layout's
// default count); everything else as SyntheticOptions has it (procedural meshes, textures).
SyntheticOptions syntheticOptions(const std::string& layout, int width, int height, std::uint64_t seed = 0,
                                  int num_views = 0);

}  // namespace saresgs
