// saresgs info: reads a dataset and prints what saresgs sees in it.
#include <iostream>
#include <sstream>

#include "apps/cli_checks.h"
#include "apps/commands.h"
#include "geometry/scene/dataset_checks.h"
#include "geometry/scene/scene.h"
#include "nbv/active_run.h"
#include "nbv/selectors.h"

namespace saresgs::apps {

namespace {

struct InfoArgs {
  std::string dataset, background;
  DatasetOptions opts;
};

// The frame the dataset is computed in (geometry/scene/scene_frame.h).
std::string frameText(const SceneFrame& f) {
  if (f.identity()) return "world coordinates (a scene of metres about the origin is kept as it is)";
  std::ostringstream o;
  o.precision(17);
  o << "internal = (world - [" << f.center.transpose() << "]) / " << f.scale;
  return o.str();
}

// The background line: the colour (or none), random, and where it came from.
std::string backgroundLine(const Scene& s) {
  std::ostringstream o;
  if (!s.background)
    o << "none (opaque images; renders are on black)";
  else if (s.random_background)
    o << "random per training step, evaluated on " << backgroundText(BackgroundChoice{false, *s.background});
  else
    o << backgroundText(BackgroundChoice{false, *s.background});
  o << " (" << s.background_from << ")";
  return o.str();
}

int runInfo(const InfoArgs& a) {
  DatasetOptions opts = a.opts;
  if (!a.background.empty()) opts.background = parseBackground(a.background, "--background");
  const Scene s = loadDataset(a.dataset, opts);
  std::cerr << formatWarnings(checkDataset(s)) << backgroundWarning(s);
  const std::string internal = s.frame.identity() ? "" : " (internal units; the frame below maps them to the world)";
  const Intrinsics& K = s.views.front().camera.K;
  ActiveOptions adaptive;
  adaptive.method = Method::kAdaptive;
  const bool adaptiveKmedian = usesKmedianGate(s, adaptive);
  int with_depth = 0;
  for (size_t i = 0; i < s.views.size(); ++i) with_depth += s.hasDepth(static_cast<int>(i));
  std::cout << "dataset " << s.source << "\n"
            << "  views:   " << s.views.size() << " (" << s.train.size() << " train, " << s.test.size() << " test), "
            << with_depth << " with ground-truth depth\n"
            << "  camera:  " << K.width << "x" << K.height << ", fx " << K.fx << ", fy " << K.fy << ", fov "
            << K.fovX() * 180 / M_PI << " x " << K.fovY() * 180 / M_PI << " deg\n"
            << "  points:  " << s.points.size() << "\n"
            << "  aabb:    [" << s.aabb.min.transpose() << "] .. [" << s.aabb.max.transpose() << "]" << internal << "\n"
            << "  extent:  " << s.extent << internal << "\n"
            << "  frame:   " << frameText(s.frame) << "\n"
            << "  background: " << backgroundLine(s) << "\n"
            << "  capture: clustering " << captureClustering(s) << " (" << (adaptiveKmedian ? "clustered" : "even")
            << "; `active --method adaptive` gates Fisher by " << (adaptiveKmedian ? "k-median gain" : "farthest view")
            << ")\n";
  // Reading one image proves the images are there and of the right size.
  const Image8& img = s.image(s.train.front());
  std::cout << "  image " << s.views[s.train.front()].name << ": " << img.width << "x" << img.height << " read\n";
  return 0;
}

}  // namespace

void addInfoCommand(CLI::App& app, Action& action) {
  auto args = std::make_shared<InfoArgs>();
  CLI::App* sub = app.add_subcommand("info", "Read a dataset (COLMAP, Blender, synthetic) and summarise it");
  sub->add_option("--dataset", args->dataset, "Dataset folder")->required();
  sub->add_option("--downscale", args->opts.load.downscale, "Image downscale factor (uses images_N if present)")
      ->check(CLI::Range(1, 64));
  sub->add_option("--background", args->background, kBackgroundHelp)->check(backgroundValue());
  sub->add_option("--test-every", args->opts.test_every, "COLMAP: every N-th view (sorted by name) is a test view")
      ->capture_default_str();
  sub->callback([&action, args] { action = [args] { return runInfo(*args); }; });
}

}  // namespace saresgs::apps
