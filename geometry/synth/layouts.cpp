#include "geometry/synth/layouts.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "geometry/synth/noise.h"
#include "geometry/synth/procedural_meshes.h"

namespace saresgs::synth {

namespace {

using Eigen::Vector2f;
using Eigen::Vector3d;
using Eigen::Vector3f;
constexpr double kPi = std::numbers::pi;

// Uniform doubles from the raw 64-bit engine output: the same on every standard library.
struct Rng {
  std::mt19937_64 g;
  explicit Rng(std::uint64_t seed) : g(mix64(seed)) {}
  double uniform() { return static_cast<double>(g() >> 11) * 0x1.0p-53; }
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  // Uniform in the unit disc (rejection sampling).
  Eigen::Vector2d disc() {
    for (;;) {
      const Eigen::Vector2d p(uniform(-1, 1), uniform(-1, 1));
      if (p.squaredNorm() <= 1) return p;
    }
  }
};

// A procedural content object before placement: its mesh in a design frame (any size;
// it is normalised to unit radius) and its texture in that normalised frame.
struct ContentSpec {
  std::string name;
  std::string kind;  // "torus", "box", ...
  TriangleMesh mesh;
  std::shared_ptr<const Texture> texture;
};

// The mesh and texture for content slot `slot`: the user's files when given (cycled),
// else the procedural ones. The mesh comes back normalised to unit radius.
void resolveContent(const Assets& assets, int slot, ContentSpec& spec, std::string& mesh_source) {
  if (!assets.meshes.empty()) {
    const std::size_t k = static_cast<std::size_t>(slot) % assets.meshes.size();
    spec.mesh = assets.meshes[k];
    mesh_source = assets.mesh_paths[k];
  } else {
    normaliseMesh(spec.mesh, 1.0f);
    mesh_source = "procedural:" + spec.kind;
  }
  if (!assets.photos.empty()) {
    const std::size_t k = static_cast<std::size_t>(slot) % assets.photos.size();
    spec.texture = makeImageTexture(assets.photos[k], assets.projection, 1.0f, assets.photo_paths[k]);
  }
}

// Places a content object on the floor: scaled to radius `size`, turned by `yaw` about
// z, its lowest point on z = floor_z, its bounding-sphere centre above (x, y).
SceneObject placeOnFloor(const Assets& assets, int slot, ContentSpec spec, const Vector2f& xy, float floor_z,
                         float size, float yaw) {
  std::string source;
  resolveContent(assets, slot, spec, source);
  const float min_z = boundingBox(spec.mesh).min().z();
  Eigen::Affine3f T = Eigen::Affine3f::Identity();
  T.translate(Vector3f(xy.x(), xy.y(), floor_z - size * min_z));
  T.rotate(Eigen::AngleAxisf(yaw, Vector3f::UnitZ()));
  T.scale(size);
  SceneObject o;
  o.name = spec.name;
  o.mesh_source = source;
  o.mesh = transformed(spec.mesh, T);
  o.to_world = T;
  o.texture = spec.texture;
  return o;
}

// An object given directly in world coordinates (room faces, pillars): local = world.
SceneObject fixedObject(std::string name, std::string kind, TriangleMesh mesh, std::shared_ptr<const Texture> texture,
                        bool casts_shadow) {
  SceneObject o;
  o.name = std::move(name);
  o.mesh_source = "procedural:" + kind;
  o.mesh = std::move(mesh);
  o.texture = std::move(texture);
  o.casts_shadow = casts_shadow;
  return o;
}

struct RoomTextures {
  std::shared_ptr<const Texture> floor, ceiling, xlo, xhi, ylo, yhi;
};

void addRoom(LayoutResult& out, const Vector3f& lo, const Vector3f& hi, const RoomTextures& t) {
  RoomFaces r = makeRoom(lo, hi, 1);
  out.objects.push_back(fixedObject("room_floor", "room_floor", std::move(r.floor), t.floor, false));
  out.objects.push_back(fixedObject("room_ceiling", "room_ceiling", std::move(r.ceiling), t.ceiling, false));
  out.objects.push_back(fixedObject("room_wall_xlo", "room_wall", std::move(r.wall_xlo), t.xlo, false));
  out.objects.push_back(fixedObject("room_wall_xhi", "room_wall", std::move(r.wall_xhi), t.xhi, false));
  out.objects.push_back(fixedObject("room_wall_ylo", "room_wall", std::move(r.wall_ylo), t.ylo, false));
  out.objects.push_back(fixedObject("room_wall_yhi", "room_wall", std::move(r.wall_yhi), t.yhi, false));
  out.room = Eigen::AlignedBox3f(lo, hi);
}

// The procedural content objects shared by the room layouts, in the order the
// layouts place them. Texture parameters refer to the unit-radius frame.
ContentSpec contentSpec(const std::string& kind, std::uint64_t seed) {
  ContentSpec s;
  s.kind = kind;
  s.name = kind;
  if (kind == "blob") {
    s.mesh = makeBumpyBlob(1.0f, 0.22f, 1.6f, seed, 96, 48);
    s.texture = makeMarble(1.2f, rgb(120, 190, 120), rgb(30, 70, 40), seed + 1);
  } else if (kind == "crate") {
    s.mesh = makeBox(Vector3f(-0.5f, -0.5f, -0.5f), Vector3f(0.5f, 0.5f, 0.5f), 1);
    s.texture = makeChecker(0.29f, rgb(230, 200, 60), rgb(40, 60, 150), seed + 2);
  } else if (kind == "ball") {
    s.mesh = makeSphere(1.0f, 96, 48);
    s.texture = makeDots(0.42f, 0.14f, rgb(235, 235, 225), rgb(200, 40, 40), seed + 3);
  } else if (kind == "donut") {
    // Standing upright: the ring axis is horizontal.
    const TriangleMesh t = makeTorus(0.7f, 0.3f, 96, 48);
    Eigen::Affine3f R(Eigen::AngleAxisf(static_cast<float>(kPi / 2), Vector3f::UnitX()));
    s.mesh = transformed(t, R);
    s.texture =
        makeStripes(Vector3f(1, 0.2f, 0), 0.14f, rgb(240, 150, 170), rgb(250, 240, 230), rgb(150, 90, 60), seed + 4);
  } else if (kind == "column") {
    s.mesh = makeCylinder(0.3f, 1.4f, 96);
    s.texture = makeWood(Vector3f(0.05f, 0.0f, 1.0f), Vector3f(0.9f, 0.4f, 0.0f), 0.07f, rgb(215, 170, 110),
                         rgb(120, 70, 35), seed + 5);
  } else if (kind == "cone") {
    s.mesh = makeCone(0.5f, 1.0f, 96);
    s.texture =
        makeStripes(Vector3f(0, 0, 1), 0.16f, rgb(60, 160, 210), rgb(245, 245, 240), rgb(250, 170, 40), seed + 6);
  } else {  // "superquadric"
    s.mesh = makeSuperquadric(Vector3f(1.0f, 0.8f, 0.6f), 0.45f, 0.45f, 96, 48);
    s.texture = makeTiles(0.3f, 0.03f, rgb(200, 90, 200), rgb(250, 230, 250), rgb(60, 50, 60), seed + 7);
  }
  return s;
}

std::vector<int> everyEighthTest(int n, std::vector<int>& train) {
  std::vector<int> test;
  for (int i = 0; i < n; ++i) (i % 8 == 0 ? test : train).push_back(i);
  return test;
}

Camera lookAtf(const Intrinsics& K, const Vector3d& eye, const Vector3d& target) {
  return Camera::lookAt(K, eye, target, Vector3d::UnitZ());
}

// Splits `total` into parts proportional to `weights` (largest remainders, each >= 0).
std::vector<int> apportion(const std::vector<double>& weights, int total) {
  double sum = 0;
  for (double w : weights) sum += w;
  std::vector<int> out(weights.size());
  std::vector<std::pair<double, std::size_t>> rem;
  int used = 0;
  for (std::size_t i = 0; i < weights.size(); ++i) {
    const double exact = weights[i] / sum * total;
    out[i] = static_cast<int>(std::floor(exact));
    used += out[i];
    rem.emplace_back(exact - out[i], i);
  }
  std::stable_sort(rem.begin(), rem.end(), [](auto& a, auto& b) { return a.first > b.first; });
  for (std::size_t k = 0; used < total; ++k, ++used) ++out[rem[k % rem.size()].second];
  return out;
}

}  // namespace

Intrinsics layoutIntrinsics(int width, int height, double fov_deg) {
  Intrinsics K;
  K.width = width;
  K.height = height;
  const double f = 0.5 * std::min(width, height) / std::tan(0.5 * fov_deg * kPi / 180.0);
  K.fx = K.fy = f;
  K.cx = 0.5 * width;
  K.cy = 0.5 * height;
  return K;
}

LayoutResult makeObjectLayout(const Assets& assets, int width, int height, std::uint64_t seed, int num_views) {
  LayoutResult out;
  if (!assets.meshes.empty()) {
    ContentSpec spec;
    spec.name = "object";
    spec.kind = "mesh";
    spec.texture = makeMarble(1.5f, rgb(235, 215, 180), rgb(110, 60, 35), mix64(seed) + 1);
    std::string source;
    resolveContent(assets, 0, spec, source);
    out.objects.push_back(fixedObject("object", "", spec.mesh, spec.texture, true));
    out.objects.back().mesh_source = source;
  } else {
    // A compound toy: a bumpy marble blob with a tilted striped ring around it and a
    // small dotted ball on top, normalised together to radius 1 about the origin.
    const std::uint64_t s = mix64(seed);
    const TriangleMesh blob = makeBumpyBlob(0.62f, 0.2f, 1.8f, s, 128, 64);
    Eigen::Affine3f ring_T = Eigen::Affine3f::Identity();
    ring_T.rotate(Eigen::AngleAxisf(0.45f, Vector3f(1, 0.3f, 0).normalized()));
    const TriangleMesh ring = transformed(makeTorus(0.82f, 0.1f, 128, 32), ring_T);
    Eigen::Affine3f ball_T(Eigen::Translation3f(0.05f, -0.05f, 0.7f));
    const TriangleMesh ball = transformed(makeSphere(0.2f, 64, 32), ball_T);
    TriangleMesh all = blob;
    appendMesh(all, ring);
    appendMesh(all, ball);
    TriangleMesh probe = all;
    const Eigen::Affine3f N = normaliseMesh(probe, 1.0f);
    auto part = [&](const char* name, const char* kind, const TriangleMesh& m, std::shared_ptr<const Texture> tex,
                    const Eigen::Affine3f& local_to_design) {
      SceneObject o = fixedObject(name, kind, transformed(m, N), std::move(tex), true);
      // The texture frame is the part's own frame before it was moved into the compound.
      o.to_world = N * local_to_design;
      out.objects.push_back(std::move(o));
    };
    part("blob", "bumpy_blob", blob, makeMarble(1.6f, rgb(240, 200, 140), rgb(150, 50, 30), s + 1),
         Eigen::Affine3f::Identity());
    part("ring", "torus", ring,
         makeStripes(Vector3f(1, 0.1f, 0.2f), 0.09f, rgb(40, 90, 200), rgb(245, 245, 245), rgb(220, 60, 50), s + 2),
         ring_T);
    part("cap", "sphere", ball, makeDots(0.11f, 0.035f, rgb(60, 170, 90), rgb(250, 240, 120), s + 3), ball_T);
    for (std::size_t k = 0; k < out.objects.size() && !assets.photos.empty(); ++k) {
      const std::size_t p = k % assets.photos.size();
      out.objects[k].texture = makeImageTexture(assets.photos[p], assets.projection, 1.0f, assets.photo_paths[p]);
    }
  }
  const int n = num_views > 0 ? num_views : 150;
  const int n_train = num_views > 0 ? static_cast<int>(std::lround(n * 2.0 / 3.0)) : 100;
  const Intrinsics K = layoutIntrinsics(width, height, 36.0);
  Rng rng(seed ^ 0x0B1EC7ull);
  const double s_lo = std::sin(10 * kPi / 180), s_hi = std::sin(80 * kPi / 180);
  for (int i = 0; i < n; ++i) {
    const double az = rng.uniform(0, 2 * kPi);
    const double el = std::asin(rng.uniform(s_lo, s_hi));  // area-uniform in the band
    const Vector3d eye = 4.0 * Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
    out.cameras.push_back(lookAtf(K, eye, Vector3d::Zero()));
    (i < n_train ? out.train : out.test).push_back(i);
  }
  return out;
}

LayoutResult makeRoom360Layout(const Assets& assets, int width, int height, std::uint64_t seed, int num_views) {
  LayoutResult out;
  const std::uint64_t s = mix64(seed + 360);
  RoomTextures rt;
  rt.floor = makePlanks(0.22f, 1.3f, rgb(205, 155, 100), rgb(120, 72, 38), s + 10);
  rt.ceiling = makeSpeckle(1.5f, rgb(235, 232, 222), rgb(150, 150, 140), s + 11);
  rt.xlo = makeBricks(0.26f, 0.11f, 0.018f, rgb(165, 72, 48), rgb(205, 200, 190), s + 12);
  rt.xhi = makeStripes(Vector3f(0, 1, 0), 0.18f, rgb(110, 160, 100), rgb(238, 232, 200), rgb(70, 110, 70), s + 13);
  rt.ylo = makeTiles(0.4f, 0.025f, rgb(70, 120, 190), rgb(235, 240, 245), rgb(90, 90, 95), s + 14);
  rt.yhi = makeMarble(0.8f, rgb(228, 230, 238), rgb(70, 75, 105), s + 15);
  addRoom(out, Vector3f(-4, -4, 0), Vector3f(4, 4, 4), rt);

  Rng rng(seed ^ 0x360360ull);
  // One object in the middle, five on a ring of radius 1.35 (sizes are bounding radii,
  // so neighbours cannot touch: the smallest gap is kept positive by construction).
  out.objects.push_back(placeOnFloor(assets, 0, contentSpec("blob", s), Vector2f(0, 0), 0.0f, 0.5f,
                                     static_cast<float>(rng.uniform(0, 2 * kPi))));
  const char* kinds[5] = {"crate", "ball", "donut", "column", "cone"};
  const float sizes[5] = {0.55f, 0.45f, 0.55f, 0.7f, 0.6f};
  const double phase = rng.uniform(0, 2 * kPi);
  for (int k = 0; k < 5; ++k) {
    const double a = phase + 2 * kPi * k / 5 + rng.uniform(-1, 1) * 5 * kPi / 180;
    const Vector2f xy(static_cast<float>(1.35 * std::cos(a)), static_cast<float>(1.35 * std::sin(a)));
    out.objects.push_back(placeOnFloor(assets, k + 1, contentSpec(kinds[k], s + 100 * (k + 1)), xy, 0.0f, sizes[k],
                                       static_cast<float>(rng.uniform(0, 2 * kPi))));
  }

  const int n = num_views > 0 ? num_views : 150;
  const Intrinsics K = layoutIntrinsics(width, height, 55.0);
  const double pr = rng.uniform(0, 2 * kPi), ph = rng.uniform(0, 2 * kPi);
  const double start = rng.uniform(0, 2 * kPi);
  for (int i = 0; i < n; ++i) {
    const double phi = start + 2 * kPi * (i + rng.uniform(-0.3, 0.3)) / n;
    const double r = 3.0 * (1.0 + 0.2 * std::sin(3 * phi + pr));
    const double h = 1.6 + 0.6 * std::sin(5 * phi + ph);
    const Vector3d eye(r * std::cos(phi), r * std::sin(phi), h);
    const Vector3d target(rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3), 0.5 + rng.uniform(-0.15, 0.15));
    out.cameras.push_back(lookAtf(K, eye, target));
  }
  out.test = everyEighthTest(n, out.train);
  return out;
}

