#pragma once
// A fast path for the PNG files that datasets hold: 8-bit RGB or RGBA, not interlaced.
// OpenCV reads them through libpng and zlib; this reads them with libdeflate's inflate
// (about twice zlib's speed) and undoes PNG's row filters itself, straight into RGB(A).
#include <cstdint>
#include <optional>
#include <span>

#include "geometry/image/image.h"

namespace saresgs {

// The 8 bytes every PNG file starts with.
inline constexpr std::uint8_t kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

// The most pixels the fast path decodes; larger files go to OpenCV, as before.
inline constexpr std::uint64_t kPlainPngMaxPixels = std::uint64_t{1} << 26;

// Decodes `file` (a whole PNG file) when it is a plain PNG: the signature, IHDR first
// (8-bit RGB or RGBA, compression, filter method 0, no interlacing), consecutive IDAT
// chunks, IEND, and otherwise only ancillary chunks other than tRNS; every chunk's CRC
// right; one zlib stream that fills the image exactly and ends with the last IDAT; row
// filters 0-4; at most kPlainPngMaxPixels. The image is what readImage gives for the file
// (RGB, or RGBA when `keep_alpha` and the file has alpha). Anything else, damage
// included, returns nothing: readImage then hands the file to OpenCV, whose verdict and
// errors are unchanged.
std::optional<Image8> decodePlainPng(std::span<const std::uint8_t> file, bool keep_alpha);

}  // namespace saresgs
