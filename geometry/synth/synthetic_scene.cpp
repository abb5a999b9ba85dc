#include "geometry/synth/synthetic_scene.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "geometry/error.h"
#include "geometry/scene/manifest.h"
#include "geometry/synth/assets.h"
#include "geometry/synth/layouts.h"
#include "geometry/synth/noise.h"
#include "geometry/synth/procedural_meshes.h"
#include "geometry/synth/render_detail.h"
#include "geometry/synth/world.h"
#include "geometry/float_env.h"

namespace saresgs {

using Eigen::Vector3f;

// ---------------------------------------------------------------------------- world

std::vector<const TriangleMesh*> SyntheticWorld::meshPointers(const std::vector<synth::SceneObject>& o,
                                                              bool casters_only) {
  std::vector<const TriangleMesh*> out;
  for (const auto& x : o)
    if (!casters_only || x.casts_shadow) out.push_back(&x.mesh);
  return out;
}

std::vector<int> SyntheticWorld::objectIds(const std::vector<synth::SceneObject>& o, bool casters_only) {
  std::vector<int> out;
  for (std::size_t k = 0; k < o.size(); ++k)
    if (!casters_only || o[k].casts_shadow) out.push_back(static_cast<int>(k));
  return out;
}

SyntheticWorld::SyntheticWorld(std::vector<synth::SceneObject> objects, synth::Lighting lighting)
    : objects_(std::move(objects)),
      lighting_(lighting),
      tracer_(meshPointers(objects_, false), objectIds(objects_, false)),
      casters_(meshPointers(objects_, true), objectIds(objects_, true)) {
  double total = 0;
  for (std::size_t k = 0; k < objects_.size(); ++k) {
    const auto& o = objects_[k];
    normals_.push_back(synth::vertexNormals(o.mesh));
    to_local_.push_back(o.to_world.inverse());
    // Normals go to the local frame by the inverse transpose of world->local, i.e. A^T.
    normal_to_local_.push_back(o.to_world.linear().transpose());
    for (std::size_t f = 0; f < o.mesh.faces.size(); ++f) {
      const auto& F = o.mesh.faces[f];
      const Eigen::Vector3d a = o.mesh.vertices[F[0]].cast<double>();
      const double area =
          0.5 * (o.mesh.vertices[F[1]].cast<double>() - a).cross(o.mesh.vertices[F[2]].cast<double>() - a).norm();
      if (!(area > 0)) continue;
      total += area;
      area_cdf_.push_back(total);
      area_faces_.emplace_back(static_cast<int>(k), static_cast<int>(f));
    }
  }
}

// ----------------------------------------------------------------------- queries

SurfaceHit SyntheticScene::intersect(const Vector3f& origin, const Vector3f& dir, float tmin, float tmax) const {
  SurfaceHit out;
  const synth::TraceHit h = world_->tracer().intersect(origin, dir, tmin, tmax);
  if (!h.hit) return out;
  const auto& obj = world_->objects()[h.object];
  const auto& F = obj.mesh.faces[h.triangle];
  const auto& V = obj.mesh.vertices;
  const auto& N = world_->normals(h.object);
  out.hit = true;
  out.object = h.object;
  out.distance = h.t * dir.norm();
  out.point = origin + h.t * dir;
  // The geometric normal decides the side; the interpolated one gives smooth shading.
  Vector3f ng = (V[F[1]] - V[F[0]]).cross(V[F[2]] - V[F[0]]);
  if (ng.dot(dir) > 0) ng = -ng;
  Vector3f ns = (1 - h.u - h.v) * N[F[0]] + h.u * N[F[1]] + h.v * N[F[2]];
  if (ns.dot(ng) < 0) ns = -ns;
  const float len = ns.norm();
  // At silhouettes the smooth normal can still lean away from the ray: use the facet's.
  if (!(len > 1e-6f) || ns.dot(dir) >= 0)
    out.normal = ng.normalized();
  else
    out.normal = ns / len;
  return out;
}

bool SyntheticScene::occluded(const Vector3f& origin, const Vector3f& dir, float tmin, float tmax) const {
  return world_->tracer().occluded(origin, dir, tmin, tmax);
}

Vector3f SyntheticScene::shade(const SurfaceHit& hit, const Vector3f& eye, bool specular) const {
  if (!hit.hit || hit.object < 0) return background;
  const synth::Lighting& L = world_->lighting();
  const auto& obj = world_->objects()[hit.object];
  Vector3f n = hit.normal;
  const Vector3f to_eye = eye - hit.point;
  if (n.dot(to_eye) < 0) n = -n;
  const Vector3f p_local = world_->toLocal(hit.object) * hit.point;
  const Vector3f n_local = (world_->normalToLocal(hit.object) * n).normalized();
  const Vector3f albedo = obj.texture->albedo(p_local, n_local);
  const float ndl = n.dot(L.to_light);
  float light = L.ambient;
  Vector3f highlight = Vector3f::Zero();
  if (ndl > 0) {
    const Vector3f start = hit.point + L.shadow_epsilon * n;
    const bool shadowed =
        world_->casters().occluded(start, L.to_light, L.shadow_epsilon, std::numeric_limits<float>::infinity());
    if (!shadowed) {
      light += L.diffuse * ndl;
      if (specular && to_eye.squaredNorm() > 0) {
        const Vector3f h = (L.to_light + to_eye.normalized()).normalized();
        highlight = Vector3f::Constant(L.specular * std::pow(std::max(0.0f, n.dot(h)), L.shininess));
      }
    }
  }
  return (albedo * light + highlight).cwiseMax(0.0f).cwiseMin(1.0f);
}

ImageF SyntheticScene::render(const Camera& cam, const RenderOptions& opts) const {
  return synth::renderGrid(*this, cam, synth::gridForSamples(opts.samples_per_pixel), true, opts.specular);
}

ImageF SyntheticScene::renderRgba(const Camera& cam, const RenderOptions& opts) const {
  return synth::renderGrid(*this, cam, synth::gridForSamples(opts.samples_per_pixel), true, opts.specular, true);
}

ImageF SyntheticScene::renderDepth(const Camera& cam) const {
  const int W = cam.K.width, H = cam.K.height;
  ImageF depth(W, H, 1, 0.0f);
  const Vector3f c = cam.center().cast<float>();
  const Eigen::Vector3d view = cam.viewDirection();
  tbb::parallel_for(tbb::blocked_range<int>(0, H), [&](const tbb::blocked_range<int>& rows) {
    const FloatEnvGuard fenv;  // geometry/float_env.h
    for (int j = rows.begin(); j != rows.end(); ++j)
      for (int i = 0; i < W; ++i) {
        const Eigen::Vector3d d = cam.rayDirection(Eigen::Vector2d(i + 0.5, j + 0.5));
        const SurfaceHit h = intersect(c, d.cast<float>());
        if (h.hit) depth.at(i, j) = static_cast<float>(h.distance * d.dot(view));
      }
  });
  return depth;
}

std::vector<SurfaceSample> SyntheticScene::sampleSurface(std::size_t count, std::mt19937_64& rng) const {
  std::vector<SurfaceSample> out;
  const auto& cdf = world_->areaCdf();
  if (cdf.empty()) return out;
  out.reserve(count);
  auto uniform = [&] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
  for (std::size_t s = 0; s < count; ++s) {
    const double pick = uniform() * cdf.back();
    std::size_t idx = static_cast<std::size_t>(std::upper_bound(cdf.begin(), cdf.end(), pick) - cdf.begin());
    idx = std::min(idx, cdf.size() - 1);
    const auto [k, f] = world_->areaFaces()[idx];
    const auto& obj = world_->objects()[k];
    const auto& F = obj.mesh.faces[f];
    const auto& N = world_->normals(k);
    // Uniform barycentrics over the triangle.
    const double r1 = std::sqrt(uniform()), r2 = uniform();
    const float a = static_cast<float>(1 - r1), b = static_cast<float>(r1 * (1 - r2)), c = static_cast<float>(r1 * r2);
    SurfaceSample smp;
    smp.point = a * obj.mesh.vertices[F[0]] + b * obj.mesh.vertices[F[1]] + c * obj.mesh.vertices[F[2]];
    Vector3f n = a * N[F[0]] + b * N[F[1]] + c * N[F[2]];
    const Vector3f ng =
        (obj.mesh.vertices[F[1]] - obj.mesh.vertices[F[0]]).cross(obj.mesh.vertices[F[2]] - obj.mesh.vertices[F[0]]);
    if (n.dot(ng) < 0 || !(n.norm() > 1e-6f)) n = ng;
    smp.normal = n.normalized();
    smp.object = k;
    out.push_back(smp);
  }
  return out;
}

std::vector<std::string> SyntheticScene::objectNames() const {
  std::vector<std::string> names;
  for (const auto& o : world_->objects()) names.push_back(o.name);
  return names;
}

// ------------------------------------------------------------------- rendering

namespace synth {

int gridForSamples(int samples_per_pixel) {
  const int n = std::max(samples_per_pixel, 4);
  int g = 1;
  while (g * g < n) ++g;  // the smallest square grid with at least n samples
  return g;
}

ImageF renderGrid(const SyntheticScene& scene, const Camera& cam, int grid, bool jitter, bool specular, bool alpha) {
  grid = std::max(grid, 1);
  const int W = cam.K.width, H = cam.K.height;
  ImageF img(W, H, alpha ? 4 : 3, 0.0f);
  const Vector3f eye = cam.center().cast<float>();
  const float inv = 1.0f / static_cast<float>(grid * grid);
  tbb::parallel_for(tbb::blocked_range<int>(0, H), [&](const tbb::blocked_range<int>& rows) {
    const FloatEnvGuard fenv;  // geometry/float_env.h
    for (int j = rows.begin(); j != rows.end(); ++j)
      for (int i = 0; i < W; ++i) {
        Vector3f sum = Vector3f::Zero(), hits_sum = Vector3f::Zero();
        int hits = 0;
        for (int sy = 0; sy < grid; ++sy)
          for (int sx = 0; sx < grid; ++sx) {
            float jx = 0.5f, jy = 0.5f;
            if (jitter) {
              const std::uint64_t h = hashInts(i, j, sy * grid + sx, 0x5A5E5Bull);
              jx = unitFloat(h);
              jy = unitFloat(mix64(h));
            }
            const Eigen::Vector2d uv(i + (sx + jx) / grid, j + (sy + jy) / grid);
            const Vector3f d = cam.rayDirection(uv).cast<float>();
            const SurfaceHit hit = scene.intersect(eye, d);
            if (alpha) {
              if (hit.hit) {
                hits_sum += scene.shade(hit, eye, specular);
                ++hits;
              }
            } else {
              sum += hit.hit ? scene.shade(hit, eye, specular) : scene.background;
            }
          }
        if (alpha) {
          if (hits > 0) sum = hits_sum / static_cast<float>(hits);
          img.at(i, j, 3) = static_cast<float>(hits) * inv;
        } else {
          sum *= inv;
        }
        for (int ch = 0; ch < 3; ++ch) img.at(i, j, ch) = std::clamp(sum[ch], 0.0f, 1.0f);
      }
  });
  return img;
}

}  // namespace synth

// ------------------------------------------------------------------- building

namespace {

nlohmann::json toJson(const Vector3f& v) { return {v.x(), v.y(), v.z()}; }

nlohmann::json toJson(const Eigen::Affine3f& T) {
  nlohmann::json rows = nlohmann::json::array();
  const Eigen::Matrix4f M = T.matrix();
  for (int r = 0; r < 4; ++r) rows.push_back({M(r, 0), M(r, 1), M(r, 2), M(r, 3)});
  return rows;
}

}  // namespace

SyntheticOptions syntheticOptions(const std::string& layout, int width, int height, std::uint64_t seed,
                                  int num_views) {
  SyntheticOptions o;
  o.layout = layout;
  o.width = width;
  o.height = height;
  o.seed = seed;
  o.num_views = num_views;
  return o;
}

SyntheticScene makeSyntheticScene(const SyntheticOptions& opts) {
  if (opts.width <= 0 || opts.height <= 0)
    throw InputError(
        "options", "width/height",
        "expected a positive image size, got " + std::to_string(opts.width) + "x" + std::to_string(opts.height));
  if (opts.width > kMaxImageSide || opts.height > kMaxImageSide)
    throw InputError("options", "width/height",
                     "expected at most " + std::to_string(kMaxImageSide) + " per side, got " +
                         std::to_string(opts.width) + "x" + std::to_string(opts.height));
  if (opts.num_views < 0 || opts.num_views > kMaxSyntheticViews)
    throw InputError("options", "num_views",
                     "expected 0 (the layout's default) .. " + std::to_string(kMaxSyntheticViews) + ", got " +
                         std::to_string(opts.num_views));
  if (opts.layout != "object" && opts.layout != "room360" && opts.layout != "unbalanced" && opts.layout != "tworooms" &&
      opts.layout != "corridor")
    throw InputError("options", "layout",
                     "expected object, room360, unbalanced, tworooms or corridor, got '" + opts.layout + "'");
  synth::Assets assets;
  assets.projection = synth::parseProjection(opts.projection);
  const Eigen::Matrix3f up = synth::upAxisRotation(opts.up_axis);
  // tworooms is built from real meshes: CGAL's when the user gives none (recorded by their
  // cgal:NAME spec, which lets a dataset's manifest rebuild the scene).
  std::vector<std::string> mesh_files = opts.meshes, mesh_names = opts.meshes;
  if (mesh_files.empty() && opts.layout == "tworooms")
    for (const auto& spec : synth::twoRoomsDefaultMeshes()) {
      mesh_files.push_back(resolveAsset(spec));
      mesh_names.push_back(spec);
    }
  for (std::size_t i = 0; i < mesh_files.size(); ++i) {
    TriangleMesh m = readMeshFile(mesh_files[i]);
    for (auto& v : m.vertices) v = up * v;
    synth::normaliseMesh(m, 1.0f);
    assets.meshes.push_back(std::move(m));
    assets.mesh_paths.push_back(mesh_names[i]);
  }
  for (const auto& path : opts.textures) {
    const Image8 img = readImage(path);
    if (img.empty()) throw InputError(path, "file", "expected a non-empty image");
    assets.photos.push_back(std::make_shared<const ImageF>(toFloat(img)));
    assets.photo_paths.push_back(path);
  }

  synth::LayoutResult layout;
  if (opts.layout == "object")
    layout = synth::makeObjectLayout(assets, opts.width, opts.height, opts.seed, opts.num_views);
  else if (opts.layout == "room360")
    layout = synth::makeRoom360Layout(assets, opts.width, opts.height, opts.seed, opts.num_views);
  else if (opts.layout == "unbalanced")
    layout = synth::makeUnbalancedLayout(assets, opts.width, opts.height, opts.seed, opts.num_views);
  else if (opts.layout == "tworooms")
    layout = synth::makeTwoRoomsLayout(assets, opts.width, opts.height, opts.seed, opts.num_views);
  else
    layout = synth::makeCorridorLayout(assets, opts.width, opts.height, opts.seed, opts.num_views);

  SyntheticScene scene;
  scene.cameras = std::move(layout.cameras);
  for (std::size_t i = 0; i < scene.cameras.size(); ++i) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%04zu.png", i);
    scene.names.emplace_back(buf);
  }
  scene.train = std::move(layout.train);
  scene.test = std::move(layout.test);
  scene.background = Vector3f(1, 1, 1);
  scene.enclosed = opts.layout != "object";