LayoutResult makeUnbalancedLayout(const Assets& assets, int width, int height, std::uint64_t seed, int num_views) {
  LayoutResult out;
  const std::uint64_t s = mix64(seed + 777);
  RoomTextures rt;
  rt.floor = makeTiles(0.5f, 0.03f, rgb(200, 195, 185), rgb(110, 105, 100), rgb(60, 55, 50), s + 10);
  rt.ceiling = makeSpeckle(1.2f, rgb(240, 238, 230), rgb(170, 165, 155), s + 11);
  rt.xlo = makeStripes(Vector3f(0, 1, 0.15f), 0.25f, rgb(210, 120, 80), rgb(245, 225, 190), rgb(160, 70, 60), s + 12);
  rt.xhi = makePlanks(0.18f, 1.6f, rgb(190, 150, 105), rgb(100, 65, 40), s + 13);
  rt.ylo = makeBricks(0.3f, 0.12f, 0.02f, rgb(200, 170, 100), rgb(90, 85, 80), s + 14);
  rt.yhi = makeMarble(0.9f, rgb(190, 215, 210), rgb(40, 80, 80), s + 15);
  addRoom(out, Vector3f(-5, -3.5f, 0), Vector3f(5, 3.5f, 3.2f), rt);

  Rng rng(seed ^ 0xBADBA1ull);
  struct Slot {
    const char* kind;
    Vector2f xy;
    float size;
  };
  const Slot slots[5] = {{"ball", {-3.0f, -2.2f}, 0.45f},
                         {"crate", {-3.0f, 2.1f}, 0.55f},
                         {"donut", {0.2f, 0.9f}, 0.55f},
                         {"cone", {3.3f, 2.2f}, 0.6f},
                         {"superquadric", {3.3f, -2.2f}, 0.55f}};
  std::vector<Vector3d> centres;  // look-at points of the objects
  for (int k = 0; k < 5; ++k) {
    out.objects.push_back(placeOnFloor(assets, k, contentSpec(slots[k].kind, s + 100 * (k + 1)), slots[k].xy, 0.0f,
                                       slots[k].size, static_cast<float>(rng.uniform(0, 2 * kPi))));
    centres.push_back(boundingBox(out.objects.back().mesh).center().cast<double>());
  }
  // Occluders: two floor-to-ceiling pillars and a partition wall.
  {
    Eigen::Affine3f T(Eigen::Translation3f(-1.3f, 0.3f, 0.0f));
    out.objects.push_back(fixedObject("pillar_round", "cylinder", transformed(makeCylinder(0.3f, 3.2f, 64), T),
                                      makeSpeckle(3.0f, rgb(175, 175, 170), rgb(90, 90, 95), s + 20), true));
    out.objects.push_back(
        fixedObject("pillar_square", "box", makeBox(Vector3f(1.45f, 0.15f, 0.0f), Vector3f(1.95f, 0.65f, 3.2f), 1),
                    makeBricks(0.22f, 0.09f, 0.015f, rgb(150, 60, 45), rgb(215, 210, 200), s + 21), true));
    out.objects.push_back(fixedObject("partition", "box",
                                      makeBox(Vector3f(-0.9f, -0.375f, 0.0f), Vector3f(0.5f, -0.225f, 1.8f), 1),
                                      makeChecker(0.2f, rgb(240, 240, 235), rgb(50, 50, 55), s + 22), true));
  }

  // The walk: four clusters (dense, nearly similar views of one object each) joined by
  // sparse stretches that look ahead along the way.
  struct Cluster {
    Vector3d centre;
    int target;  // index into `centres`
    double weight;
  };
  const Cluster clusters[4] = {
      {{-1.2, -1.4, 1.5}, 0, 36}, {{1.2, -1.5, 1.4}, 4, 26}, {{2.6, 2.0, 1.6}, 2, 34}, {{-1.5, 2.2, 1.5}, 1, 30}};
  // Stretch k runs from cluster k to cluster k+1 (the last one back towards the first)
  // through the given via points, which keep it clear of the pillars.
  const std::vector<std::vector<Vector3d>> stretches = {{clusters[0].centre, clusters[1].centre},
                                                        {clusters[1].centre, {3.3, 0.0, 1.5}, clusters[2].centre},
                                                        {clusters[2].centre, clusters[3].centre},
                                                        {clusters[3].centre, {-2.4, 0.3, 1.5}, {-1.9, -0.7, 1.5}}};
  const int n = num_views > 0 ? num_views : 150;
  std::vector<double> weights;
  for (int k = 0; k < 4; ++k) {
    weights.push_back(clusters[k].weight);
    weights.push_back(6);
  }
  const std::vector<int> counts = apportion(weights, n);
  const Intrinsics K = layoutIntrinsics(width, height, 60.0);
  for (int k = 0; k < 4; ++k) {
    const Cluster& c = clusters[k];
    for (int i = 0; i < counts[2 * k]; ++i) {
      const Eigen::Vector2d d = rng.disc() * 0.18;
      const Vector3d eye = c.centre + Vector3d(d.x(), d.y(), rng.uniform(-0.12, 0.12));
      const Eigen::Vector2d e = rng.disc() * 0.25;
      const Vector3d target = centres[c.target] + Vector3d(e.x(), e.y(), rng.uniform(-0.1, 0.1));
      out.cameras.push_back(lookAtf(K, eye, target));
    }
    // The stretch: evenly spaced by arc length along its polyline, ends excluded.
    const auto& poly = stretches[k];
    std::vector<double> cum{0};
    for (std::size_t j = 1; j < poly.size(); ++j) cum.push_back(cum.back() + (poly[j] - poly[j - 1]).norm());
    const int m = counts[2 * k + 1];
    for (int i = 0; i < m; ++i) {
      const double len = cum.back() * (i + 1) / (m + 1);
      std::size_t j = 1;
      while (j + 1 < poly.size() && cum[j] < len) ++j;
      const double t = (len - cum[j - 1]) / (cum[j] - cum[j - 1]);
      Vector3d eye = poly[j - 1] + t * (poly[j] - poly[j - 1]);
      eye.z() += 0.15 * std::sin(3.0 * len) + rng.uniform(-0.05, 0.05);
      Vector3d ahead = (poly[j] - poly[j - 1]).normalized();
      ahead = Eigen::AngleAxisd(rng.uniform(-0.5, 0.5), Vector3d::UnitZ()) * ahead;
      const Vector3d target = eye + 2.5 * ahead + Vector3d(0, 0, -0.8 + rng.uniform(-0.2, 0.2));
      out.cameras.push_back(lookAtf(K, eye, target));
    }
  }
  out.test = everyEighthTest(static_cast<int>(out.cameras.size()), out.train);
  return out;
}

