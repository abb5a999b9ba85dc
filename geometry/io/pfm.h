#pragma once
// Portable Float Map (PFM) for depth maps: "Pf" (1 channel) or "PF" (3 channels),
// little-endian (negative scale), rows stored bottom to top as the format requires.
#include <string>

#include "geometry/image/image.h"

namespace saresgs {

ImageF readPfm(const std::string& path);
void writePfm(const std::string& path, const ImageF& img);  // atomic (temp + rename)

}  // namespace saresgs