  synth::Lighting lighting;
  nlohmann::json& m = scene.manifest;
  m["layout"] = opts.layout;
  m["seed"] = opts.seed;
  m["width"] = opts.width;
  m["height"] = opts.height;
  m["num_views"] = scene.cameras.size();
  m["num_train"] = scene.train.size();
  m["num_test"] = scene.test.size();
  m["up_axis"] = opts.up_axis;
  m["projection"] = opts.projection;
  // The data's background: an enclosed room has none (every pixel sees a wall), which
  // tells a trainer that no white-background handling applies; an object layout's misses
  // are white.
  m["background"] = scene.enclosed ? nlohmann::json(nullptr) : toJson(scene.background);
  m["light"] = {{"direction", toJson(lighting.to_light)},
                {"ambient", lighting.ambient},
                {"diffuse", lighting.diffuse},
                {"specular", lighting.specular},
                {"shininess", lighting.shininess}};
  if (layout.room) m["room"] = {{"min", toJson(layout.room->min())}, {"max", toJson(layout.room->max())}};
  m["objects"] = nlohmann::json::array();
  for (const auto& o : layout.objects) {
    const Eigen::AlignedBox3f box = synth::boundingBox(o.mesh);
    m["objects"].push_back({{"name", o.name},
                            {"mesh", o.mesh_source},
                            {"texture", o.texture->describe()},
                            {"transform", toJson(o.to_world)},
                            {"bbox_min", toJson(box.min())},
                            {"bbox_max", toJson(box.max())},
                            {"triangles", o.mesh.faces.size()},
                            {"area", synth::surfaceArea(o.mesh)},
                            {"casts_shadow", o.casts_shadow}});
  }
  scene.world_ = std::make_shared<const SyntheticWorld>(std::move(layout.objects), lighting);
  return scene;
}

}  // namespace saresgs
