#pragma once
// Reads a JSON file; a missing file or invalid JSON is an InputError naming the file
// (field "json" for a parse error), so every reader reports bad input the same way.
#include <nlohmann/json.hpp>

#include <string>

namespace saresgs {

nlohmann::json readJsonFile(const std::string& path);

}  // namespace saresgs
