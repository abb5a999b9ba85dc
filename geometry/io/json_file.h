#pragma once
// Reads a JSON file; a missing file or invalid JSON is an InputError naming the file
// (field "json" for a parse error), so every reader reports bad input the same way.
//
// Typed fields: each function below takes a value, the file it came from and the field's
// path in it ("frames[3].transform_matrix", built with jsonPath) and returns the value
// as the type asked for, or throws InputError(file, field, "expected ..., got ...") — never
// nlohmann's own "type must be number, but is string", which names neither.
#include <nlohmann/json.hpp>

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

namespace saresgs {

nlohmann::json readJsonFile(const std::string& path);

// "parent.key" (or "key" at the top), "parent[index]".
std::string jsonPath(const std::string& parent, const std::string& key);
std::string jsonPath(const std::string& parent, std::size_t index);

// `v` itself, checked to be an object / an array (of at most max_size items).
const nlohmann::json& jsonObject(const nlohmann::json& v, const std::string& file, const std::string& field);
const nlohmann::json& jsonArray(const nlohmann::json& v, const std::string& file, const std::string& field,
                                std::size_t max_size = std::numeric_limits<std::size_t>::max());

// Member `key` of the object `object` (at `path`): jsonMember throws when it is missing,
// jsonFind returns null; both throw when `object` is not an object.
const nlohmann::json& jsonMember(const nlohmann::json& object, const std::string& key, const std::string& file,
                                 const std::string& path);
const nlohmann::json* jsonFind(const nlohmann::json& object, const std::string& key, const std::string& file,
                               const std::string& path);

// A finite number (optionally within [lo, hi]).
double jsonNumber(const nlohmann::json& v, const std::string& file, const std::string& field);
double jsonNumberIn(const nlohmann::json& v, const std::string& file, const std::string& field, double lo, double hi);
// A whole number within [lo, hi]; 2e9 written as a float counts when it is whole, 1.5 does not.
long long jsonInteger(const nlohmann::json& v, const std::string& file, const std::string& field, long long lo,
                      long long hi);
bool jsonBool(const nlohmann::json& v, const std::string& file, const std::string& field);
std::string jsonString(const nlohmann::json& v, const std::string& file, const std::string& field);

// Arrays of one type; an item's error names it ("field[i]").
std::vector<std::string> jsonStrings(const nlohmann::json& v, const std::string& file, const std::string& field);
std::vector<double> jsonNumbers(const nlohmann::json& v, const std::string& file, const std::string& field);
std::vector<long long> jsonIntegers(const nlohmann::json& v, const std::string& file, const std::string& field,
                                    long long lo, long long hi);

}  // namespace saresgs
