#include "geometry/synth/assets.h"

#include <cctype>
#include <cstdlib>
#include <filesystem>

#include "geometry/error.h"

namespace saresgs {

namespace fs = std::filesystem;

namespace {

constexpr const char* kCgalData = "/usr/share/doc/libcgal-dev/data.tar.gz";
constexpr const char* kOpencvData = "/usr/share/doc/opencv-doc/examples/data";

bool safeName(const std::string& s) {
  if (s.empty() || s.find("..") != std::string::npos) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) return false;
  return true;
}

}  // namespace

std::string dataCacheDir() {
  const char* env = std::getenv("SARESGS_DATA_CACHE");
  return (env && *env) ? std::string(env) : std::string("data_cache");
}

std::string resolveAsset(const std::string& spec) {
  if (spec.rfind("cgal:", 0) == 0) {
    const std::string name = spec.substr(5);
    if (!safeName(name)) throw InputError(spec, "mesh name", "expected a name such as cgal:bunny00");
    const fs::path dir = fs::path(dataCacheDir()) / "cgal";
    for (const char* ext : {".off", ".ply", ".obj"}) {
      const fs::path p = dir / "data" / "meshes" / (name + ext);
      if (fs::exists(p)) return p.string();
    }
    if (!fs::exists(kCgalData))
      throw InputError(spec, "mesh", std::string("needs ") + kCgalData + " (Debian package libcgal-demo)");
    fs::create_directories(dir);
    // Extract only the requested mesh; tar's wildcard matches any of the three formats.
    const std::string cmd = "tar -xzf " + std::string(kCgalData) + " -C '" + dir.string() +
                            "' --wildcards 'data/meshes/" + name + ".*' > /dev/null 2>&1";
    (void)std::system(cmd.c_str());
    for (const char* ext : {".off", ".ply", ".obj"}) {
      const fs::path p = dir / "data" / "meshes" / (name + ext);
      if (fs::exists(p)) return p.string();
    }
    throw InputError(
        spec, "mesh",
        std::string("no mesh of that name in ") + kCgalData + " (list them: tar tzf " + kCgalData + " | grep meshes/)");
  }
  if (spec.rfind("opencv:", 0) == 0) {
    const std::string name = spec.substr(7);
    const fs::path p = fs::path(kOpencvData) / name;
    if (!safeName(name) || !fs::exists(p))
      throw InputError(spec, "texture",
                       std::string("no such photograph in ") + kOpencvData + " (Debian package opencv-doc)");
    return p.string();
  }
  return spec;
}

}  // namespace saresgs
