// COLMAP text models: cameras.txt, images.txt, points3D.txt.
#include <algorithm>
#include <charconv>
#include <cstdint>
#include <filesystem>
#include <locale>
#include <optional>
#include <ostream>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <vector>

#include "geometry/error.h"
#include "geometry/io/atomic_file.h"
#include "geometry/io/colmap.h"
#include "geometry/io/colmap_detail.h"

namespace saresgs {

namespace {

using namespace colmap_detail;  // the checks both readers share

constexpr std::string_view kSpace = " \t\r\v\f";

std::string_view trim(std::string_view s) {
  const size_t b = s.find_first_not_of(kSpace);
  if (b == std::string_view::npos) return {};
  return s.substr(b, s.find_last_not_of(kSpace) - b + 1);
}

std::string lineName(size_t number) { return "line " + std::to_string(number); }

template <typename T>
const char* describe() {
  if constexpr (std::is_floating_point_v<T>)
    return "a number";
  else if constexpr (std::is_same_v<T, std::uint8_t>)
    return "an integer in [0, 255]";
  else if constexpr (std::is_same_v<T, std::uint32_t>)
    return "an integer in [0, 4294967295]";
  else
    return "a non-negative integer";
}

// The whole token as one T; nothing when it is not exactly that (trailing junk,
// sign on an unsigned value, out of range).
template <typename T>
std::optional<T> parseToken(std::string_view tok) {
  // std::from_chars refuses a leading '+', which C++ streams (and COLMAP) accept.
  if constexpr (std::is_floating_point_v<T>)
    if (tok.size() > 1 && tok[0] == '+' && tok[1] != '-') tok.remove_prefix(1);
  T value{};
  const char* end = tok.data() + tok.size();
  const auto [ptr, ec] = std::from_chars(tok.data(), end, value);
  if (tok.empty() || ec != std::errc() || ptr != end) return std::nullopt;
  return value;
}

struct Line {
  size_t number = 0;  // 1-based
  std::string_view text;
};

// The whitespace-separated values of one line, taken left to right by column name.
// Errors read "<file>: line N: COLUMN: expected ...".
class Fields {
 public:
  Fields(const std::string& file, Line line) : file_(file), line_(line) {
    size_t pos = 0;
    while ((pos = line.text.find_first_not_of(kSpace, pos)) != std::string_view::npos) {
      const size_t end = std::min(line.text.find_first_of(kSpace, pos), line.text.size());
      tokens_.push_back(line.text.substr(pos, end - pos));
      pos = end;
    }
  }

  size_t left() const { return tokens_.size() - next_; }
  bool done() const { return left() == 0; }
  std::string where() const { return lineName(line_.number); }

  std::string_view word(std::string_view column) {
    if (done()) fail(column, "expected a value, got the end of the line");
    return tokens_[next_++];
  }

  template <typename T>
  T take(std::string_view column) {
    if (done()) fail(column, std::string("expected ") + describe<T>() + ", got the end of the line");
    return parse<T>(tokens_[next_++], column);
  }

  template <typename T>
  T parse(std::string_view tok, std::string_view column) const {
    const std::optional<T> v = parseToken<T>(tok);
    if (!v) fail(column, std::string("expected ") + describe<T>() + ", got '" + std::string(tok) + "'");
    return *v;
  }

  // Everything from the next value to the end of the line, so that image names may
  // contain spaces.
  std::string_view rest() {
    if (done()) return {};
    const size_t from = static_cast<size_t>(tokens_[next_].data() - line_.text.data());
    next_ = tokens_.size();
    return trim(line_.text.substr(from));
  }

  [[noreturn]] void fail(std::string_view column, const std::string& what) const {
    throw InputError(file_, where() + ": " + std::string(column), what);
  }

 private:
  const std::string& file_;
  Line line_;
  std::vector<std::string_view> tokens_;
  size_t next_ = 0;
};

// A text model file read line by line. Comment and blank lines between records are
// skipped; the "# Number of <things>: N" comment that COLMAP writes is checked
// against the number of records, which catches truncated files.
class TextFile {
 public:
  TextFile(std::string path, std::string_view things)
      : path_(std::move(path)),
        content_(readFile(path_)),
        things_(things),
        count_prefix_("# Number of " + std::string(things) + ":") {}

