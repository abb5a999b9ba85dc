#include "geometry/io/json_file.h"

#include "geometry/error.h"
#include "geometry/io/atomic_file.h"

namespace saresgs {

nlohmann::json readJsonFile(const std::string& path) {
  const std::string text = readFile(path);
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, "json", std::string("not valid JSON: ") + e.what());
  }
}

}  // namespace saresgs
