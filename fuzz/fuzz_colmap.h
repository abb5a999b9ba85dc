#pragma once
// What the two COLMAP model targets (fuzz_colmap_text.cpp, fuzz_colmap_binary.cpp) do
// alike: they differ only in the file names and the reader.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz/fuzz_support.h"
#include "geometry/io/colmap.h"
#include "geometry/scene/colmap_convert.h"

namespace saresgs::fuzz {

// One input of a COLMAP model target: its parts written to dir/names (cameras, images,
// points3D, in that order), read with `read`, cross-checked and converted to saresgs
// cameras as loadColmapDataset does.
inline void checkColmapModel(const std::string& dir, const std::vector<std::string>& names,
                             ColmapModel (*read)(const std::string& dir), const std::uint8_t* data, std::size_t size) {
  writeParts(dir, names, splitFiles(data, size));
  check([&] {
    const ColmapModel model = read(dir);
    validateColmapModel(model, dir);
    for (const auto& [id, cam] : model.cameras) (void)intrinsicsFromColmap(cam, dir + "/" + names[0]);
  });
}

}  // namespace saresgs::fuzz
