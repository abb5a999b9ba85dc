#pragma once
// Renders beside their ground truth, for people to look at: one PNG per evaluated view
// (truth | render, PSNR in the label) and one sheet of all of them.
#include <string>

#include "splat/train/trainer.h"

namespace saresgs {

void writeTestRenders(const Trainer& t, const Evaluation& ev, const std::string& dir);

}  // namespace saresgs
