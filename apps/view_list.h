#pragma once
// A list of train views on the command line: train indices or image names, comma-separated.
#include <string>
#include <vector>

#include "geometry/scene/scene.h"

namespace saresgs::apps {

// Indices into scene.views, in the order given. Throws InputError naming `option` and the
// item for an index out of range, a name that is not a train image, a view listed twice
// or an empty list.
std::vector<int> parseTrainViews(const std::string& text, const Scene& scene, const std::string& option);

}  // namespace saresgs::apps
