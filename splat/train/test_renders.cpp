#include "splat/train/test_renders.h"

#include <cstdio>
#include <filesystem>
#include <tbb/parallel_for.h>

#include "geometry/image/contact_sheet.h"

namespace saresgs {

void writeTestRenders(const Trainer& t, const Evaluation& ev, const std::string& dir) {
  namespace fs = std::filesystem;
  fs::create_directories(dir);
  const std::size_t n = ev.views.size();
  // The renders: the evaluation's when it kept them, else rendered here (in turn: each
  // render is parallel).
  std::vector<Image8> rendered;
  if (ev.renders.size() != n)
    for (const ViewMetrics& m : ev.views)
      rendered.push_back(toByte(t.render(t.scene().views[static_cast<std::size_t>(m.view)].camera).rgb));
  const std::vector<Image8>& renders = ev.renders.size() == n ? ev.renders : rendered;
  std::vector<ContactSheetItem> sheet(2 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const SceneView& v = t.scene().views[static_cast<std::size_t>(ev.views[i].view)];
    char label[64];
    std::snprintf(label, sizeof label, "%.2f dB", ev.views[i].psnr);
    sheet[2 * i] = {&t.scene().image(ev.views[i].view), v.name + " truth", false};
    sheet[2 * i + 1] = {&renders[i], std::string("render ") + label, true};
  }
  // One PNG per view (truth | render), encoded side by side: an encode is single-threaded.
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) {
    const SceneView& v = t.scene().views[static_cast<std::size_t>(ev.views[i].view)];
    const std::vector<ContactSheetItem> pair(sheet.begin() + 2 * i, sheet.begin() + 2 * i + 2);
    writeImage(dir + "/" + fs::path(v.name).stem().string() + ".png", makeContactSheet(pair, 2, renders[i].width));
  });
  if (!sheet.empty()) writeImage(dir + "/all.png", makeContactSheet(sheet, 4, 256));
}

}  // namespace saresgs
