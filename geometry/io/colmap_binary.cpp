// COLMAP binary models: cameras.bin, images.bin, points3D.bin (little-endian).
#include <bit>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <ostream>
#include <string_view>

#include "geometry/error.h"
#include "geometry/io/atomic_file.h"
#include "geometry/io/byte_order.h"
#include "geometry/io/colmap.h"
#include "geometry/io/colmap_detail.h"

namespace saresgs {

namespace {

using namespace colmap_detail;  // the checks both readers share

// Smallest size of one record, used to refuse counts that the file cannot hold
// before anything is allocated for them.
constexpr size_t kCameraBytes = 4 + 4 + 8 + 8 + 3 * 8;  // id, model, size, >= 3 params
constexpr size_t kImageBytes = 4 + 7 * 8 + 4 + 1 + 8;   // id, pose, camera, "\0", count
constexpr size_t kPoint2DBytes = 8 + 8 + 8;             // x, y, point3D_id
constexpr size_t kPointBytes = 8 + 3 * 8 + 3 + 8 + 8;   // id, xyz, rgb, error, length
constexpr size_t kTrackElementBytes = 4 + 4;            // image_id, point2D_idx

// Names the record being read: "image 7" once its id is known, "image record 3"
// (0-based position in the file) while reading the id itself, nothing for the
// file's leading count. Formatted only when an error is thrown.
struct Where {
  const char* kind = nullptr;
  std::uint64_t number = 0;
  bool is_index = false;

  std::string name() const { return std::string(kind) + (is_index ? " record " : " ") + std::to_string(number); }
  std::string field(std::string_view field) const {
    return kind ? name() + ": " + std::string(field) : std::string(field);
  }
};

// A whole binary file in memory, read front to back. Every read checks the bytes
// that remain, so a truncated or corrupt file gives an InputError, never a read
// past the end.
class ByteReader {
 public:
  explicit ByteReader(std::string path) : path_(std::move(path)), data_(readFile(path_)) {}

  const std::string& path() const { return path_; }
  size_t remaining() const { return data_.size() - pos_; }

  template <typename T>
  T read(const Where& where, std::string_view field) {
    if (remaining() < sizeof(T))
      fail(where, field,
           "expected " + std::to_string(sizeof(T)) + " more bytes at offset " + std::to_string(pos_) +
               ", the file ends (truncated)");
    const T value = byte_order::load<T>(data_.data() + pos_, std::endian::little);
    pos_ += sizeof(T);
    return value;
  }

  // A uint64 count of records of at least `min_bytes` each.
  std::uint64_t readCount(const Where& where, std::string_view field, size_t min_bytes) {
    const auto count = read<std::uint64_t>(where, field);
    if (count > remaining() / min_bytes)
      fail(where, field,
           "count " + std::to_string(count) + " needs at least " + std::to_string(min_bytes) + " bytes each, only " +
               std::to_string(remaining()) + " bytes remain (corrupt or truncated)");
    return count;
  }

  std::string readName(const Where& where, std::string_view field) {
    const size_t end = data_.find('\0', pos_);
    if (end == std::string::npos) fail(where, field, "expected a name ending in '\\0', the file ends (truncated)");
    std::string name = data_.substr(pos_, end - pos_);
    pos_ = end + 1;
    if (name.empty()) fail(where, field, "expected an image name, got an empty one");
    return name;
  }

  void expectEnd(std::uint64_t records, std::string_view things) const {
    if (remaining() != 0)
      throw InputError(path_, "end of file",
                       "expected the file to end after " + std::to_string(records) + " " + std::string(things) +
                           ", found " + std::to_string(remaining()) + " more bytes");
  }

  [[noreturn]] void fail(const Where& where, std::string_view field, const std::string& what) const {
    throw InputError(path_, where.field(field), what);
  }

