#pragma once
// Renders beside their ground truth, for people to look at: one PNG per evaluated view
// (truth | render, PSNR in the label) and one sheet of all of them.
#include <string>
#include <vector>

#include "splat/train/trainer.h"

namespace saresgs {

void writeTestRenders(const Trainer& t, const Evaluation& ev, const std::string& dir);
// The file name (without .png) of each evaluated view's pair: its image's stem, or where
// two views or a view and the sheet (all.png) would share one, a longer name that does not
// (the views are written side by side, so a shared name would be a race, not only a loss).
std::vector<std::string> testRenderNames(const Scene& scene, const Evaluation& ev);

}  // namespace saresgs
