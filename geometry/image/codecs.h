#pragma once
// PNG and JPEG decoding and encoding with libpng and libjpeg-turbo directly (Debian's, the
// libraries OpenCV's image codecs wrap), so that no program of ours loads
// libopencv_imgcodecs and the ~120 libraries it brings (GDAL, OpenEXR, ...): a process
// starts in a fraction of the time. The pixels are the ones OpenCV gave for the same
// files (the tests compare them with OpenCV's reading).
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "geometry/image/image.h"

namespace saresgs {

// Any PNG: 1-16 bits, grey, grey + alpha, palette, RGB(A), tRNS, interlaced. RGB, or RGBA
// when `keep_alpha` and the file has alpha (or tRNS); 16-bit samples become 8-bit as they
// did through OpenCV: rounded (v / 257) with `keep_alpha`, their high byte without. Nothing (and `error` says why) when libpng refuses the file.
std::optional<Image8> decodePng(std::span<const std::uint8_t> file, bool keep_alpha, std::string* error = nullptr);

// A baseline or progressive JPEG (grey, YCbCr, RGB) as RGB, decoded as libjpeg-turbo does
// by default. `exif_orientation`: turn the image as its EXIF Orientation tag says (what
// OpenCV did for readImage without alpha; datasets are read as stored, as COLMAP reads
// them). Nothing when libjpeg refuses the file (or it is CMYK, which it cannot turn into RGB).
std::optional<Image8> decodeJpeg(std::span<const std::uint8_t> file, bool exif_orientation,
                                 std::string* error = nullptr);

// The EXIF Orientation (1-8) of a JPEG file; 1 when it has none.
int jpegExifOrientation(std::span<const std::uint8_t> file);

// PNG of a 1-, 3- or 4-channel 8-bit image (zlib level 1, as OpenCV wrote it).
std::vector<std::uint8_t> encodePng(const Image8& img);
// Baseline JPEG of a 1- or 3-channel image (an alpha channel is dropped), quality 0-100.
std::vector<std::uint8_t> encodeJpeg(const Image8& img, int quality);

}  // namespace saresgs
