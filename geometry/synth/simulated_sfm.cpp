#include "geometry/synth/simulated_sfm.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "geometry/scene/scene.h"
#include "geometry/float_env.h"

namespace saresgs {

namespace {

struct Observation {
  std::uint32_t image_index;  // index into scene.cameras
  Eigen::Vector2d uv;
  double depth;
};

// Which train cameras see `s` directly: in front, inside the image, facing the
// surface and not occluded on the segment from the camera to the point.
std::vector<Observation> observe(const SyntheticScene& scene, const SurfaceSample& s) {
  std::vector<Observation> obs;
  const Eigen::Vector3d X = s.point.cast<double>();
  for (int i : scene.train) {
    const Camera& cam = scene.cameras[i];
    const Eigen::Vector3d C = cam.center();
    if (s.normal.cast<double>().dot(C - X) <= 0) continue;
    const auto uv = cam.project(X);
    if (!uv || !cam.inImage(*uv)) continue;
    const Eigen::Vector3f dir = (s.point - C.cast<float>());
    // Segment parameter in (1e-4, 1 - 1e-3): stop short of the surface itself.
    if (scene.occluded(C.cast<float>(), dir, 1e-4f, 1.0f - 1e-3f)) continue;
    obs.push_back({static_cast<std::uint32_t>(i), *uv, cam.toCamera(X).z()});
  }
  return obs;
}

}  // namespace

void simulateSfm(const SyntheticScene& scene, ColmapModel& model, const SimulatedSfmOptions& opts) {
  std::mt19937_64 rng(opts.seed ^ 0x5f3759dfULL);
  const std::vector<SurfaceSample> samples = scene.sampleSurface(opts.candidates, rng);

  // Visibility is the expensive part (one shadow ray per camera and sample); it is
  // computed in parallel into fixed slots, so the result does not depend on threads.
  std::vector<std::vector<Observation>> seen(samples.size());
  tbb::parallel_for(std::size_t(0), samples.size(), [&](std::size_t k) {
    const FloatEnvGuard fenv;  // geometry/float_env.h
    seen[k] = observe(scene, samples[k]);
  });

  AABB box;
  for (const auto& s : samples) box.extend(s.point.cast<double>());

  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::uint64_t next_id = 1;
  for (std::size_t k = 0; k < samples.size() && model.points.size() < opts.max_points; ++k) {
    const auto& obs = seen[k];
    if (static_cast<int>(obs.size()) < opts.min_views) continue;
    ColmapPoint3D p;
    p.id = next_id++;
    // Noise whose projection is about `pixel_noise` px in the mean: the image-plane
    // displacement of an isotropic 3D offset of std s at depth z is ~ f s sqrt(2) / z
    // in rms, and the mean of a 2D Gaussian norm is sqrt(pi/2)/sqrt(2) of its rms.
    double mean_depth = 0, f = 0;
    for (const auto& o : obs) {
      mean_depth += o.depth;
      f += scene.cameras[o.image_index].K.fx;
    }
    mean_depth /= obs.size();
    f /= obs.size();
    const double sigma = opts.pixel_noise * mean_depth / (f * std::sqrt(M_PI / 2.0));
    const Eigen::Vector3d X = samples[k].point.cast<double>();
    Eigen::Vector3d noisy = X + sigma * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng));
    if (uni(rng) < opts.outlier_fraction) {
      // A wrong match: a random point in the box, but in front of every camera that
      // observes it, as SfM's cheirality check guarantees. A few tries, else an inlier.
      for (int attempt = 0; attempt < 16; ++attempt) {
        const Eigen::Vector3d cand =
            box.min + (box.max - box.min).cwiseProduct(Eigen::Vector3d(uni(rng), uni(rng), uni(rng)));
        const bool in_front = std::all_of(obs.begin(), obs.end(), [&](const Observation& o) {
          return scene.cameras[o.image_index].toCamera(cand).z() > 1e-6;
        });
        if (in_front) {
          noisy = cand;
          break;
        }
      }
    }
    p.xyz = noisy;

    // Colour as the first observing camera sees the surface.
    SurfaceHit hit;
    hit.hit = true;
    hit.point = samples[k].point;
    hit.normal = samples[k].normal;
    hit.object = samples[k].object;
    const Eigen::Vector3f rgb = scene.shade(hit, scene.cameras[obs.front().image_index].center().cast<float>());
    for (int c = 0; c < 3; ++c)
      p.rgb[c] = static_cast<std::uint8_t>(std::lround(std::clamp(rgb[c], 0.0f, 1.0f) * 255.0f));

    double err = 0;
    for (const auto& o : obs) {
      ColmapImage& im = model.images.at(o.image_index + 1);
      const auto proj = scene.cameras[o.image_index].project(noisy);
      err += (*proj - o.uv).norm();  // in front of every observer by construction
      p.track.push_back({im.id, static_cast<std::uint32_t>(im.xys.size())});
      im.xys.push_back(o.uv);
      im.point3d_ids.push_back(p.id);
    }
    p.error = err / obs.size();
    model.points.emplace(p.id, std::move(p));
  }
}

}  // namespace saresgs
