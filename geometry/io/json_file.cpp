#include "geometry/io/json_file.h"

#include <cmath>
#include <cstdint>
#include <sstream>

#include "geometry/error.h"
#include "geometry/io/atomic_file.h"

namespace saresgs {

namespace {

using nlohmann::json;

// The offending value as JSON text, cut short so that a message stays one line.
std::string shown(const json& v) {
  std::string s = v.dump();
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  return s;
}

[[noreturn]] void expected(const json& v, const std::string& file, const std::string& field, const std::string& what) {
  throw InputError(file, field, "expected " + what + ", got " + shown(v));
}

}  // namespace

nlohmann::json readJsonFile(const std::string& path) {
  const std::string text = readFile(path);
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, "json", std::string("not valid JSON: ") + e.what());
  }
}

std::string jsonPath(const std::string& parent, const std::string& key) {
  return parent.empty() ? key : parent + "." + key;
}
std::string jsonPath(const std::string& parent, std::size_t index) {
  return parent + "[" + std::to_string(index) + "]";
}

const json& jsonObject(const json& v, const std::string& file, const std::string& field) {
  if (!v.is_object()) expected(v, file, field.empty() ? "json" : field, "an object");
  return v;
}

const json& jsonArray(const json& v, const std::string& file, const std::string& field, std::size_t max_size) {
  if (!v.is_array()) expected(v, file, field, "an array");
  if (v.size() > max_size)
    throw InputError(file, field,
                     "holds " + std::to_string(v.size()) + " items, at most " + std::to_string(max_size) + " allowed");
  return v;
}

const json* jsonFind(const json& object, const std::string& key, const std::string& file, const std::string& path) {
  jsonObject(object, file, path);
  const auto it = object.find(key);
  return it == object.end() ? nullptr : &*it;
}

const json& jsonMember(const json& object, const std::string& key, const std::string& file, const std::string& path) {
  const json* v = jsonFind(object, key, file, path);
  if (!v) throw InputError(file, jsonPath(path, key), "missing");
  return *v;
}

double jsonNumber(const json& v, const std::string& file, const std::string& field) {
  if (!v.is_number()) expected(v, file, field, "a number");
  const double x = v.get<double>();
  if (!std::isfinite(x)) expected(v, file, field, "a finite number");
  return x;
}

double jsonNumberIn(const json& v, const std::string& file, const std::string& field, double lo, double hi) {
  const double x = v.is_number() ? v.get<double>() : NAN;
  if (!(x >= lo && x <= hi)) {
    std::ostringstream range;
    range << "a number in " << lo << ".." << hi;
    expected(v, file, field, range.str());
  }
  return x;
}

long long jsonInteger(const json& v, const std::string& file, const std::string& field, long long lo, long long hi) {
  const std::string what = "a whole number in " + std::to_string(lo) + ".." + std::to_string(hi);
  if (v.is_number_unsigned()) {
    const auto u = v.get<std::uint64_t>();
    if (hi < 0 || u > static_cast<std::uint64_t>(hi) || static_cast<long long>(u) < lo) expected(v, file, field, what);
    return static_cast<long long>(u);
  }
  if (v.is_number_integer()) {
    const auto i = v.get<std::int64_t>();
    if (i < lo || i > hi) expected(v, file, field, what);
    return i;
  }
  if (v.is_number_float()) {
    // Compared in double: the bounds as doubles may round, so refuse at the edges.
    const double x = v.get<double>();
    if (!(x == std::floor(x) && x >= static_cast<double>(lo) && x <= static_cast<double>(hi)) || std::abs(x) >= 0x1p63)
      expected(v, file, field, what);
    const auto i = static_cast<long long>(x);
    if (i < lo || i > hi) expected(v, file, field, what);
    return i;
  }
  expected(v, file, field, what);
}

bool jsonBool(const json& v, const std::string& file, const std::string& field) {
  if (!v.is_boolean()) expected(v, file, field, "true or false");
  return v.get<bool>();
}

std::string jsonString(const json& v, const std::string& file, const std::string& field) {
  if (!v.is_string()) expected(v, file, field, "a string");
  return v.get<std::string>();
}

std::vector<std::string> jsonStrings(const json& v, const std::string& file, const std::string& field) {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < jsonArray(v, file, field).size(); ++i)
    out.push_back(jsonString(v[i], file, jsonPath(field, i)));
  return out;
}

std::vector<double> jsonNumbers(const json& v, const std::string& file, const std::string& field) {
  std::vector<double> out;
  for (std::size_t i = 0; i < jsonArray(v, file, field).size(); ++i)
    out.push_back(jsonNumber(v[i], file, jsonPath(field, i)));
  return out;
}

std::vector<long long> jsonIntegers(const json& v, const std::string& file, const std::string& field, long long lo,
                                    long long hi) {
  std::vector<long long> out;
  for (std::size_t i = 0; i < jsonArray(v, file, field).size(); ++i)
    out.push_back(jsonInteger(v[i], file, jsonPath(field, i), lo, hi));
  return out;
}

}  // namespace saresgs
