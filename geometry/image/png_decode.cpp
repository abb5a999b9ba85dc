// The plain-PNG fast path (png_decode.h). Facts used, from the PNG specification: a file
// is an 8-byte signature and chunks (4-byte big-endian length, 4-byte type, data, CRC-32
// of type and data); IHDR holds width, height, bit depth, colour type (2 RGB, 6 RGBA),
// compression, filter and interlace methods; the IDAT data, concatenated, is one zlib
// stream of the rows, each prefixed by its filter type, which predicts every byte from
// the byte one pixel to the left (a), the byte above (b) and the one above-left (c):
// 0 none, 1 a, 2 b, 3 floor((a + b) / 2), 4 Paeth (of a, b, c, the one closest to
// a + b - c, ties to a, then b), added modulo 256; bytes outside the image count as 0.
#include "geometry/image/png_decode.h"

#include <libdeflate.h>

#include <cstdlib>
#include <cstring>
#include <memory>
#include <vector>

namespace saresgs {

namespace {

std::uint32_t be32(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | p[3];
}

bool isType(const std::uint8_t* p, const char* t) { return std::memcmp(p, t, 4) == 0; }

struct DecompressorFree {
  void operator()(libdeflate_decompressor* d) const { libdeflate_free_decompressor(d); }
};

// Undoes row `y`'s filter in place; `prev` is the row above, already unfiltered (null for
// the first row). Returns false for a filter type PNG does not define.
template <int kBpp>
bool unfilterRow(int type, std::uint8_t* row, const std::uint8_t* prev, std::size_t n) {
  switch (type) {
    case 0:
      return true;
    case 1:
      for (std::size_t i = kBpp; i < n; ++i) row[i] = static_cast<std::uint8_t>(row[i] + row[i - kBpp]);
      return true;
    case 2:
      if (prev)
        for (std::size_t i = 0; i < n; ++i) row[i] = static_cast<std::uint8_t>(row[i] + prev[i]);
      return true;
    case 3:
      for (std::size_t i = 0; i < n; ++i) {
        const int a = i >= kBpp ? row[i - kBpp] : 0, b = prev ? prev[i] : 0;
        row[i] = static_cast<std::uint8_t>(row[i] + ((a + b) >> 1));
      }
      return true;
    case 4:
      for (std::size_t i = 0; i < n; ++i) {
        const int a = i >= kBpp ? row[i - kBpp] : 0, b = prev ? prev[i] : 0;
        const int c = prev && i >= kBpp ? prev[i - kBpp] : 0;
        const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
        const int pred = (pa <= pb && pa <= pc) ? a : (pb <= pc ? b : c);
        row[i] = static_cast<std::uint8_t>(row[i] + pred);
      }
      return true;
    default:
      return false;
  }
}

}  // namespace

std::optional<Image8> decodePlainPng(std::span<const std::uint8_t> file, bool keep_alpha) {
  if (file.size() < 8 + 25 || std::memcmp(file.data(), kPngSignature, 8) != 0) return std::nullopt;
  const std::uint8_t* const f = file.data();
  const std::size_t size = file.size();

  std::uint32_t width = 0, height = 0;
  int bpp = 0;
  // The IDAT chunks' data, in file order; `idat_closed` once another chunk follows them.
  std::vector<std::pair<std::size_t, std::size_t>> idat;
  bool idat_closed = false, ended = false;
  for (std::size_t p = 8; !ended;) {
    if (size - p < 12) return std::nullopt;  // no room for a chunk: no IEND
    const std::uint32_t len = be32(f + p);
    if (len > size - p - 12) return std::nullopt;
    const std::uint8_t* type = f + p + 4;
    const std::uint8_t* data = f + p + 8;
    if (libdeflate_crc32(0, type, len + std::size_t{4}) != be32(data + len)) return std::nullopt;
    const bool first = p == 8;
    if (first != isType(type, "IHDR")) return std::nullopt;
    if (first) {
      if (len != 13) return std::nullopt;
      width = be32(data);
      height = be32(data + 4);
      const int depth = data[8], colour = data[9];
      if (width == 0 || height == 0 || width > 0x7fffffffu || height > 0x7fffffffu) return std::nullopt;
      if (std::uint64_t{width} * height > kPlainPngMaxPixels) return std::nullopt;
      if (depth != 8 || (colour != 2 && colour != 6) || data[10] != 0 || data[11] != 0 || data[12] != 0)
        return std::nullopt;
      bpp = colour == 6 ? 4 : 3;
    } else if (isType(type, "IDAT")) {
      if (idat_closed) return std::nullopt;
      idat.emplace_back(p + 8, len);
    } else if (isType(type, "IEND")) {
      if (len != 0) return std::nullopt;
      ended = true;
    } else {
      // Critical chunks other than these (PLTE among them), and transparency, are
      // OpenCV's to interpret.
      if (!(type[0] & 0x20) || isType(type, "tRNS")) return std::nullopt;
      if (!idat.empty()) idat_closed = true;
    }
    p += std::size_t{12} + len;
  }
  if (idat.empty()) return std::nullopt;

  // One zlib stream over the IDAT data, inflated into a kept per-thread buffer.
  thread_local std::unique_ptr<libdeflate_decompressor, DecompressorFree> inflater;
  thread_local std::vector<std::uint8_t> joined, raw;
  if (!inflater) inflater.reset(libdeflate_alloc_decompressor());
  if (!inflater) return std::nullopt;
  // A kept buffer that grew past 32 MiB for one large image is released on the way out,
  // whichever way that is.
  struct Trim {
    ~Trim() {
      for (std::vector<std::uint8_t>* v : {&joined, &raw})
        if (v->capacity() > (std::size_t{1} << 25)) std::vector<std::uint8_t>().swap(*v);
    }
  } trim;
  const std::uint8_t* in = f + idat[0].first;
  std::size_t in_size = idat[0].second;
  if (idat.size() > 1) {
    joined.clear();
    for (const auto& [at, n] : idat) joined.insert(joined.end(), f + at, f + at + n);
    in = joined.data();
    in_size = joined.size();
  }
  const std::size_t row_bytes = std::size_t{width} * bpp, stride = row_bytes + 1;
  const std::size_t raw_size = stride * height;
  // Deflate expands at most 1032-fold (258 bytes from a 2-bit code, past a block's
  // overhead): a header that claims more than its stream can hold is declined before the
  // buffer is sized for it.
  if (raw_size / 1032 > in_size) return std::nullopt;
  raw.resize(raw_size);
  std::size_t used = 0, got = 0;
  if (libdeflate_zlib_decompress_ex(inflater.get(), in, in_size, raw.data(), raw_size, &used, &got) !=
          LIBDEFLATE_SUCCESS ||
      used != in_size || got != raw_size)
    return std::nullopt;

  const int channels = bpp == 4 && keep_alpha ? 4 : 3;
  Image8 out(static_cast<int>(width), static_cast<int>(height), channels);
  for (std::size_t y = 0; y < height; ++y) {
    std::uint8_t* row = &raw[y * stride + 1];
    const std::uint8_t* prev = y ? row - stride : nullptr;
    const int type = row[-1];
    if (!(bpp == 3 ? unfilterRow<3>(type, row, prev, row_bytes) : unfilterRow<4>(type, row, prev, row_bytes)))
      return std::nullopt;
    std::uint8_t* dst = &out.data[y * width * channels];
    if (channels == bpp) {
      std::memcpy(dst, row, row_bytes);
    } else {
      for (std::size_t x = 0; x < width; ++x) std::memcpy(dst + 3 * x, row + 4 * x, 3);
    }
  }
  return out;
}

}  // namespace saresgs