  const std::string& path() const { return path_; }

  // The next line holding data; nothing at the end of the file.
  std::optional<Line> nextRecord() {
    Line line;
    while (takeLine(line)) {
      const std::string_view body = trim(line.text);
      if (body.empty()) continue;
      if (body[0] == '#') {
        noteCount(line);
        continue;
      }
      return line;
    }
    return std::nullopt;
  }

  // The next line as it is, even when blank (an image's 2D point line); blank at the
  // end of the file, where COLMAP may leave out the last image's empty line.
  Line nextLine() {
    Line line{line_number_ + 1, {}};
    takeLine(line);
    return line;
  }

  void checkCount(size_t records) const {
    if (count_ && *count_ != records)
      throw InputError(path_, lineName(count_line_) + ": " + countField(),
                       "the header says " + std::to_string(*count_) + " " + things_ + ", the file has " +
                           std::to_string(records) + " (truncated or edited file?)");
  }

 private:
  bool takeLine(Line& out) {
    if (pos_ >= content_.size()) return false;
    size_t end = content_.find('\n', pos_);
    if (end == std::string::npos) end = content_.size();
    std::string_view text(content_.data() + pos_, end - pos_);
    if (!text.empty() && text.back() == '\r') text.remove_suffix(1);  // CRLF files
    out = {++line_number_, text};
    pos_ = end + 1;
    return true;
  }

  std::string countField() const { return "Number of " + things_; }

  void noteCount(const Line& line) {
    const std::string_view body = trim(line.text);
    if (!body.starts_with(count_prefix_)) return;
    std::string_view value = body.substr(count_prefix_.size());
    value = trim(value.substr(0, value.find(',')));  // "N, mean track length: ..."
    count_ = parseToken<std::uint64_t>(value);
    count_line_ = line.number;
    if (!count_)
      throw InputError(path_, lineName(line.number) + ": " + countField(),
                       "expected a non-negative integer, got '" + std::string(value) + "'");
  }

