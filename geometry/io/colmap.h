#pragma once
// COLMAP sparse models (cameras, images, points3D), text and binary, read and write.
// Layout and semantics follow COLMAP's documented formats; ids are kept as stored.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace saresgs {

inline constexpr std::uint64_t kInvalidPoint3DId = std::numeric_limits<std::uint64_t>::max();

struct ColmapCamera {
  std::uint32_t id = 0;
  std::string model;  // e.g. "PINHOLE"
  std::uint64_t width = 0, height = 0;
  std::vector<double> params;  // model parameters in COLMAP's order
};

struct ColmapImage {
  std::uint32_t id = 0;
  Eigen::Quaterniond q{1, 0, 0, 0};  // world -> camera, (w, x, y, z)
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  std::uint32_t camera_id = 0;
  std::string name;
  std::vector<Eigen::Vector2d> xys;        // 2D points
  std::vector<std::uint64_t> point3d_ids;  // kInvalidPoint3DId where unmatched
};

struct TrackElement {
  std::uint32_t image_id = 0;
  std::uint32_t point2d_idx = 0;
  bool operator==(const TrackElement&) const = default;
};

struct ColmapPoint3D {
  std::uint64_t id = 0;
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  std::array<std::uint8_t, 3> rgb{0, 0, 0};
  double error = 0;
  std::vector<TrackElement> track;
};

struct ColmapModel {
  std::map<std::uint32_t, ColmapCamera> cameras;
  std::map<std::uint32_t, ColmapImage> images;
  std::map<std::uint64_t, ColmapPoint3D> points;
};

// Model id <-> name and the number of parameters, for all of COLMAP's camera models.
// Unknown names/ids give -1.
int colmapModelId(const std::string& name);
std::string colmapModelName(int id);
int colmapModelParamCount(int id);

// Reads cameras.txt/images.txt/points3D.txt (or the .bin files) from `dir`. Every
// model that COLMAP defines is accepted by the readers; converting a distorted one
// to a Camera is refused by cameraFromColmap. Errors name the file and the field.
ColmapModel readColmapText(const std::string& dir);
ColmapModel readColmapBinary(const std::string& dir);
// Picks binary when cameras.bin exists, text when cameras.txt does; errors otherwise.
ColmapModel readColmapModel(const std::string& dir);
void writeColmapText(const std::string& dir, const ColmapModel& model);
void writeColmapBinary(const std::string& dir, const ColmapModel& model);

// Checks that images reference existing cameras, point ids in images reference
// existing points and tracks reference existing images/2D points. Throws InputError.
void validateColmapModel(const ColmapModel& model, const std::string& dir);

}  // namespace saresgs
