#include "geometry/image/codecs.h"

#include <jpeglib.h>
#include <png.h>

#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <memory>

#include "geometry/io/byte_order.h"

namespace saresgs {

namespace {

// Larger images are refused before any allocation of their size (2^28 pixels: 16k x 16k).
constexpr std::uint64_t kMaxPixels = std::uint64_t{1} << 28;

// ---- PNG -----------------------------------------------------------------------------

struct PngInput {
  std::span<const std::uint8_t> file;
  std::size_t at = 0;
};

struct PngState {
  Image8 img;
  std::vector<std::uint8_t> wide;  // 16-bit samples before rounding
  std::vector<png_bytep> rows;
  std::string error;
};

void pngRead(png_structp png, png_bytep out, png_size_t n) {
  auto* in = static_cast<PngInput*>(png_get_io_ptr(png));
  if (n > in->file.size() - in->at) png_error(png, "file ends early");
  std::memcpy(out, in->file.data() + in->at, n);
  in->at += n;
}

void pngError(png_structp png, png_const_charp message) {
  static_cast<PngState*>(png_get_error_ptr(png))->error = message;
  png_longjmp(png, 1);
}
void pngWarning(png_structp, png_const_charp) {}

// The whole decode, under libpng's longjmp: every object it changes lives in `st` (the
// caller's frame), none in this one.
bool pngDecodeInto(PngInput& in, bool keep_alpha, PngState& st) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &st, pngError, pngWarning);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  png_infop end = png_create_info_struct(png);
  if (!info || !end) {
    png_destroy_read_struct(&png, &info, &end);
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, &end);
    return false;
  }
  png_set_read_fn(png, &in, pngRead);
  png_read_info(png, info);
  const png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
  const int colour = png_get_color_type(png, info), depth = png_get_bit_depth(png, info);
  if (static_cast<std::uint64_t>(w) * h > kMaxPixels) png_error(png, "image too large");
  if (colour == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (colour == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (keep_alpha && png_get_valid(png, info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(png);
  if (colour == PNG_COLOR_TYPE_GRAY || colour == PNG_COLOR_TYPE_GRAY_ALPHA) png_set_gray_to_rgb(png);
  if (!keep_alpha) png_set_strip_alpha(png);
  // 16-bit samples as OpenCV gave them: without alpha their high byte, with alpha rounded
  // (v / 257) from native 16-bit samples below.
  if (depth == 16 && !keep_alpha) png_set_strip_16(png);
  if (depth == 16 && keep_alpha) png_set_swap(png);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  const int channels = png_get_channels(png, info);
  const int out_depth = png_get_bit_depth(png, info);
  if ((channels != 3 && channels != 4) || (out_depth != 8 && out_depth != 16)) png_error(png, "unexpected layout");
  st.img = Image8(static_cast<int>(w), static_cast<int>(h), channels);
  const std::size_t row_bytes = png_get_rowbytes(png, info);
  std::uint8_t* base = st.img.data.data();
  if (out_depth == 16) {
    st.wide.resize(row_bytes * h);
    base = st.wide.data();
  }
  st.rows.resize(h);
  for (png_uint_32 y = 0; y < h; ++y) st.rows[y] = base + y * row_bytes;
  png_read_image(png, st.rows.data());
  png_read_end(png, end);
  png_destroy_read_struct(&png, &info, &end);
  if (out_depth == 16) {
    // round(v / 257): v = 257 k + r rounds up from r = 129 on.
    const auto* v = reinterpret_cast<const std::uint16_t*>(st.wide.data());
    for (std::size_t i = 0; i < st.img.data.size(); ++i) st.img.data[i] = static_cast<std::uint8_t>((v[i] + 128) / 257);
  }
  return true;
}

void pngWrite(png_structp png, png_bytep data, png_size_t n) {
  auto* out = static_cast<std::vector<std::uint8_t>*>(png_get_io_ptr(png));
  out->insert(out->end(), data, data + n);
}
void pngFlush(png_structp) {}

struct PngWriteState {
  std::vector<std::uint8_t> bytes;
  std::vector<png_bytep> rows;
  std::string error;
};

bool pngEncodeInto(const Image8& img, PngWriteState& st) {
  png_structp png = png_create_write_struct(
      PNG_LIBPNG_VER_STRING, &st,
      [](png_structp p, png_const_charp m) {
        static_cast<PngWriteState*>(png_get_error_ptr(p))->error = m;
        png_longjmp(p, 1);
      },
      pngWarning);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_set_write_fn(png, &st.bytes, pngWrite, pngFlush);
  const int colour = img.channels == 1   ? PNG_COLOR_TYPE_GRAY
                     : img.channels == 3 ? PNG_COLOR_TYPE_RGB
                                         : PNG_COLOR_TYPE_RGB_ALPHA;
  png_set_IHDR(png, info, static_cast<png_uint_32>(img.width), static_cast<png_uint_32>(img.height), 8, colour,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_BASE, PNG_FILTER_TYPE_BASE);
  // Speed over size, as OpenCV wrote them: the Sub filter, zlib level 1, run-length matching.
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_set_compression_level(png, 1);
  png_set_compression_mem_level(png, 9);
  png_set_compression_strategy(png, 3);  // Z_RLE
  png_write_info(png, info);
  st.rows.resize(static_cast<std::size_t>(img.height));
  for (int y = 0; y < img.height; ++y)
    st.rows[static_cast<std::size_t>(y)] = const_cast<png_bytep>(&img.data[img.index(0, y)]);
  png_write_image(png, st.rows.data());
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return true;
}

// ---- JPEG ----------------------------------------------------------------------------

struct JpegError {
  jpeg_error_mgr mgr;
  std::jmp_buf jump;
  std::string* message;
};

void jpegErrorExit(j_common_ptr c) {
  auto* e = reinterpret_cast<JpegError*>(c->err);
  char text[JMSG_LENGTH_MAX];
  (*c->err->format_message)(c, text);
  *e->message = text;
  std::longjmp(e->jump, 1);
}
void jpegSilence(j_common_ptr, int) {}

// libjpeg's errors as a longjmp to err.jump, the message kept in *message; no warnings.
jpeg_error_mgr* jpegErrors(JpegError& err, std::string* message) {
  jpeg_std_error(&err.mgr);
  err.mgr.error_exit = jpegErrorExit;
  err.mgr.emit_message = jpegSilence;
  err.message = message;
  return &err.mgr;
}

struct JpegState {
  Image8 img;
  std::string error;
  int orientation = 1;
};

// The Orientation tag of an APP1 Exif block (a TIFF file after "Exif\0\0"); 1 if none.
int exifOrientation(const std::uint8_t* p, std::size_t n) {
  if (n < 14 || std::memcmp(p, "Exif\0\0", 6) != 0) return 1;
  p += 6, n -= 6;
  const bool le = p[0] == 'I' && p[1] == 'I';
  if (!le && !(p[0] == 'M' && p[1] == 'M')) return 1;
  const std::endian order = le ? std::endian::little : std::endian::big;
  const char* b = reinterpret_cast<const char*>(p);
  auto u16 = [&](std::size_t at) -> unsigned { return byte_order::load<std::uint16_t>(b + at, order); };
  auto u32 = [&](std::size_t at) { return byte_order::load<std::uint32_t>(b + at, order); };
  const std::uint32_t ifd = u32(4);
  if (ifd > n || n - ifd < 2) return 1;
  const unsigned entries = u16(ifd);
  for (unsigned k = 0; k < entries; ++k) {
    const std::size_t e = ifd + 2 + 12 * std::size_t{k};
    if (e + 12 > n) break;
    if (u16(e) == 0x0112 && u16(e + 2) == 3) {
      const unsigned v = u16(e + 8);
      return v >= 1 && v <= 8 ? static_cast<int>(v) : 1;
    }
  }
  return 1;
}

// The decode (or with `header_only` the header and its EXIF orientation alone), under
// libjpeg's longjmp: every object it changes lives in `st`.
bool jpegDecodeInto(std::span<const std::uint8_t> file, JpegState& st, bool header_only = false) {
  jpeg_decompress_struct c;
  JpegError err;
  c.err = jpegErrors(err, &st.error);
  if (setjmp(err.jump)) {
    jpeg_destroy_decompress(&c);
    return false;
  }
  jpeg_create_decompress(&c);
  jpeg_mem_src(&c, file.data(), static_cast<unsigned long>(file.size()));
  jpeg_save_markers(&c, JPEG_APP0 + 1, 0xffff);
  jpeg_read_header(&c, TRUE);
  for (jpeg_saved_marker_ptr m = c.marker_list; m; m = m->next)
    if (m->marker == JPEG_APP0 + 1) st.orientation = exifOrientation(m->data, m->data_length);
  if (header_only) {
    jpeg_destroy_decompress(&c);
    return true;
  }
  if (c.jpeg_color_space == JCS_CMYK || c.jpeg_color_space == JCS_YCCK) {
    st.error = "a CMYK JPEG (convert it to RGB)";
    jpeg_destroy_decompress(&c);
    return false;
  }
  if (static_cast<std::uint64_t>(c.image_width) * c.image_height > kMaxPixels) {
    st.error = "image too large";
    jpeg_destroy_decompress(&c);
    return false;
  }
  c.out_color_space = JCS_RGB;
  jpeg_start_decompress(&c);
  st.img = Image8(static_cast<int>(c.output_width), static_cast<int>(c.output_height), 3);
  while (c.output_scanline < c.output_height) {
    JSAMPROW row = &st.img.data[st.img.index(0, static_cast<int>(c.output_scanline))];
    jpeg_read_scanlines(&c, &row, 1);
  }
  jpeg_finish_decompress(&c);
  jpeg_destroy_decompress(&c);
  return true;
}

// The image turned as EXIF orientation o says (OpenCV's order: transpose, then flip).
Image8 orient(const Image8& in, int o) {
  if (o <= 1 || o > 8) return in;
  const bool transpose = o >= 5;
  const int w = transpose ? in.height : in.width, h = transpose ? in.width : in.height;
  // After the transpose: 2, 7 mirror left-right... as the tag defines each case.
  const bool flip_x = o == 2 || o == 3 || o == 6 || o == 7;
  const bool flip_y = o == 3 || o == 4 || o == 7 || o == 8;
  Image8 out(w, h, in.channels);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int sx0 = flip_x ? w - 1 - x : x, sy0 = flip_y ? h - 1 - y : y;
      const int sx = transpose ? sy0 : sx0, sy = transpose ? sx0 : sy0;
      std::memcpy(&out.data[out.index(x, y)], &in.data[in.index(sx, sy)], static_cast<std::size_t>(in.channels));
    }
  return out;
}

struct JpegWriteState {
  unsigned char* buffer = nullptr;
  unsigned long size = 0;
  std::vector<std::uint8_t> rgb;  // a 4-channel image without its alpha
  std::string error;
};

bool jpegEncodeInto(const Image8& img, int quality, JpegWriteState& st) {
  jpeg_compress_struct c;
  JpegError err;
  c.err = jpegErrors(err, &st.error);
  if (setjmp(err.jump)) {
    jpeg_destroy_compress(&c);
    return false;
  }
  jpeg_create_compress(&c);
  jpeg_mem_dest(&c, &st.buffer, &st.size);
  c.image_width = static_cast<JDIMENSION>(img.width);
  c.image_height = static_cast<JDIMENSION>(img.height);
  c.input_components = img.channels == 1 ? 1 : 3;
  c.in_color_space = img.channels == 1 ? JCS_GRAYSCALE : JCS_RGB;
  jpeg_set_defaults(&c);
  jpeg_set_quality(&c, quality, TRUE);
  jpeg_start_compress(&c, TRUE);
  const std::uint8_t* src = img.data.data();
  std::size_t stride = static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.channels);
  if (img.channels == 4) {
    st.rgb.resize(static_cast<std::size_t>(img.width) * img.height * 3);
    for (std::size_t p = 0, n = static_cast<std::size_t>(img.width) * img.height; p < n; ++p)
      std::memcpy(&st.rgb[3 * p], &img.data[4 * p], 3);
    src = st.rgb.data();
    stride = static_cast<std::size_t>(img.width) * 3;
  }
  while (c.next_scanline < c.image_height) {
    JSAMPROW row = const_cast<JSAMPROW>(src + c.next_scanline * stride);
    jpeg_write_scanlines(&c, &row, 1);
  }
  jpeg_finish_compress(&c);
  jpeg_destroy_compress(&c);
  return true;
}

}  // namespace