 private:
  std::string path_;
  std::string data_;
  size_t pos_ = 0;
};

template <typename Map, typename Record>
void insertUniqueBinary(Map& map, Record&& record, const ByteReader& in, const Where& where, std::string_view field) {
  const auto id = record.id;
  if (!map.emplace(id, std::forward<Record>(record)).second)
    in.fail(where, field, "expected unique ids, " + std::to_string(id) + " appears twice");
}

// One .bin file of records: their count, each record read and kept once by its id, and
// nothing after the last.
template <typename Map, typename ReadRecord>
void readBinaryRecords(const std::string& dir, const char* file, const char* count_field, size_t min_bytes, Map& into,
                       ReadRecord read, const char* kind, const char* id_field, const char* things) {
  ByteReader in(pathIn(dir, file));
  const std::uint64_t count = in.readCount({}, count_field, min_bytes);
  for (std::uint64_t i = 0; i < count; ++i) insertUniqueBinary(into, read(in, i), in, {kind, i, true}, id_field);
  in.expectEnd(count, things);
}

ColmapCamera readCamera(ByteReader& in, std::uint64_t index) {
  ColmapCamera cam;
  cam.id = in.read<std::uint32_t>({"camera", index, true}, "camera_id");
  const Where where{"camera", cam.id};
  const auto model_id = in.read<std::int32_t>(where, "model_id");
  cam.model = colmapModelName(model_id);
  if (cam.model.empty())
    in.fail(where, "model_id", "expected a COLMAP camera model id 0..10, got " + std::to_string(model_id));
  cam.width = in.read<std::uint64_t>(where, "width");
  cam.height = in.read<std::uint64_t>(where, "height");
  cam.params.resize(static_cast<size_t>(colmapModelParamCount(model_id)));
  for (double& p : cam.params) p = in.read<double>(where, "params");
  checkCamera(cam, in.path(), where.name());
  return cam;
}

// images.bin stores point3D ids as int64 with -1 for "no point".
std::uint64_t readPoint3DId(ByteReader& in, const Where& where) {
  const auto id = in.read<std::int64_t>(where, "point3D_id");
  if (id == -1) return kInvalidPoint3DId;
  if (id < 0) in.fail(where, "point3D_id", "expected -1 or a non-negative id, got " + std::to_string(id));
  return static_cast<std::uint64_t>(id);
}

ColmapImage readImage(ByteReader& in, std::uint64_t index) {
  ColmapImage img;
  img.id = in.read<std::uint32_t>({"image", index, true}, "image_id");
  const Where where{"image", img.id};
  // Separate statements: the order of evaluation of function arguments is unspecified.
  const auto qw = in.read<double>(where, "qw");
  const auto qx = in.read<double>(where, "qx");
  const auto qy = in.read<double>(where, "qy");
  const auto qz = in.read<double>(where, "qz");
  img.q = Eigen::Quaterniond(qw, qx, qy, qz);
  for (int i = 0; i < 3; ++i) img.t[i] = in.read<double>(where, std::string("t") + "xyz"[i]);
  img.camera_id = in.read<std::uint32_t>(where, "camera_id");
  img.name = in.readName(where, "name");
  const std::uint64_t n = in.readCount(where, "num_points2D", kPoint2DBytes);
  img.xys.reserve(n);
  img.point3d_ids.reserve(n);
  for (std::uint64_t i = 0; i < n; ++i) {
    const auto x = in.read<double>(where, "points2D: x");
    const auto y = in.read<double>(where, "points2D: y");
    img.xys.emplace_back(x, y);
    img.point3d_ids.push_back(readPoint3DId(in, where));
  }
  checkPose(img.q, img.t, in.path(), where.name());
  checkImagePoints(img, in.path(), where.name());
  return img;
}

ColmapPoint3D readPoint(ByteReader& in, std::uint64_t index) {
  ColmapPoint3D pt;
  pt.id = in.read<std::uint64_t>({"point", index, true}, "point3D_id");
  const Where where{"point", pt.id};
  for (int i = 0; i < 3; ++i) pt.xyz[i] = in.read<double>(where, std::string(1, "xyz"[i]));
  for (int i = 0; i < 3; ++i) pt.rgb[static_cast<size_t>(i)] = in.read<std::uint8_t>(where, std::string(1, "rgb"[i]));
  pt.error = in.read<double>(where, "error");
  const std::uint64_t n = in.readCount(where, "track_length", kTrackElementBytes);
  pt.track.reserve(n);
  for (std::uint64_t i = 0; i < n; ++i) {
    TrackElement e;
    e.image_id = in.read<std::uint32_t>(where, "track: image_id");
    e.point2d_idx = in.read<std::uint32_t>(where, "track: point2D_idx");
    pt.track.push_back(e);
  }
  checkPoint(pt, in.path(), where.name());
  return pt;
}

// Little-endian values collected in a buffer and passed to the stream in large
// blocks rather than a stream call per value.
class ByteWriter {
 public:
  explicit ByteWriter(std::ostream& out) : out_(out) {}

  template <typename T>
  void put(T value) {
    byte_order::appendLittleEndian(buf_, value);
    if (buf_.size() >= (1u << 20)) flush();
  }
  void putName(const std::string& name) {
    buf_ += name;
    buf_.push_back('\0');
  }
  void flush() {
    out_.write(buf_.data(), static_cast<std::streamsize>(buf_.size()));
    buf_.clear();
  }

