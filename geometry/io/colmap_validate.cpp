// Per-record checks shared by the readers, cross-reference checks of a whole model,
// and readColmapModel, which picks the format and runs both.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <sstream>
#include <utility>

#include "geometry/camera/camera.h"
#include "geometry/error.h"
#include "geometry/io/colmap.h"
#include "geometry/io/colmap_detail.h"

namespace saresgs {

namespace colmap_detail {

namespace {

[[noreturn]] void fail(const std::string& file, const std::string& where, const std::string& field,
                       const std::string& what) {
  throw InputError(file, where + ": " + field, what);
}

std::string str(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

}  // namespace

void checkCamera(const ColmapCamera& cam, const std::string& file, const std::string& where) {
  const int id = colmapModelId(cam.model);
  if (id < 0)
    fail(file, where, "model",
         "expected a COLMAP camera model (SIMPLE_PINHOLE, PINHOLE, ...), got '" + cam.model + "'");
  const auto count = static_cast<size_t>(colmapModelParamCount(id));
  if (cam.params.size() != count)
    fail(file, where, "params",
         "expected " + std::to_string(count) + " parameters for " + cam.model + ", got " +
             std::to_string(cam.params.size()));
  for (size_t i = 0; i < count; ++i)
    if (!std::isfinite(cam.params[i]))
      fail(file, where, "params",
           "expected finite parameters, parameter " + std::to_string(i) + " is " + str(cam.params[i]));
  for (int i = 0; i < focalLengthCount(id); ++i)
    if (!(cam.params[static_cast<size_t>(i)] > 0))
      fail(file, where, "focal length",
           "expected a positive focal length, got " + str(cam.params[static_cast<size_t>(i)]));
  // Checked as read (64-bit), before anything narrows them to int.
  for (const auto& [name, v] : {std::pair<const char*, std::uint64_t>{"width", cam.width}, {"height", cam.height}})
    if (v == 0 || v > static_cast<std::uint64_t>(kMaxImageSide))
      fail(file, where, name,
           "expected an image " + std::string(name) + " in 1.." + std::to_string(kMaxImageSide) + ", got " +
               std::to_string(v));
}

void checkPose(const Eigen::Quaterniond& q, const Eigen::Vector3d& t, const std::string& file,
               const std::string& where) {
  if (!q.coeffs().allFinite()) fail(file, where, "quaternion", "expected finite QW QX QY QZ, got NaN or Inf");
  if (!t.allFinite()) fail(file, where, "translation", "expected finite TX TY TZ, got NaN or Inf");
  // COLMAP writes normalised quaternions; a clearly non-unit one means a corrupt or
  // mis-ordered file, and silently normalising it would hide that.
  const double norm = q.norm();
  if (std::abs(norm - 1.0) > 1e-3)
    fail(file, where, "quaternion", "expected a unit quaternion (|norm - 1| <= 1e-3), got norm " + str(norm));
}

void checkImagePoints(const ColmapImage& img, const std::string& file, const std::string& where) {
  if (img.xys.size() != img.point3d_ids.size())
    fail(file, where, "points2D",
         "expected one point3D id per 2D point, got " + std::to_string(img.xys.size()) + " points and " +
             std::to_string(img.point3d_ids.size()) + " ids");
  for (size_t i = 0; i < img.xys.size(); ++i)
    if (!img.xys[i].allFinite())
      fail(file, where, "points2D", "expected finite X Y, 2D point " + std::to_string(i) + " has NaN or Inf");
}

void checkPoint(const ColmapPoint3D& pt, const std::string& file, const std::string& where) {
  if (!pt.xyz.allFinite()) fail(file, where, "xyz", "expected finite X Y Z, got NaN or Inf");
  if (!std::isfinite(pt.error)) fail(file, where, "error", "expected a finite error, got " + str(pt.error));
}

}  // namespace colmap_detail

namespace {

using colmap_detail::fail;

// The ids are the map keys as well; a model built in code could disagree.
template <typename Map>
void checkKeys(const Map& map, const std::string& dir, const char* kind, const char* field) {
  for (const auto& [key, value] : map)
    if (value.id != key)
      fail(dir, std::string(kind) + " " + std::to_string(key), field,
           "expected the id to equal its map key, got " + std::to_string(value.id));
}

void checkImageReferences(const ColmapModel& model, const ColmapImage& img, const std::string& dir) {
  const std::string where = "image " + std::to_string(img.id);
  if (!model.cameras.count(img.camera_id))
    fail(dir, where, "camera_id",
         "expected an existing camera, camera " + std::to_string(img.camera_id) + " is not in cameras");
  for (size_t i = 0; i < img.point3d_ids.size(); ++i) {
    const std::uint64_t pid = img.point3d_ids[i];
    if (pid != kInvalidPoint3DId && !model.points.count(pid))
      fail(dir, where, "point3D_id",
           "expected an existing point, 2D point " + std::to_string(i) + " references point " + std::to_string(pid) +
               ", which is not in points3D");
  }
}

void checkTrack(const ColmapModel& model, const ColmapPoint3D& pt, const std::string& dir) {
  const std::string where = "point " + std::to_string(pt.id);
  for (size_t k = 0; k < pt.track.size(); ++k) {
    const TrackElement& e = pt.track[k];
    const auto it = model.images.find(e.image_id);
    if (it == model.images.end())
      fail(dir, where, "track",
           "expected existing images, element " + std::to_string(k) + " references image " +
               std::to_string(e.image_id) + ", which is not in images");
    if (e.point2d_idx >= it->second.xys.size())
      fail(dir, where, "track",
           "expected a 2D point index below " + std::to_string(it->second.xys.size()) + " (the 2D points of image " +
               std::to_string(e.image_id) + "), element " + std::to_string(k) + " has " +
               std::to_string(e.point2d_idx));
  }
}

}  // namespace

void validateColmapModel(const ColmapModel& model, const std::string& dir) {
  checkKeys(model.cameras, dir, "camera", "camera_id");
  checkKeys(model.images, dir, "image", "image_id");
  checkKeys(model.points, dir, "point", "point3D_id");
  for (const auto& [id, cam] : model.cameras) colmap_detail::checkCamera(cam, dir, "camera " + std::to_string(id));
  for (const auto& [id, img] : model.images) {
    const std::string where = "image " + std::to_string(id);
    colmap_detail::checkPose(img.q, img.t, dir, where);
    colmap_detail::checkImagePoints(img, dir, where);
    checkImageReferences(model, img, dir);
  }
  for (const auto& [id, pt] : model.points) {
    // images.bin stores point3D ids as int64 with -1 for "none", so larger ids
    // cannot be referenced from an image.
    if (id > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
      fail(dir, "point " + std::to_string(id), "point3D_id", "expected an id below 2^63");
    colmap_detail::checkPoint(pt, dir, "point " + std::to_string(id));
    checkTrack(model, pt, dir);
  }
}

ColmapModel readColmapModel(const std::string& dir) {
  namespace fs = std::filesystem;
  ColmapModel model;
  if (fs::exists(fs::path(dir) / "cameras.bin"))
    model = readColmapBinary(dir);
  else if (fs::exists(fs::path(dir) / "cameras.txt"))
    model = readColmapText(dir);
  else
    throw InputError(dir, "model",
                     "expected cameras.bin/images.bin/points3D.bin or "
                     "cameras.txt/images.txt/points3D.txt");
  validateColmapModel(model, dir);
  return model;
}

}  // namespace saresgs