std::optional<Image8> decodePng(std::span<const std::uint8_t> file, bool keep_alpha, std::string* error) {
  PngInput in{file};
  PngState st;
  if (!pngDecodeInto(in, keep_alpha, st)) {
    if (error) *error = st.error.empty() ? "not a PNG libpng can read" : st.error;
    return std::nullopt;
  }
  return std::move(st.img);
}

std::optional<Image8> decodeJpeg(std::span<const std::uint8_t> file, bool exif_orientation, std::string* error) {
  JpegState st;
  if (!jpegDecodeInto(file, st)) {
    if (error) *error = st.error;
    return std::nullopt;
  }
  if (exif_orientation && st.orientation != 1) return orient(st.img, st.orientation);
  return std::move(st.img);
}

int jpegExifOrientation(std::span<const std::uint8_t> file) {
  JpegState st;
  return jpegDecodeInto(file, st, /*header_only=*/true) ? st.orientation : 1;
}

std::vector<std::uint8_t> encodePng(const Image8& img) {
  PngWriteState st;
  if (!pngEncodeInto(img, st)) throw std::runtime_error("PNG encoding failed: " + st.error);
  return std::move(st.bytes);
}

std::vector<std::uint8_t> encodeJpeg(const Image8& img, int quality) {
  JpegWriteState st;
  const bool ok = jpegEncodeInto(img, quality, st);
  std::vector<std::uint8_t> out;
  if (ok) out.assign(st.buffer, st.buffer + st.size);
  std::free(st.buffer);
  if (!ok) throw std::runtime_error("JPEG encoding failed: " + st.error);
  return out;
}

}  // namespace saresgs
