#include "splat/train/test_renders.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <tbb/parallel_for.h>

#include "geometry/image/contact_sheet.h"

namespace saresgs {

std::vector<std::string> testRenderNames(const Scene& scene, const Evaluation& ev) {
  namespace fs = std::filesystem;
  const std::size_t n = ev.views.size();
  std::vector<std::string> names(n);
  std::map<std::string, int> uses{{"all", 1}};  // the sheet of all views
  auto nameOf = [&](std::size_t i) -> const std::string& {
    return scene.views[static_cast<std::size_t>(ev.views[i].view)].name;
  };
  for (std::size_t i = 0; i < n; ++i) ++uses[names[i] = fs::path(nameOf(i)).stem().string()];
  // Where two views (say cam1/0001.png and cam2/0001.png), or a view and the sheet, share
  // a stem: the path without its extension, folders joined by '_'.
  for (std::size_t i = 0; i < n; ++i)
    if (uses[names[i]] > 1) {
      names[i] = fs::path(nameOf(i)).replace_extension().generic_string();
      std::replace(names[i].begin(), names[i].end(), '/', '_');
    }
  // And if even those meet (a view listed twice, "a_b" beside "a/b"): the view's index.
  std::map<std::string, int> again;
  for (const std::string& s : names) ++again[s];
  for (std::size_t i = 0; i < n; ++i)
    if (again[names[i]] > 1 || names[i] == "all") names[i] += "_" + std::to_string(ev.views[i].view);
  return names;
}

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
  // One PNG per view (truth | render) and the sheet of all, encoded side by side (an encode
  // is single-threaded); the sheet, the longest, first.
  const std::vector<std::string> names = testRenderNames(t.scene(), ev);
  if (n == 0) return;
  tbb::parallel_for(std::size_t{0}, n + 1, [&](std::size_t k) {
    if (k == 0) {
      writeImage(dir + "/all.png", makeContactSheet(sheet, 4, 256));
      return;
    }
    const std::size_t i = k - 1;
    const std::vector<ContactSheetItem> pair(sheet.begin() + 2 * i, sheet.begin() + 2 * i + 2);
    writeImage(dir + "/" + names[i] + ".png", makeContactSheet(pair, 2, renders[i].width));
  });
}

}  // namespace saresgs
