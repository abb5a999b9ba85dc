#include "geometry/synth/colmap_sfm.h"

#include <sqlite3.h>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <stdexcept>

#include "geometry/error.h"

namespace saresgs {

namespace fs = std::filesystem;

namespace {

std::string quote(const std::string& s) {
  // POSIX shell single quotes; an embedded quote becomes '\''.
  std::string q = "'";
  for (char c : s) {
    if (c == '\'')
      q.append("'\\''");
    else
      q.push_back(c);
  }
  q.push_back('\'');
  return q;
}

void runColmap(const std::string& args, const fs::path& log) {
  const std::string cmd = "colmap " + args + " >> " + quote(log.string()) + " 2>&1";
  if (std::system(cmd.c_str()) != 0)
    throw std::runtime_error("colmap step failed: colmap " + args + " (log: " + log.string() + ")");
}

// COLMAP's database: image name -> (image_id, camera_id).
std::map<std::string, std::pair<std::uint32_t, std::uint32_t>> databaseImages(const fs::path& db) {
  sqlite3* handle = nullptr;
  if (sqlite3_open_v2(db.c_str(), &handle, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    sqlite3_close(handle);
    throw InputError(db.string(), "database", "cannot open COLMAP's SQLite database");
  }
  std::map<std::string, std::pair<std::uint32_t, std::uint32_t>> out;
  sqlite3_stmt* stmt = nullptr;
  if (sqlite3_prepare_v2(handle, "SELECT image_id, name, camera_id FROM images", -1, &stmt, nullptr) != SQLITE_OK) {
    sqlite3_close(handle);
    throw InputError(db.string(), "images", "expected COLMAP's images table");
  }
  while (sqlite3_step(stmt) == SQLITE_ROW) {
    const auto id = static_cast<std::uint32_t>(sqlite3_column_int64(stmt, 0));
    const char* name = reinterpret_cast<const char*>(sqlite3_column_text(stmt, 1));
    const auto cam = static_cast<std::uint32_t>(sqlite3_column_int64(stmt, 2));
    out[name ? name : ""] = {id, cam};
  }
  sqlite3_finalize(stmt);
  sqlite3_close(handle);
  return out;
}

}  // namespace

ColmapModel triangulateWithColmap(const SyntheticScene& scene, const std::string& dataset_dir,
                                  const ColmapModel& known) {
  if (std::system("colmap help > /dev/null 2>&1") != 0)
    throw std::runtime_error("--sfm colmap needs the colmap binary (bash scripts/install_deps.sh)");
  if (known.cameras.size() != 1) throw std::runtime_error("--sfm colmap: expected one shared camera");
  const fs::path root(dataset_dir), work = root / "colmap";
  fs::create_directories(work / "known");
  fs::create_directories(work / "triangulated");
  const fs::path db = work / "database.db", log = work / "log.txt";
  fs::remove(db);
  const ColmapCamera& cam = known.cameras.begin()->second;
  std::string params;
  for (double p : cam.params) params += (params.empty() ? "" : ",") + std::to_string(p);
  // CPU only, so it runs on machines without a GPU or a display.
  runColmap("feature_extractor --database_path " + quote(db.string()) + " --image_path " +
                quote((root / "images").string()) + " --ImageReader.camera_model " + cam.model +
                " --ImageReader.single_camera 1 --ImageReader.camera_params " + params +
                " --SiftExtraction.use_gpu 0 --SiftExtraction.num_threads 2",
            log);
  const bool small = scene.cameras.size() <= 60;
  runColmap(std::string(small ? "exhaustive_matcher" : "sequential_matcher --SequentialMatching.overlap 15") +
                " --database_path " + quote(db.string()) + " --SiftMatching.use_gpu 0 --SiftMatching.num_threads 2",
            log);

  // The known model with COLMAP's own ids: both the image and the camera ids must be
  // the database's, matched by image name.
  const auto ids = databaseImages(db);
  ColmapModel input;
  std::map<std::uint32_t, std::uint32_t> to_known;  // colmap image id -> our image id
  for (const auto& [our_id, im] : known.images) {
    const auto it = ids.find(im.name);
    if (it == ids.end()) throw std::runtime_error("COLMAP's database lacks image " + im.name);
    ColmapImage copy = im;
    copy.id = it->second.first;
    copy.camera_id = it->second.second;
    copy.xys.clear();
    copy.point3d_ids.clear();
    to_known[copy.id] = our_id;
    ColmapCamera c = cam;
    c.id = copy.camera_id;
    input.cameras[c.id] = c;
    input.images.emplace(copy.id, std::move(copy));
  }
  writeColmapText((work / "known").string(), input);
  runColmap("point_triangulator --database_path " + quote(db.string()) + " --image_path " +
                quote((root / "images").string()) + " --input_path " + quote((work / "known").string()) +
                " --output_path " + quote((work / "triangulated").string()) +
                " --Mapper.ba_refine_focal_length 0 --Mapper.ba_refine_principal_point 0"
                " --Mapper.ba_refine_extra_params 0 --Mapper.num_threads 2",
            log);
  ColmapModel tri = readColmapModel((work / "triangulated").string());

  // Back to our ids and our camera record.
  ColmapModel out;
  out.cameras = known.cameras;
  for (auto& [cid, im] : tri.images) {
    ColmapImage copy = im;
    copy.id = to_known.at(cid);
    copy.camera_id = known.images.at(copy.id).camera_id;
    out.images.emplace(copy.id, std::move(copy));
  }
  for (const auto& [our_id, im] : known.images)
    if (!out.images.count(our_id)) out.images.emplace(our_id, im);  // unregistered: no points
  for (auto& [pid, p] : tri.points) {
    ColmapPoint3D copy = p;
    for (auto& e : copy.track) e.image_id = to_known.at(e.image_id);
    out.points.emplace(pid, std::move(copy));
  }
  return out;
}

}  // namespace saresgs