  std::string path_;
  std::string content_;
  std::string things_;
  std::string count_prefix_;
  size_t pos_ = 0;
  size_t line_number_ = 0;
  std::optional<std::uint64_t> count_;
  size_t count_line_ = 0;
};

template <typename Map, typename Record>
void insertUnique(Map& map, Record&& record, const Fields& fields, std::string_view column) {
  const auto id = record.id;
  if (!map.emplace(id, std::forward<Record>(record)).second)
    fields.fail(column, "expected unique ids, " + std::to_string(id) + " appears twice");
}

ColmapCamera parseCamera(Fields& f) {
  ColmapCamera cam;
  cam.id = f.take<std::uint32_t>("CAMERA_ID");
  cam.model = std::string(f.word("MODEL"));
  cam.width = f.take<std::uint64_t>("WIDTH");
  cam.height = f.take<std::uint64_t>("HEIGHT");
  while (!f.done()) cam.params.push_back(f.take<double>("PARAMS"));
  return cam;
}

// cameras.txt or points3D.txt: one record a line, each parsed, checked and kept once by
// its id, and as many as the header's count says.
template <typename Map, typename Parse, typename Check>
void readRecords(const std::string& dir, const char* name, const char* things, Map& into, Parse parse, Check check,
                 const char* id_field) {
  TextFile file(pathIn(dir, name), things);
  while (const auto line = file.nextRecord()) {
    Fields f(file.path(), *line);
    auto record = parse(f);
    check(record, file.path(), f.where());
    insertUnique(into, std::move(record), f, id_field);
  }
  file.checkCount(into.size());
}

void readCameras(const std::string& dir, ColmapModel& model) {
  readRecords(dir, "cameras.txt", "cameras", model.cameras, parseCamera, checkCamera, "CAMERA_ID");
}

// The first line of an image: IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME.
ColmapImage parseImageHeader(Fields& f) {
  ColmapImage img;
  img.id = f.take<std::uint32_t>("IMAGE_ID");
  // Separate statements: the order of evaluation of function arguments is unspecified.
  const double qw = f.take<double>("QW");
  const double qx = f.take<double>("QX");
  const double qy = f.take<double>("QY");
  const double qz = f.take<double>("QZ");
  img.q = Eigen::Quaterniond(qw, qx, qy, qz);
  for (int i = 0; i < 3; ++i) img.t[i] = f.take<double>(std::string("T") + "XYZ"[i]);
  img.camera_id = f.take<std::uint32_t>("CAMERA_ID");
  img.name = std::string(f.rest());
  if (img.name.empty()) f.fail("NAME", "expected an image name, got the end of the line");
  return img;
}

// The second line of an image: X Y POINT3D_ID triples, POINT3D_ID -1 for none.
void parsePoints2D(Fields& f, ColmapImage& img) {
  if (f.left() % 3 != 0)
    f.fail("POINTS2D",
           "expected X Y POINT3D_ID triples (the second line of an image, which may be "
           "empty but must be there), got " +
               std::to_string(f.left()) + " values");
  img.xys.reserve(f.left() / 3);
  img.point3d_ids.reserve(f.left() / 3);
  while (!f.done()) {
    const double x = f.take<double>("X");
    const double y = f.take<double>("Y");
    img.xys.emplace_back(x, y);
    const std::string_view id = f.word("POINT3D_ID");
    img.point3d_ids.push_back(id == "-1" ? kInvalidPoint3DId : f.parse<std::uint64_t>(id, "POINT3D_ID"));
  }
}

void readImages(const std::string& dir, ColmapModel& model) {
  TextFile file(pathIn(dir, "images.txt"), "images");
  while (const auto header = file.nextRecord()) {
    Fields f(file.path(), *header);
    ColmapImage img = parseImageHeader(f);
    checkPose(img.q, img.t, file.path(), f.where());
    Fields points(file.path(), file.nextLine());
    parsePoints2D(points, img);
    checkImagePoints(img, file.path(), points.where());
    insertUnique(model.images, std::move(img), f, "IMAGE_ID");
  }
  file.checkCount(model.images.size());
}

ColmapPoint3D parsePoint(Fields& f) {
  ColmapPoint3D pt;
  pt.id = f.take<std::uint64_t>("POINT3D_ID");
  for (int i = 0; i < 3; ++i) pt.xyz[i] = f.take<double>(std::string(1, "XYZ"[i]));
  for (int i = 0; i < 3; ++i) pt.rgb[static_cast<size_t>(i)] = f.take<std::uint8_t>(std::string(1, "RGB"[i]));
  pt.error = f.take<double>("ERROR");
  if (f.left() % 2 != 0)
    f.fail("TRACK", "expected IMAGE_ID POINT2D_IDX pairs, got " + std::to_string(f.left()) + " values");
  pt.track.reserve(f.left() / 2);
  while (!f.done()) {
    TrackElement e;
    e.image_id = f.take<std::uint32_t>("TRACK: IMAGE_ID");
    e.point2d_idx = f.take<std::uint32_t>("TRACK: POINT2D_IDX");
    pt.track.push_back(e);
  }
  return pt;
}

void readPoints(const std::string& dir, ColmapModel& model) {
  readRecords(dir, "points3D.txt", "points", model.points, parsePoint, checkPoint, "POINT3D_ID");
}

// 17 significant digits: enough for any double to read back exactly, and close enough
// to the double (within ~0.05 ulp) that COLMAP, which parses with std::stold and then
// rounds to double, gets the same double too. The shortest round-trip form is not: it
// can sit near a rounding midpoint, where that double rounding drifts by 1 ulp (seen
// with `colmap model_converter`).
void putDouble(std::ostream& o, double v) {
  char buf[40];
  const auto res = std::to_chars(buf, buf + sizeof(buf), v, std::chars_format::general, 17);
  o.write(buf, res.ptr - buf);
}

void writeCameras(std::ostream& o, const ColmapModel& model) {
  o << "# Camera list with one line of data per camera:\n"
       "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
       "# Number of cameras: "
    << model.cameras.size() << '\n';
  for (const auto& [id, cam] : model.cameras) {
    o << id << ' ' << cam.model << ' ' << cam.width << ' ' << cam.height;
    for (double p : cam.params) putDouble(o << ' ', p);
    o << '\n';
  }
}

void writeImages(std::ostream& o, const ColmapModel& model) {
  size_t observations = 0;
  for (const auto& [id, img] : model.images)
    for (std::uint64_t pid : img.point3d_ids) observations += pid != kInvalidPoint3DId;
  const double mean = model.images.empty() ? 0.0 : double(observations) / double(model.images.size());
  o << "# Image list with two lines of data per image:\n"
       "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
       "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
       "# Number of images: "
    << model.images.size() << ", mean observations per image: " << mean << '\n';
  for (const auto& [id, img] : model.images) {
    o << id;
    for (double v : {img.q.w(), img.q.x(), img.q.y(), img.q.z(), img.t.x(), img.t.y(), img.t.z()})
      putDouble(o << ' ', v);
    o << ' ' << img.camera_id << ' ' << img.name << '\n';
    for (size_t i = 0; i < img.xys.size(); ++i) {
      if (i > 0) o << ' ';
      putDouble(o, img.xys[i].x());
      putDouble(o << ' ', img.xys[i].y());
      o << ' ';
      if (img.point3d_ids[i] == kInvalidPoint3DId)
        o << -1;
      else
        o << img.point3d_ids[i];
    }
    o << '\n';
  }
}

void writePoints(std::ostream& o, const ColmapModel& model) {
  size_t elements = 0;
  for (const auto& [id, pt] : model.points) elements += pt.track.size();
  const double mean = model.points.empty() ? 0.0 : double(elements) / double(model.points.size());
  o << "# 3D point list with one line of data per point:\n"
       "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
       "# Number of points: "
    << model.points.size() << ", mean track length: " << mean << '\n';
  for (const auto& [id, pt] : model.points) {
    o << id;
    for (int i = 0; i < 3; ++i) putDouble(o << ' ', pt.xyz[i]);
    for (std::uint8_t c : pt.rgb) o << ' ' << int(c);
    putDouble(o << ' ', pt.error);
    for (const TrackElement& e : pt.track) o << ' ' << e.image_id << ' ' << e.point2d_idx;
    o << '\n';
  }
}

// Refuses, before anything is written, what the text format cannot hold so that it
// reads back the same: names on one line without surrounding blanks, one point3D
// id per 2D point.
void checkWritable(const ColmapModel& model, const std::string& path) {
  for (const auto& [id, img] : model.images) {
    const std::string where = "image " + std::to_string(id);
    if (img.name.empty() || img.name.find_first_of("\r\n") != std::string::npos || trim(img.name) != img.name)
      throw InputError(path, where + ": name",
                       "expected a non-empty name on one line without leading or trailing blanks, "
                       "got '" +
                           img.name + "'");
    if (img.xys.size() != img.point3d_ids.size())
      throw InputError(path, where + ": points2D", "expected one point3D id per 2D point");
  }
}

}  // namespace

ColmapModel readColmapText(const std::string& dir) {
  ColmapModel model;
  readCameras(dir, model);
  readImages(dir, model);
  readPoints(dir, model);
  return model;
}

void writeColmapText(const std::string& dir, const ColmapModel& model) {
  checkWritable(model, pathIn(dir, "images.txt"));
  // The classic locale: a global one could add digit grouping to the integers.
  const auto write = [&](const char* name, void (*writer)(std::ostream&, const ColmapModel&)) {
    writeStreamAtomic(pathIn(dir, name), [&](std::ostream& o) {
      o.imbue(std::locale::classic());
      writer(o, model);
    });
  };
  write("cameras.txt", writeCameras);
  write("images.txt", writeImages);
  write("points3D.txt", writePoints);
}

}  // namespace saresgs
