#include "geometry/scene/background.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "geometry/error.h"

namespace saresgs {

BackgroundChoice parseBackground(const std::string& text, const std::string& where) {
  if (text == "white") return {};
  if (text == "black") return {false, {0, 0, 0}};
  if (text == "random") return {true, {1, 1, 1}};
  const auto bad = [&] {
    return InputError(where, "value", "expected " + std::string(kBackgroundForms) + ", got '" + text + "'");
  };
  BackgroundChoice b;
  std::size_t at = 0;
  for (int c = 0; c < 3; ++c) {
    const std::size_t end = c < 2 ? text.find(',', at) : text.size();
    if (end == std::string::npos) throw bad();
    const std::string part = text.substr(at, end - at);
    char* stop = nullptr;
    const double v = part.empty() ? NAN : std::strtod(part.c_str(), &stop);
    if (part.empty() || stop != part.c_str() + part.size() || !(v >= 0 && v <= 1)) throw bad();
    b.color[static_cast<std::size_t>(c)] = static_cast<float>(v);
    at = end + 1;
  }
  return b;
}

std::string backgroundText(const BackgroundChoice& b) {
  if (b.random) return "random";
  if (b.color == std::array<float, 3>{1, 1, 1}) return "white";
  if (b.color == std::array<float, 3>{0, 0, 0}) return "black";
  std::ostringstream o;
  o << b.color[0] << "," << b.color[1] << "," << b.color[2];
  return o.str();
}

}  // namespace saresgs
