#pragma once
// Small image value types. Images live in memory as 8-bit (Image8) and are
// converted to float linear RGB in [0,1] (ImageF) per use; depth maps are float. The file
// functions (readImage, writeImage, ...) are defined in image_io.cpp, on the codecs.
#include <cstdint>
#include <string>
#include <vector>

namespace saresgs {

template <typename T>
struct ImageT {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<T> data;  // row-major, interleaved channels

  ImageT() = default;
  ImageT(int w, int h, int c, T fill = T{})
      : width(w), height(h), channels(c), data(static_cast<size_t>(w) * h * c, fill) {}
  bool empty() const { return data.empty(); }
  size_t index(int x, int y, int ch = 0) const { return (static_cast<size_t>(y) * width + x) * channels + ch; }
  T& at(int x, int y, int ch = 0) { return data[index(x, y, ch)]; }
  const T& at(int x, int y, int ch = 0) const { return data[index(x, y, ch)]; }
};

using Image8 = ImageT<std::uint8_t>;  // 8-bit, 1 (grey), 3 (RGB) or 4 (RGBA) channels
using ImageF = ImageT<float>;         // float, RGB in [0,1] or 1-channel depth

// 8-bit <-> float in [0,1]; values are clamped and rounded on the way back.
ImageF toFloat(const Image8& img);
// The same into `out`, reusing its storage when it is large enough.
void toFloatInto(const Image8& img, ImageF& out);
Image8 toByte(const ImageF& img);

// Reads a PNG/JPEG as RGB or RGBA (alpha kept when `keep_alpha` and present).
// Throws InputError naming the file when it is missing or unreadable.
Image8 readImage(const std::string& path, bool keep_alpha = false);
// Whether the image at `path` carries alpha, from its header when it is a PNG (colour
// type 4 or 6, or a tRNS chunk before the image data) and false for a JPEG; any other file
// is decoded to see. A file that cannot be read says false: reading it later gives the error.
bool imageHasAlpha(const std::string& path);
// Whether the image at `path` has a pixel that is not opaque: imageHasAlpha, then a decode
// of the file to look (many tools write opaque images as RGBA). False for a file that
// cannot be read.
bool imageHasTransparency(const std::string& path);
// Writes PNG/JPEG by extension, to a temporary name first, then renames.
void writeImage(const std::string& path, const Image8& img);
// The image encoded as `ext` (".png" or ".jpg"; JPEG at `jpeg_quality`, 0..100), in memory.
// Throws InputError naming `ext` for any other extension.
std::vector<std::uint8_t> encodeImage(const Image8& img, const std::string& ext, int jpeg_quality = 90);
// Area-averaging resize to an exact size (used for downscaled loading).
Image8 resizeImage(const Image8& img, int width, int height);
// Composites RGBA on a background colour (components in [0,1]) and returns RGB.
Image8 compositeOnBackground(const Image8& rgba, const float background[3]);

}  // namespace saresgs
