#include "splat/train/test_renders.h"

#include <cstdio>
#include <filesystem>

#include "geometry/image/contact_sheet.h"

namespace saresgs {

void writeTestRenders(const Trainer& t, const Evaluation& ev, const std::string& dir) {
  namespace fs = std::filesystem;
  fs::create_directories(dir);
  std::vector<Image8> images;
  images.reserve(2 * ev.views.size());
  std::vector<ContactSheetItem> sheet;
  for (const ViewMetrics& m : ev.views) {
    const SceneView& v = t.scene().views[static_cast<std::size_t>(m.view)];
    images.push_back(t.scene().image(m.view));
    images.push_back(toByte(t.render(v.camera).rgb));
    char label[64];
    std::snprintf(label, sizeof label, "%.2f dB", m.psnr);
    const std::vector<ContactSheetItem> pair = {{&images[images.size() - 2], v.name + " truth", false},
                                                {&images.back(), std::string("render ") + label, true}};
    writeImage(dir + "/" + fs::path(v.name).stem().string() + ".png", makeContactSheet(pair, 2, images.back().width));
    sheet.insert(sheet.end(), pair.begin(), pair.end());
  }
  if (!sheet.empty()) writeImage(dir + "/all.png", makeContactSheet(sheet, 4, 256));
}

}  // namespace saresgs
