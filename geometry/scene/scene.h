#pragma once
// The Scene value that every later room consumes: cameras, lazily loaded images,
// the train/test split, sparse points with colours, AABB, extent, optional
// ground-truth depth maps.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "geometry/camera/camera.h"
#include "geometry/image/image.h"
#include "geometry/scene/background.h"
#include "geometry/scene/scene_frame.h"

namespace saresgs {

struct SceneView {
  std::string name;        // image name as in the dataset (e.g. "000123.png")
  Camera camera;           // intrinsics already scaled to the loaded image size
  std::string image_path;  // absolute or relative to the working directory
  std::string depth_path;  // ground-truth depth (PFM, z along the camera axis), or empty
};

struct SparsePoint {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  std::array<std::uint8_t, 3> rgb{0, 0, 0};
};

struct AABB {
  Eigen::Vector3d min = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d max = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());
  bool empty() const { return !(min.array() <= max.array()).all(); }
  void extend(const Eigen::Vector3d& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
  Eigen::Vector3d center() const { return 0.5 * (min + max); }
  Eigen::Vector3d size() const { return empty() ? Eigen::Vector3d::Zero() : Eigen::Vector3d(max - min); }
};

// How images are read: from `images/` (factor 1), from `images_<f>` when that folder
// exists, or resized on load by 1/f. RGBA images are composited on `background`, which
// the loaders set to the scene's (settleBackground: a caller's value is replaced; say a
// background with DatasetOptions::background).
struct ImageLoadOptions {
  int downscale = 1;  // 1, 2, 4, 8, ...
  std::array<float, 3> background{1.0f, 1.0f, 1.0f};
  bool keep_alpha = false;  // also keep each RGBA image's alpha (Scene::alpha)
};

class ImageCache;  // defined in scene.cpp; shared by copies of a Scene
struct CachedImage;

class Scene {
 public:
  std::string source;  // dataset path, for messages
  std::vector<SceneView> views;
  std::vector<int> train;  // indices into views
  std::vector<int> test;
  std::vector<SparsePoint> points;
  AABB aabb;            // of the sparse points (of the cameras when there are none)
  double extent = 0.0;  // 3DGS scene scale from the train cameras
  // Cameras, points, aabb, extent and depth maps are in this frame's internal coordinates
  // (scene_frame.h): world = frame.toWorld(internal). The loaders choose it; a Scene built
  // in memory is in world coordinates (the identity frame) until moveToOwnFrame.
  SceneFrame frame;
  // The colour behind the content, which RGBA images are composited on and which training,
  // evaluation, Fisher scoring and the final fit render against (settleBackground below
  // says where it comes from). Unset: the data has none (opaque images; renders on black).
  std::optional<std::array<float, 3>> background;
  // Training draws a fresh background colour per step (`--background random`); everything
  // else renders against `background`. The images' alpha is then kept (alpha()).
  bool random_background = false;
  // Where the background came from, for `saresgs info` and results.json: "--background",
  // "manifest", "Blender (white)", "alpha in the images, none said (white)", or "none".
  std::string background_from = "none";
  ImageLoadOptions load;

  Scene();
  // The 8-bit RGB image of view i, read on first use and kept. Thread-safe.
  const Image8& image(int i) const;
  // Reads the images of `which` not yet kept, several at once (decoding is single-threaded
  // per image), and returns how many it read; on an unreadable one, throws the error of
  // the first in `which`'s order.
  std::size_t preloadImages(const std::vector<int>& which) const;
  // View i's alpha (1 channel, the image's size), when it has one and the scene keeps it
  // (random_background); else nullptr. Read with the image.
  const Image8* alpha(int i) const;
  // The same as float RGB in [0,1], converted on each call.
  ImageF imageFloat(int i) const { return toFloat(image(i)); }
  bool hasDepth(int i) const { return !views.at(i).depth_path.empty(); }
  // Ground-truth depth of view i (1 channel, z along the camera axis, in the frame's
  // internal units); throws if none.
  ImageF depth(int i) const;
  std::vector<Camera> cameras(const std::vector<int>& which) const;
  // Recomputes aabb and extent from points and the train cameras.
  void finalize();
  // Drops every cached image (memory back).
  void releaseImages() const;
  // Detaches this scene from the image cache it shares with its copies (a fresh, empty
  // one): for a copy whose images are read otherwise (setBackground).
  void resetImageCache();

 private:
  // View i's cache slot, read on first use (one lock for the read and the lookup).
  const CachedImage& cachedImage(int i) const;
  std::shared_ptr<ImageCache> cache_;
};

// Moves a scene in world coordinates (identity frame) into the frame chooseSceneFrame picks
// for its train cameras: cameras, points, aabb, extent (and depth maps as read). Every
// loader below ends with it; a frame that is the identity changes nothing.
void moveToOwnFrame(Scene& scene);

// The one rule for every loader's background. In order: the user's `said` choice (the
// `--background` option); the data's own word (`data_said`: a manifest's colour or null, or
// Blender's white), `data_from` naming it; when neither said anything, white if any image
// has pixels that are not opaque (backgroundWarning then says so), else none. It sets
// background, random_background, background_from and load (the compositing colour and
// whether to keep alpha) before any image is read.
struct BackgroundRule {
  std::optional<BackgroundChoice> said;
  std::string said_by = "--background";  // what said it, for background_from
  bool data_said = false;
  std::optional<std::array<float, 3>> data_color;
  std::string data_from;
};
void settleBackground(Scene& scene, const BackgroundRule& rule);

// Gives a loaded scene another background (Python's Trainer(background=...)): the same as
// the loader's rule with `choice` said, and the images read again on their next use.
void setBackground(Scene& scene, const BackgroundChoice& choice, const std::string& said_by = "--background");

// The warning settleBackground found, if any (the images have alpha and nothing said what
// stands behind them), for `saresgs info`, train and active to print.
std::string backgroundWarning(const Scene& scene);

struct DatasetOptions {
  ImageLoadOptions load;
  // The user's background (`--background`); unset: what the data says (settleBackground).
  std::optional<BackgroundChoice> background;
  int test_every = 8;     // COLMAP: sorted by name, index % test_every == 0 is a test view
                          // (0 puts every view in train)
  std::string model_dir;  // COLMAP: sparse model folder; empty searches sparse/0, sparse, .
};

// Loads a dataset folder: a NeRF-synthetic/Blender folder (transforms_train.json), a
// nerfstudio folder (transforms.json), a
// COLMAP folder (sparse model + images/), or a synthetic scene written by `saresgs scene`
// (a COLMAP folder with depth/). Throws InputError with file and field on bad input.
// The scene comes in its own frame (moveToOwnFrame).
Scene loadDataset(const std::string& path, const DatasetOptions& opts = {});
Scene loadColmapDataset(const std::string& path, const DatasetOptions& opts = {});
Scene loadBlenderDataset(const std::string& path, const DatasetOptions& opts = {});
// nerfstudio's transforms.json: fl_x, fl_y, cx, cy, w, h at the top level or per frame;
// camera_model PINHOLE / SIMPLE_PINHOLE, or OPENCV / SIMPLE_RADIAL / RADIAL with zero
// distortion (anything else is refused by field: saresgs does not undistort); poses in
// OpenGL axes as Blender's; applied_transform checked; ply_file_path gives the points;
// split from train_filenames / test_filenames (or val_filenames), else every
// test_every-th view by name. JPEG or PNG images.
Scene loadNerfstudioDataset(const std::string& path, const DatasetOptions& opts = {});

}  // namespace saresgs