 private:
  std::ostream& out_;
  std::string buf_;
};

void writeCamerasBinary(std::ostream& o, const ColmapModel& model) {
  ByteWriter w(o);
  w.put<std::uint64_t>(model.cameras.size());
  for (const auto& [id, cam] : model.cameras) {
    w.put<std::uint32_t>(id);
    w.put<std::int32_t>(colmapModelId(cam.model));
    w.put<std::uint64_t>(cam.width);
    w.put<std::uint64_t>(cam.height);
    for (double p : cam.params) w.put(p);
  }
  w.flush();
}

void writeImagesBinary(std::ostream& o, const ColmapModel& model) {
  ByteWriter w(o);
  w.put<std::uint64_t>(model.images.size());
  for (const auto& [id, img] : model.images) {
    w.put<std::uint32_t>(id);
    for (double v : {img.q.w(), img.q.x(), img.q.y(), img.q.z(), img.t.x(), img.t.y(), img.t.z()}) w.put(v);
    w.put<std::uint32_t>(img.camera_id);
    w.putName(img.name);
    w.put<std::uint64_t>(img.xys.size());
    for (size_t i = 0; i < img.xys.size(); ++i) {
      w.put(img.xys[i].x());
      w.put(img.xys[i].y());
      const std::uint64_t pid = img.point3d_ids[i];
      w.put<std::int64_t>(pid == kInvalidPoint3DId ? -1 : static_cast<std::int64_t>(pid));
    }
  }
  w.flush();
}

void writePointsBinary(std::ostream& o, const ColmapModel& model) {
  ByteWriter w(o);
  w.put<std::uint64_t>(model.points.size());
  for (const auto& [id, pt] : model.points) {
    w.put<std::uint64_t>(id);
    for (int i = 0; i < 3; ++i) w.put(pt.xyz[i]);
    for (std::uint8_t c : pt.rgb) w.put(c);
    w.put(pt.error);
    w.put<std::uint64_t>(pt.track.size());
    for (const TrackElement& e : pt.track) {
      w.put(e.image_id);
      w.put(e.point2d_idx);
    }
  }
  w.flush();
}

// Refuses, before anything is written, what the binary format cannot encode:
// unknown models or parameter counts (the reader takes the count from the model),
// names with '\0', point3D ids that do not fit images.bin's int64.
void checkBinaryWritable(const ColmapModel& model, const std::string& dir) {
  for (const auto& [id, cam] : model.cameras) {
    const std::string where = "camera " + std::to_string(id);
    const int model_id = colmapModelId(cam.model);
    if (model_id < 0)
      throw InputError(pathIn(dir, "cameras.bin"), where + ": model",
                       "expected a COLMAP camera model, got '" + cam.model + "'");
    if (cam.params.size() != static_cast<size_t>(colmapModelParamCount(model_id)))
      throw InputError(pathIn(dir, "cameras.bin"), where + ": params",
                       "expected " + std::to_string(colmapModelParamCount(model_id)) + " parameters for " + cam.model);
  }
  constexpr auto kMaxId = static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
  for (const auto& [id, img] : model.images) {
    const std::string where = "image " + std::to_string(id);
    const std::string path = pathIn(dir, "images.bin");
    if (img.name.empty() || img.name.find('\0') != std::string::npos)
      throw InputError(path, where + ": name", "expected a non-empty name without '\\0'");
    if (img.xys.size() != img.point3d_ids.size())
      throw InputError(path, where + ": points2D", "expected one point3D id per 2D point");
    for (std::uint64_t pid : img.point3d_ids)
      if (pid != kInvalidPoint3DId && pid > kMaxId)
        throw InputError(path, where + ": point3D_id", "expected ids below 2^63, got " + std::to_string(pid));
  }
}

}  // namespace

ColmapModel readColmapBinary(const std::string& dir) {
  ColmapModel model;
  readBinaryRecords(dir, "cameras.bin", "num_cameras", kCameraBytes, model.cameras, readCamera, "camera", "camera_id",
                    "cameras");
  readBinaryRecords(dir, "images.bin", "num_images", kImageBytes, model.images, readImage, "image", "image_id",
                    "images");
  readBinaryRecords(dir, "points3D.bin", "num_points3D", kPointBytes, model.points, readPoint, "point", "point3D_id",
                    "points");
  return model;
}

void writeColmapBinary(const std::string& dir, const ColmapModel& model) {
  checkBinaryWritable(model, dir);
  const auto write = [&](const char* name, void (*writer)(std::ostream&, const ColmapModel&)) {
    writeStreamAtomic(
        pathIn(dir, name), [&](std::ostream& o) { writer(o, model); }, /*binary=*/true);
  };
  write("cameras.bin", writeCamerasBinary);
  write("images.bin", writeImagesBinary);
  write("points3D.bin", writePointsBinary);
}

}  // namespace saresgs
