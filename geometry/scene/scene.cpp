#include "geometry/scene/scene.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <mutex>
#include <tbb/parallel_for.h>
#include <stdexcept>

#include "geometry/error.h"
#include "geometry/io/pfm.h"

namespace saresgs {

// Images are read on first use and kept as 8-bit; the mutex guards the slots, and a
// slot once filled is never replaced, so returned references stay valid.
struct CachedImage {
  Image8 rgb;
  Image8 alpha;  // empty unless the file has alpha and the scene keeps it
};

class ImageCache {
 public:
  std::mutex mutex;
  std::vector<std::unique_ptr<CachedImage>> slots;
};

Scene::Scene() : cache_(std::make_shared<ImageCache>()) {}

namespace {

// Reads view `v`'s image at the size its camera expects. A folder such as images_4 is
// already downscaled (Scene loaders point image_path at it); otherwise the image is
// resized on load. A size that matches neither is an error naming the file.
std::unique_ptr<CachedImage> loadViewImage(const SceneView& v, const ImageLoadOptions& load) {
  auto out = std::make_unique<CachedImage>();
  Image8 img = readImage(v.image_path, /*keep_alpha=*/true);
  if (img.channels == 4 && load.keep_alpha) {
    out->alpha = Image8(img.width, img.height, 1);
    for (std::size_t p = 0; p < out->alpha.data.size(); ++p) out->alpha.data[p] = img.data[4 * p + 3];
  }
  if (img.channels == 4) img = compositeOnBackground(img, load.background.data());
  const int w = v.camera.K.width, h = v.camera.K.height;
  out->rgb = std::move(img);
  if (out->rgb.width == w && out->rgb.height == h) return out;
  // Accept a source that is `downscale` times larger (rounding either way).
  const int f = std::max(1, load.downscale);
  if (std::abs(out->rgb.width - w * f) <= f && std::abs(out->rgb.height - h * f) <= f && f > 1) {
    out->rgb = resizeImage(out->rgb, w, h);
    if (!out->alpha.empty()) out->alpha = resizeImage(out->alpha, w, h);
    return out;
  }
  img = std::move(out->rgb);
  throw InputError(v.image_path, "image size",
                   "expected " + std::to_string(w * f) + "x" + std::to_string(h * f) +
                       " (the camera's size) but the file is " + std::to_string(img.width) + "x" +
                       std::to_string(img.height));
}

}  // namespace

const Image8& Scene::image(int i) const { return cachedImage(i).rgb; }

const Image8* Scene::alpha(int i) const {
  const CachedImage& c = cachedImage(i);
  return c.alpha.empty() ? nullptr : &c.alpha;
}

const CachedImage& Scene::cachedImage(int i) const {
  std::lock_guard<std::mutex> lock(cache_->mutex);
  if (cache_->slots.size() < views.size()) cache_->slots.resize(views.size());
  auto& slot = cache_->slots.at(static_cast<size_t>(i));
  if (!slot) slot = loadViewImage(views.at(i), load);
  return *slot;
}

std::size_t Scene::preloadImages(const std::vector<int>& which) const {
  std::vector<int> missing;
  {
    std::lock_guard<std::mutex> lock(cache_->mutex);
    if (cache_->slots.size() < views.size()) cache_->slots.resize(views.size());
    for (int i : which)
      if (!cache_->slots.at(static_cast<size_t>(i))) missing.push_back(i);
  }
  std::sort(missing.begin(), missing.end());
  missing.erase(std::unique(missing.begin(), missing.end()), missing.end());
  std::vector<std::unique_ptr<CachedImage>> loaded(missing.size());
  std::vector<std::exception_ptr> failed(missing.size());
  tbb::parallel_for(std::size_t{0}, missing.size(), [&](std::size_t k) {
    try {
      loaded[k] = loadViewImage(views.at(static_cast<size_t>(missing[k])), load);
    } catch (...) {
      failed[k] = std::current_exception();
    }
  });
  // The first failure in `which`'s order, whatever order the decodes finished in.
  for (int i : which) {
    const auto at = std::lower_bound(missing.begin(), missing.end(), i);
    if (at != missing.end() && *at == i && failed[static_cast<size_t>(at - missing.begin())])
      std::rethrow_exception(failed[static_cast<size_t>(at - missing.begin())]);
  }
  std::lock_guard<std::mutex> lock(cache_->mutex);
  for (std::size_t k = 0; k < missing.size(); ++k) {
    auto& slot = cache_->slots[static_cast<size_t>(missing[k])];
    if (!slot) slot = std::move(loaded[k]);
  }
  return missing.size();
}

void Scene::resetImageCache() { cache_ = std::make_shared<ImageCache>(); }

void Scene::releaseImages() const {
  std::lock_guard<std::mutex> lock(cache_->mutex);
  cache_->slots.clear();
}

ImageF Scene::depth(int i) const {
  const SceneView& v = views.at(i);
  if (v.depth_path.empty()) throw InputError(source, "view " + v.name, "has no ground-truth depth");
  ImageF d = readPfm(v.depth_path);
  if (d.channels != 1) throw InputError(v.depth_path, "channels", "expected a 1-channel depth map");
  const int w = v.camera.K.width, h = v.camera.K.height;
  if (frame.scale != 1.0)
    for (float& z : d.data) z = static_cast<float>(z / frame.scale);
  if (d.width == w && d.height == h) return d;
  // Downscaled view: sample the depth at the new pixel centres (nearest). Averaging
  // depths would invent surfaces across occlusion edges.
  if (d.width < w || d.height < h) throw InputError(v.depth_path, "size", "depth map is smaller than the view");
  ImageF out(w, h, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int sx = std::min(d.width - 1, static_cast<int>((x + 0.5) * d.width / w));
      const int sy = std::min(d.height - 1, static_cast<int>((y + 0.5) * d.height / h));
      out.at(x, y) = d.at(sx, sy);
    }
  return out;
}

std::vector<Camera> Scene::cameras(const std::vector<int>& which) const {
  std::vector<Camera> out;
  out.reserve(which.size());
  for (int i : which) out.push_back(views.at(i).camera);
  return out;
}

void Scene::finalize() {
  aabb = AABB{};
  for (const auto& p : points) aabb.extend(p.xyz);
  if (points.empty())
    for (int i : train) aabb.extend(views[i].camera.center());
  extent = sceneExtent(cameras(train));
}

namespace {
constexpr const char* kAlphaNoneSaid = "alpha in the images, none said (white)";
// Images with an alpha channel decoded to find one that is not opaque, at most.
constexpr int kAlphaImagesDecoded = 8;
}  // namespace

void settleBackground(Scene& scene, const BackgroundRule& rule) {
  scene.random_background = false;
  if (rule.said) {
    scene.background = rule.said->color;
    scene.random_background = rule.said->random;
    scene.background_from = rule.said_by;
  } else if (rule.data_said) {
    scene.background = rule.data_color;
    scene.background_from = rule.data_color ? rule.data_from : rule.data_from + ": none";
  } else {
    scene.background.reset();
    scene.background_from = "none";
  }
  // Images with alpha need a background to be composited on, and training must render on
  // the same one: where nothing said one, white (the compositing default of every loader).
  // A manifest's null is a word too: the data is opaque (rooms written as RGBA).
  // Many tools write opaque images as RGBA: alpha counts where a pixel is not opaque, in
  // one of the first few images whose header says alpha (each of those is decoded).
  if (!rule.said && !rule.data_said) {
    int decoded = 0;
    for (const SceneView& v : scene.views) {
      if (decoded >= kAlphaImagesDecoded) break;
      if (!imageHasAlpha(v.image_path)) continue;
      ++decoded;
      if (imageHasTransparency(v.image_path)) {
        scene.background = std::array<float, 3>{1, 1, 1};
        scene.background_from = kAlphaNoneSaid;
        break;
      }
    }
  }
  // With none, renders are on black: so is any alpha a file still has.
  scene.load.background = scene.background.value_or(std::array<float, 3>{0, 0, 0});
  scene.load.keep_alpha = scene.random_background;
}

void setBackground(Scene& scene, const BackgroundChoice& choice, const std::string& said_by) {
  BackgroundRule rule;
  rule.said = choice;
  rule.said_by = said_by;
  settleBackground(scene, rule);
  scene.resetImageCache();
}

std::string backgroundWarning(const Scene& scene) {
  if (scene.background_from != kAlphaNoneSaid) return {};
  return scene.source +
         ": background: the images have alpha but nothing says what stands behind them; they are "
         "composited on white and trained against white (say --background white|black|R,G,B|random)\n";
}

void moveToOwnFrame(Scene& scene) {
  if (!scene.frame.identity())
    throw std::logic_error("moveToOwnFrame: " + scene.source + " is already in a frame of its own");
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int i : scene.train) mean += scene.views.at(i).camera.center();
  if (!scene.train.empty()) mean /= static_cast<double>(scene.train.size());
  const SceneFrame f = chooseSceneFrame(scene.extent, mean);
  if (f.identity()) return;
  for (SceneView& v : scene.views) v.camera = f.toInternal(v.camera);
  for (SparsePoint& p : scene.points) p.xyz = f.toInternal(p.xyz);
  scene.frame = f;
  scene.finalize();
}

}  // namespace saresgs
