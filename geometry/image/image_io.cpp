// readImage, writeImage and the other file functions of geometry/image/image.h, on the
// codecs (geometry/image/codecs.h, png_decode.h), which build on image.h's types: a file
// of their own, so that the types do not depend on the codecs that depend on them.
#include <algorithm>
#include <cstdio>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <optional>
#include <stdexcept>

#include "geometry/error.h"
#include "geometry/image/codecs.h"
#include "geometry/image/image.h"
#include "geometry/image/png_decode.h"
#include "geometry/io/atomic_file.h"

namespace saresgs {

namespace {

// The whole file (under 1 GiB); none when it cannot be read.
std::optional<std::vector<std::uint8_t>> fileBytes(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) return std::nullopt;
  std::optional<std::vector<std::uint8_t>> out;
  if (std::fseek(file, 0, SEEK_END) == 0) {
    const long size = std::ftell(file);
    if (size >= 0 && size < (1L << 30) && std::fseek(file, 0, SEEK_SET) == 0) {
      std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size));
      if (std::fread(bytes.data(), 1, bytes.size(), file) == bytes.size()) out = std::move(bytes);
    }
  }
  std::fclose(file);
  return out;
}

}  // namespace

Image8 readImage(const std::string& path, bool keep_alpha) {
  if (!std::filesystem::exists(path)) throw InputError(path, "file", "image does not exist");
  const auto bytes = fileBytes(path);
  if (!bytes) throw InputError(path, "file", "cannot be read (or is 1 GiB or more)");
  const std::span<const std::uint8_t> b(*bytes);
  std::string why;
  if (b.size() >= 8 && std::memcmp(b.data(), kPngSignature, 8) == 0) {
    // Plain 8-bit RGB(A) PNGs, most datasets' images, by the fast path (png_decode.h); the
    // rest, and any file it declines, by libpng.
    if (auto img = decodePlainPng(b, keep_alpha)) return std::move(*img);
    if (auto img = decodePng(b, keep_alpha, &why)) return std::move(*img);
  } else if (b.size() >= 3 && b[0] == 0xff && b[1] == 0xd8 && b[2] == 0xff) {
    // A dataset's images (read with alpha) are taken as stored, as COLMAP takes them;
    // without alpha, as EXIF says to show them (what OpenCV did for both).
    if (auto img = decodeJpeg(b, /*exif_orientation=*/!keep_alpha, &why)) return std::move(*img);
  } else {
    why = "neither PNG nor JPEG";
  }
  throw InputError(path, "file", "not a readable PNG/JPEG image (" + why + ")");
}

bool imageHasAlpha(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) return false;
  std::uint8_t head[8]{};
  const bool png = std::fread(head, 1, 8, file) == 8 && std::memcmp(head, kPngSignature, 8) == 0;
  const bool jpeg = !png && head[0] == 0xff && head[1] == 0xd8;
  bool alpha = false;
  if (png) {
    // Chunk headers only (length, type), skipping their data, until the image data: a few
    // dozen bytes read for any file, however large.
    for (int chunk = 0; chunk < 64; ++chunk) {
      std::uint8_t h[8];
      if (std::fread(h, 1, 8, file) != 8) break;
      const std::uint32_t length =
          (std::uint32_t{h[0]} << 24) | (std::uint32_t{h[1]} << 16) | (std::uint32_t{h[2]} << 8) | h[3];
      const std::string type(reinterpret_cast<const char*>(h + 4), 4);
      if (type == "IHDR") {
        std::uint8_t ihdr[13];
        if (length != 13 || std::fread(ihdr, 1, 13, file) != 13) break;
        const std::uint8_t colour = ihdr[9];
        alpha = colour == 4 || colour == 6;
        if (alpha || std::fseek(file, 4, SEEK_CUR) != 0) break;  // skips the CRC
        continue;
      }
      if (type == "tRNS") alpha = true;
      if (type == "tRNS" || type == "IDAT" || type == "IEND") break;
      if (std::fseek(file, static_cast<long>(length) + 4, SEEK_CUR) != 0) break;
    }
  }
  std::fclose(file);
  if (png || jpeg) return alpha;
  try {
    return readImage(path, /*keep_alpha=*/true).channels == 4;
  } catch (const std::exception&) {
    return false;
  }
}

bool imageHasTransparency(const std::string& path) {
  if (!imageHasAlpha(path)) return false;
  try {
    const Image8 img = readImage(path, /*keep_alpha=*/true);
    if (img.channels != 4) return false;
    for (std::size_t p = 3; p < img.data.size(); p += 4)
      if (img.data[p] != 255) return true;
  } catch (const std::exception&) {
  }
  return false;
}

std::vector<std::uint8_t> encodeImage(const Image8& img, const std::string& ext, int jpeg_quality) {
  std::string e = ext;
  for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (img.channels != 1 && img.channels != 3 && img.channels != 4)
    throw std::invalid_argument("encodeImage: expected 1, 3 or 4 channels");
  if (e == ".png") return encodePng(img);
  if (e == ".jpg" || e == ".jpeg") return encodeJpeg(img, std::clamp(jpeg_quality, 0, 100));
  throw InputError(ext, "extension", "expected .png or .jpg to encode the image");
}

void writeImage(const std::string& path, const Image8& img) {
  const std::string ext = std::filesystem::path(path).extension().string();
  std::vector<std::uint8_t> bytes;
  try {
    bytes = encodeImage(img, ext);
  } catch (const InputError&) {
    throw InputError(path, "extension", "expected .png or .jpg to encode the image");
  }
  writeFileAtomic(path, std::string(bytes.begin(), bytes.end()));
}

}  // namespace saresgs
