// COLMAP's camera model table: id, name, parameter count (from COLMAP's documentation).
#include <array>
#include <string_view>

#include "geometry/io/colmap.h"
#include "geometry/io/colmap_detail.h"

namespace saresgs {

namespace {

struct ModelInfo {
  std::string_view name;
  int param_count;
  int focal_count;  // leading focal-length parameters: f, or fx and fy
};

// Indexed by COLMAP's model id.
constexpr std::array<ModelInfo, 11> kModels{{
    {"SIMPLE_PINHOLE", 3, 1},         // f, cx, cy
    {"PINHOLE", 4, 2},                // fx, fy, cx, cy
    {"SIMPLE_RADIAL", 4, 1},          // f, cx, cy, k
    {"RADIAL", 5, 1},                 // f, cx, cy, k1, k2
    {"OPENCV", 8, 2},                 // fx, fy, cx, cy, k1, k2, p1, p2
    {"OPENCV_FISHEYE", 8, 2},         // fx, fy, cx, cy, k1, k2, k3, k4
    {"FULL_OPENCV", 12, 2},           // fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6
    {"FOV", 5, 2},                    // fx, fy, cx, cy, omega
    {"SIMPLE_RADIAL_FISHEYE", 4, 1},  // f, cx, cy, k
    {"RADIAL_FISHEYE", 5, 1},         // f, cx, cy, k1, k2
    {"THIN_PRISM_FISHEYE", 12, 2},    // fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, sx1, sy1
}};

const ModelInfo* find(int id) {
  return id >= 0 && id < static_cast<int>(kModels.size()) ? &kModels[static_cast<size_t>(id)] : nullptr;
}

}  // namespace

int colmapModelId(const std::string& name) {
  for (size_t i = 0; i < kModels.size(); ++i)
    if (kModels[i].name == name) return static_cast<int>(i);
  return -1;
}

std::string colmapModelName(int id) {
  const ModelInfo* m = find(id);
  return m ? std::string(m->name) : std::string();
}

int colmapModelParamCount(int id) {
  const ModelInfo* m = find(id);
  return m ? m->param_count : -1;
}

int colmap_detail::focalLengthCount(int id) {
  const ModelInfo* m = find(id);
  return m ? m->focal_count : -1;
}

}  // namespace saresgs
