#pragma once
// Reading the run report's JSON (internal to nbv: run_report.cpp, step_report.cpp).
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include "geometry/io/json_file.h"
#include "geometry/scene/scene.h"

namespace saresgs::report_json {

// j[key] as T; InputError(source, path.key) when it is missing, of another type or, for
// counts, negative or fractional.
template <class T>
T field(const nlohmann::json& j, const char* key, const std::string& source, const std::string& path) {
  const std::string name = jsonPath(path, key);
  const nlohmann::json& v = jsonMember(j, key, source, path);
  if constexpr (std::is_same_v<T, std::string>)
    return jsonString(v, source, name);
  else if constexpr (std::is_same_v<T, bool>)
    return jsonBool(v, source, name);
  else if constexpr (std::is_same_v<T, double>)
    return jsonNumber(v, source, name);
  else if constexpr (std::is_integral_v<T>)
    return static_cast<T>(jsonInteger(v, source, name, 0,
                                      static_cast<long long>(std::min<std::uint64_t>(
                                          std::numeric_limits<T>::max(), std::numeric_limits<long long>::max()))));
  else if constexpr (std::is_same_v<T, std::vector<std::string>>)
    return jsonStrings(v, source, name);
  else if constexpr (std::is_same_v<T, std::vector<double>>)
    return jsonNumbers(v, source, name);
  else {
    static_assert(std::is_same_v<T, std::vector<int>>);
    std::vector<int> out;
    for (long long x : jsonIntegers(v, source, name, 0, std::numeric_limits<int>::max()))
      out.push_back(static_cast<int>(x));
    return out;
  }
}

// The names of views given by index.
inline std::vector<std::string> names(const Scene& scene, const std::vector<int>& views) {
  std::vector<std::string> n;
  n.reserve(views.size());
  for (int v : views) n.push_back(scene.views.at(static_cast<std::size_t>(v)).name);
  return n;
}

}  // namespace saresgs::report_json
