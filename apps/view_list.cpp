#include "apps/view_list.h"

#include <algorithm>
#include <sstream>

#include "geometry/error.h"

namespace saresgs::apps {

std::vector<int> parseTrainViews(const std::string& text, const Scene& scene, const std::string& option) {
  std::vector<int> out;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) {
    int v = -1;
    const bool digits =
        !item.empty() && std::all_of(item.begin(), item.end(), [](char c) { return c >= '0' && c <= '9'; });
    if (digits) {
      // A train index (at most 9 digits: anything longer is out of range anyway).
      const long long i = item.size() <= 9 ? std::stoll(item) : -1;
      if (i < 0 || i >= static_cast<long long>(scene.train.size()))
        throw InputError(option, item, "train index out of range 0.." + std::to_string(scene.train.size() - 1));
      v = scene.train[static_cast<std::size_t>(i)];
    } else {
      for (int t : scene.train)
        if (scene.views[static_cast<std::size_t>(t)].name == item) v = t;
      if (v < 0) throw InputError(option, item, "neither a train index nor the name of a train image");
    }
    if (std::find(out.begin(), out.end(), v) != out.end()) throw InputError(option, item, "listed twice");
    out.push_back(v);
  }
  if (out.empty()) throw InputError(option, text, "expected a comma-separated list of train views");
  return out;
}

}  // namespace saresgs::apps
