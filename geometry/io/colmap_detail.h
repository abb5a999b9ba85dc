#pragma once
// Internal to the COLMAP readers/writers: the model table's focal-length count and
// the per-record checks that the text reader, the binary reader and
// validateColmapModel share, so that all three accept and refuse the same records.
// `where` names the record ("line 7", "image 3"); errors read "<where>: <field>".
#include <filesystem>
#include <string>

#include "geometry/io/colmap.h"

namespace saresgs::colmap_detail {

// dir/name, the path of one of a model's files.
inline std::string pathIn(const std::string& dir, const char* name) {
  return (std::filesystem::path(dir) / name).string();
}

// 1 for models with a single focal length f (SIMPLE_*, RADIAL*), 2 for fx, fy; -1 if unknown.
int focalLengthCount(int model_id);

// Known model, parameter count of that model, finite parameters, positive focal
// length(s) and positive width/height.
void checkCamera(const ColmapCamera& cam, const std::string& file, const std::string& where);
// Finite pose and a unit quaternion (|norm - 1| <= 1e-3; a zero quaternion fails).
void checkPose(const Eigen::Quaterniond& q, const Eigen::Vector3d& t, const std::string& file,
               const std::string& where);
// Finite 2D points, one point3D id per 2D point.
void checkImagePoints(const ColmapImage& img, const std::string& file, const std::string& where);
// Finite position and error.
void checkPoint(const ColmapPoint3D& pt, const std::string& file, const std::string& where);

}  // namespace saresgs::colmap_detail