const std::vector<std::string>& twoRoomsDefaultMeshes() {
  static const std::vector<std::string> kMeshes = {"cgal:cow",   "cgal:elephant",    "cgal:camel",
                                                   "cgal:homer", "cgal:triceratops", "cgal:pig"};
  return kMeshes;
}

LayoutResult makeTwoRoomsLayout(const Assets& assets, int width, int height, std::uint64_t seed, int num_views) {
  LayoutResult out;
  const std::uint64_t s = mix64(seed + 2222);
  RoomTextures rt;
  rt.floor = makePlanks(0.2f, 1.4f, rgb(196, 150, 98), rgb(110, 70, 40), s + 10);
  rt.ceiling = makeSpeckle(1.4f, rgb(238, 236, 228), rgb(160, 158, 150), s + 11);
  rt.xlo = makeBricks(0.28f, 0.11f, 0.018f, rgb(170, 80, 55), rgb(210, 205, 195), s + 12);
  rt.xhi = makeMarble(0.8f, rgb(215, 225, 235), rgb(60, 70, 110), s + 13);
  rt.ylo = makeStripes(Vector3f(0, 0, 1), 0.2f, rgb(120, 170, 110), rgb(240, 236, 205), rgb(80, 120, 80), s + 14);
  rt.yhi = makeTiles(0.45f, 0.03f, rgb(210, 170, 80), rgb(245, 240, 225), rgb(90, 80, 70), s + 15);
  const float half_w = 3.0f, top = 3.0f;
  addRoom(out, Vector3f(-6, -half_w, 0), Vector3f(6, half_w, top), rt);

  // The dividing wall at x = 0 (16 cm thick) with a doorway |y| <= 0.55, z <= 2.1: two
  // wall pieces and a lintel. Named room_* like the room's faces (structure, not content).
  const float t = 0.08f, door = 0.55f, door_top = 2.1f;
  auto wallTexture = [&](std::uint64_t k) { return makeChecker(0.25f, rgb(235, 230, 220), rgb(70, 90, 120), s + k); };
  out.objects.push_back(fixedObject("room_divider_south", "box",
                                    makeBox(Vector3f(-t, -half_w, 0), Vector3f(t, -door, top), 1), wallTexture(20),
                                    true));
  out.objects.push_back(fixedObject(
      "room_divider_north", "box", makeBox(Vector3f(-t, door, 0), Vector3f(t, half_w, top), 1), wallTexture(20), true));
  out.objects.push_back(fixedObject("room_divider_lintel", "box",
                                    makeBox(Vector3f(-t, -door, door_top), Vector3f(t, door, top), 1), wallTexture(20),
                                    true));

  Rng rng(seed ^ 0x2D002D00ull);
  struct Slot {
    const char* kind;  // the texture's (and, with no mesh files, the mesh's) kind
    Vector2f xy;
    float size;
  };
  // Three objects per room around its centre (x = -3 and x = 3), apart by construction.
  const Slot slots[6] = {{"blob", {-3.0f, 0.0f}, 0.55f}, {"crate", {-3.8f, -0.8f}, 0.45f},
                         {"cone", {-2.3f, 0.9f}, 0.45f}, {"superquadric", {3.0f, 0.0f}, 0.55f},
                         {"ball", {3.7f, 0.9f}, 0.45f},  {"donut", {2.4f, -0.9f}, 0.45f}};
  for (int k = 0; k < 6; ++k) {
    out.objects.push_back(placeOnFloor(assets, k, contentSpec(slots[k].kind, s + 100 * (k + 1)), slots[k].xy, 0.0f,
                                       slots[k].size, static_cast<float>(rng.uniform(0, 2 * kPi))));
    // A built-in mesh names its object ("cow"); a file keeps the slot's name.
    SceneObject& o = out.objects.back();
    if (o.mesh_source.rfind("cgal:", 0) == 0) o.name = o.mesh_source.substr(5);
  }

  const int n = num_views > 0 ? num_views : 150;
  const std::vector<int> counts = apportion({56.0, 16.0, 56.0, 22.0}, n);
  const Intrinsics K = layoutIntrinsics(width, height, 60.0);
  auto jitteredCentre = [&](double cx) {
    return Vector3d(cx + rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5), 0.4 + rng.uniform(-0.2, 0.2));
  };
  // A three-quarter arc of radius 2 about (cx, 0), its gap towards the door, looking in.
  auto arc = [&](double cx, double from, int m) {
    for (int i = 0; i < m; ++i) {
      const double a = from + 1.5 * kPi * (i + 0.5 + rng.uniform(-0.25, 0.25)) / m;
      const double r = 2.0 + rng.uniform(-0.1, 0.1);
      const Vector3d eye(cx + r * std::cos(a), r * std::sin(a), 1.6 + 0.2 * std::sin(2 * a) + rng.uniform(-0.05, 0.05));
      out.cameras.push_back(lookAtf(K, eye, jitteredCentre(cx)));
    }
  };
  arc(-3.0, 0.25 * kPi, counts[0]);  // first room: 45 .. 315 degrees
  // Through the door, looking ahead (yaw within +-0.35 rad) and a little down.
  for (int i = 0; i < counts[1]; ++i) {
    const double x = -1.5 + 3.0 * (i + 0.5) / counts[1];
    const Vector3d eye(x, rng.uniform(-0.1, 0.1), 1.5 + rng.uniform(-0.05, 0.05));
    const double yaw = rng.uniform(-0.35, 0.35);
    const Vector3d target = eye + 2.5 * Vector3d(std::cos(yaw), std::sin(yaw), 0) + Vector3d(0, 0, -0.8);
    out.cameras.push_back(lookAtf(K, eye, target));
  }
  arc(3.0, -0.75 * kPi, counts[2]);  // second room: 225 .. 495 degrees
  // Looking back from the second room towards the first one's centre: the wall hides
  // most of it, the doorway shows a slice.
  for (int i = 0; i < counts[3]; ++i) {
    const Vector3d eye(rng.uniform(1.0, 2.4), rng.uniform(-1.6, 1.6), 1.5 + rng.uniform(-0.1, 0.1));
    out.cameras.push_back(lookAtf(K, eye, jitteredCentre(-3.0)));
  }
  out.test = everyEighthTest(static_cast<int>(out.cameras.size()), out.train);
  return out;
}

