// Portable Float Map read/write.
#include "geometry/io/pfm.h"

#include <bit>
#include <charconv>
#include <cmath>
#include <limits>
#include <optional>
#include <string_view>
#include <system_error>

#include "geometry/error.h"
#include "geometry/io/atomic_file.h"
#include "geometry/io/byte_order.h"

namespace saresgs {

namespace {

bool isPfmSpace(char c) { return c == ' ' || c == '\n' || c == '\r' || c == '\t'; }

// The header after the magic: "<ws>width<ws>height<ws>scale<one ws>", then data.
class HeaderReader {
 public:
  HeaderReader(const std::string& path, const std::string& data) : path_(path), data_(data) {}

  void readMagic(int& channels) {
    const std::string_view magic = std::string_view(data_).substr(0, 2);
    if (magic == "PF")
      channels = 3;
    else if (magic == "Pf")
      channels = 1;
    else
      throw InputError(path_, "header: magic", "expected 'PF' (3 channels) or 'Pf' (1 channel)");
    pos_ = 2;
  }

  // A positive size (width or height).
  int readSize(const char* field) {
    const std::string_view tok = token(field);
    int v = 0;
    const auto [p, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
    if (ec != std::errc() || p != tok.data() + tok.size() || v <= 0)
      fail(field, "expected a positive integer, got '" + std::string(tok) + "'");
    return v;
  }

  // The scale; its sign gives the byte order of the data.
  double readScale() {
    const std::string_view tok = token("header: scale");
    double v = 0;
    const auto [p, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
    if (ec != std::errc() || p != tok.data() + tok.size() || !std::isfinite(v) || v == 0)
      fail("header: scale", "expected a non-zero number (negative: little-endian), got '" + std::string(tok) + "'");
    // Exactly one whitespace character ends the header: the data may start with a
    // byte that looks like whitespace.
    if (pos_ >= data_.size() || !isPfmSpace(data_[pos_]))
      fail("header: scale", "expected one whitespace character after the scale");
    ++pos_;
    return v;
  }

  size_t position() const { return pos_; }

  [[noreturn]] void fail(const char* field, const std::string& what) const { throw InputError(path_, field, what); }

 private:
  // Whitespace (at least one character), then a token of at most 32 characters.
  std::string_view token(const char* field) {
    const size_t start = pos_;
    while (pos_ < data_.size() && isPfmSpace(data_[pos_])) ++pos_;
    if (pos_ == start) fail(field, "expected whitespace before it");
    const size_t begin = pos_;
    while (pos_ < data_.size() && !isPfmSpace(data_[pos_]) && pos_ - begin <= 32) ++pos_;
    if (pos_ == begin) fail(field, "expected a value, the file ends");
    return std::string_view(data_).substr(begin, pos_ - begin);
  }

  const std::string& path_;
  const std::string& data_;
  size_t pos_ = 0;
};

}  // namespace

ImageF readPfm(const std::string& path) {
  const std::string data = readFile(path);
  HeaderReader header(path, data);
  int channels = 0;
  header.readMagic(channels);
  const int width = header.readSize("header: width");
  const int height = header.readSize("header: height");
  const std::endian order = header.readScale() < 0 ? std::endian::little : std::endian::big;

  // Compare before allocating (a corrupt size must not allocate gigabytes); by
  // division, since height * row_bytes can overflow.
  const size_t row_bytes = static_cast<size_t>(width) * static_cast<size_t>(channels) * sizeof(float);
  const size_t remaining = data.size() - header.position();
  if (remaining % row_bytes != 0 || remaining / row_bytes != static_cast<size_t>(height))
    throw InputError(path, "data",
                     "expected " + std::to_string(height) + " rows of " + std::to_string(row_bytes) + " bytes, found " +
                         std::to_string(remaining) + " bytes");

  ImageF img(width, height, channels);
  const char* p = data.data() + header.position();
  // The first stored row is the bottom one.
  for (int y = height - 1; y >= 0; --y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < channels; ++c, p += sizeof(float)) img.at(x, y, c) = byte_order::load<float>(p, order);
  return img;
}

void writePfm(const std::string& path, const ImageF& img) {
  if (img.channels != 1 && img.channels != 3)
    throw InputError(path, "channels", "expected 1 or 3 channels, got " + std::to_string(img.channels));
  if (img.width <= 0 || img.height <= 0 ||
      img.data.size() !=
          static_cast<size_t>(img.width) * static_cast<size_t>(img.height) * static_cast<size_t>(img.channels))
    throw InputError(path, "image", "expected a non-empty image whose data matches its size");
  std::string bytes = (img.channels == 3 ? "PF\n" : "Pf\n") + std::to_string(img.width) + " " +
                      std::to_string(img.height) + "\n-1.0\n";  // negative scale: little-endian
  bytes.reserve(bytes.size() + img.data.size() * sizeof(float));
  for (int y = img.height - 1; y >= 0; --y)
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < img.channels; ++c) byte_order::appendLittleEndian(bytes, img.at(x, y, c));
  writeFileAtomic(path, bytes);
}

}  // namespace saresgs