LayoutResult makeCorridorLayout(const Assets& assets, int width, int height, std::uint64_t seed, int num_views) {
  LayoutResult out;
  const std::uint64_t s = mix64(seed + 3333);
  RoomTextures rt;
  rt.floor = makeTiles(0.4f, 0.03f, rgb(180, 185, 190), rgb(95, 100, 110), rgb(50, 50, 55), s + 10);
  rt.ceiling = makeSpeckle(1.3f, rgb(236, 234, 226), rgb(165, 160, 150), s + 11);
  rt.xlo = makeMarble(0.8f, rgb(225, 210, 190), rgb(110, 70, 50), s + 12);
  rt.xhi = makeBricks(0.26f, 0.1f, 0.016f, rgb(150, 90, 70), rgb(215, 210, 200), s + 13);
  rt.ylo = makePlanks(0.2f, 1.5f, rgb(200, 160, 110), rgb(105, 70, 45), s + 14);
  rt.yhi = makeStripes(Vector3f(0, 0, 1), 0.22f, rgb(90, 140, 190), rgb(240, 238, 225), rgb(60, 90, 130), s + 15);
  const float half_w = 3.0f, top = 3.0f;
  addRoom(out, Vector3f(-9, -half_w, 0), Vector3f(9, half_w, top), rt);

  // Two dividing walls (16 cm thick) at x = -3 and x = 3, each with a doorway (1.1 m wide,
  // 2.1 m high) on opposite sides, so that no straight line passes both doors.
  const float t = 0.08f, door_top = 2.1f;
  auto divider = [&](const std::string& name, float x, float door_lo, float door_hi, std::uint64_t k) {
    auto tex = [&] { return makeChecker(0.25f, rgb(230, 228, 220), rgb(120, 70, 90), s + k); };
    out.objects.push_back(fixedObject(
        name + "_south", "box", makeBox(Vector3f(x - t, -half_w, 0), Vector3f(x + t, door_lo, top), 1), tex(), true));
    out.objects.push_back(fixedObject(
        name + "_north", "box", makeBox(Vector3f(x - t, door_hi, 0), Vector3f(x + t, half_w, top), 1), tex(), true));
    out.objects.push_back(fixedObject(name + "_lintel", "box",
                                      makeBox(Vector3f(x - t, door_lo, door_top), Vector3f(x + t, door_hi, top), 1),
                                      tex(), true));
  };
  divider("room_divider_ab", -3.0f, 0.9f, 2.0f, 20);
  divider("room_divider_bc", 3.0f, -2.0f, -0.9f, 21);

  Rng rng(seed ^ 0xC0441D02ull);
  struct Slot {
    const char* kind;
    Vector2f xy;
    float size;
  };
  // Two objects in each of the first two rooms, three in the last.
  const Slot slots[7] = {{"blob", {-6.0f, 0.0f}, 0.55f},        {"crate", {-7.1f, -1.0f}, 0.4f},
                         {"cone", {0.8f, 1.6f}, 0.45f},         {"donut", {-0.8f, -1.6f}, 0.45f},
                         {"superquadric", {6.9f, -0.9f}, 0.5f}, {"ball", {5.4f, 0.8f}, 0.4f},
                         {"column", {6.7f, 0.9f}, 0.4f}};
  std::vector<Vector3d> centres;
  for (int k = 0; k < 7; ++k) {
    out.objects.push_back(placeOnFloor(assets, k, contentSpec(slots[k].kind, s + 100 * (k + 1)), slots[k].xy, 0.0f,
                                       slots[k].size, static_cast<float>(rng.uniform(0, 2 * kPi))));
    centres.push_back(boundingBox(out.objects.back().mesh).center().cast<double>());
  }

  // The walk, in order, with uneven density: a slow look around the first room, through its
  // door, a quick diagonal pass through the second room glancing at its two objects, through
  // the second door, a dense cluster of close views of one object in the last room, then a
  // sparse arc around that room.
  const int n = num_views > 0 ? num_views : 150;
  const std::vector<int> counts = apportion({55.0, 10.0, 10.0, 10.0, 47.0, 18.0}, n);
  const Intrinsics K = layoutIntrinsics(width, height, 60.0);
  auto centreOf = [&](double cx, double cy) {
    return Vector3d(cx + rng.uniform(-0.4, 0.4), cy + rng.uniform(-0.4, 0.4), 0.4 + rng.uniform(-0.2, 0.2));
  };
  auto arc = [&](double cx, double r0, double from, double sweep, int m) {
    for (int i = 0; i < m; ++i) {
      const double a = from + sweep * (i + 0.5 + rng.uniform(-0.25, 0.25)) / m;
      const double r = r0 + rng.uniform(-0.1, 0.1);
      const Vector3d eye(cx + r * std::cos(a), r * std::sin(a), 1.5 + 0.2 * std::sin(2 * a) + rng.uniform(-0.05, 0.05));
      out.cameras.push_back(lookAtf(K, eye, centreOf(cx, 0.0)));
    }
  };
  // Evenly spaced by arc length along a polyline, looking ahead (yaw within +-0.35 rad) and down.
  auto walk = [&](const std::vector<Vector3d>& poly, int m) {
    std::vector<double> cum{0};
    for (std::size_t j = 1; j < poly.size(); ++j) cum.push_back(cum.back() + (poly[j] - poly[j - 1]).norm());
    for (int i = 0; i < m; ++i) {
      const double len = cum.back() * (i + 0.5) / m;
      std::size_t j = 1;
      while (j + 1 < poly.size() && cum[j] < len) ++j;
      const double f = (len - cum[j - 1]) / (cum[j] - cum[j - 1]);
      Vector3d eye = poly[j - 1] + f * (poly[j] - poly[j - 1]);
      eye.z() += rng.uniform(-0.05, 0.05);
      const Vector3d ahead =
          Eigen::AngleAxisd(rng.uniform(-0.35, 0.35), Vector3d::UnitZ()) * (poly[j] - poly[j - 1]).normalized();
      out.cameras.push_back(lookAtf(K, eye, eye + 2.5 * ahead + Vector3d(0, 0, -0.8)));
    }
  };
  arc(-6.0, 1.8, 0.45 * kPi, 1.4 * kPi, counts[0]);  // the first room, 81 .. 333 degrees
  walk({{-4.3, 0.6, 1.5}, {-3.6, 1.45, 1.5}, {-2.2, 1.45, 1.5}}, counts[1]);
  for (int i = 0; i < counts[2]; ++i) {  // the second room: a diagonal, glancing either side
    const double f = (i + 0.5) / counts[2];
    const Vector3d eye(-1.8 + 3.6 * f, 1.45 - 2.9 * f + rng.uniform(-0.1, 0.1), 1.5 + rng.uniform(-0.05, 0.05));
    const Eigen::Vector2d e = rng.disc() * 0.2;
    out.cameras.push_back(lookAtf(K, eye, centres[2 + i % 2] + Vector3d(e.x(), e.y(), rng.uniform(-0.1, 0.1))));
  }
  walk({{2.2, -1.45, 1.5}, {3.6, -1.45, 1.5}, {4.4, -0.8, 1.5}}, counts[3]);
  for (int i = 0; i < counts[4]; ++i) {  // the last room: a cluster of close views of one object
    const Eigen::Vector2d d = rng.disc() * 0.2;
    const Vector3d eye = Vector3d(5.0, -1.9, 1.3) + Vector3d(d.x(), d.y(), rng.uniform(-0.12, 0.12));
    const Eigen::Vector2d e = rng.disc() * 0.2;
    out.cameras.push_back(lookAtf(K, eye, centres[4] + Vector3d(e.x(), e.y(), rng.uniform(-0.1, 0.1))));
  }
  arc(6.2, 2.2, -0.35 * kPi, 1.4 * kPi, counts[5]);  // and a sparse arc around it
  out.test = everyEighthTest(static_cast<int>(out.cameras.size()), out.train);
  return out;
}

}  // namespace saresgs::synth
