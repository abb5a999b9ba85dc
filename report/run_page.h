#pragma once
// The report of one active run as one HTML page (html_page.h): the trained model in an
// interactive splat viewer with the capture's cameras, the run's curve, every test view
// (truth, render, error) worst first, why each view was chosen, timings and options.
// Written by `saresgs report RUN_DIR`, at the end of `saresgs active` and by
// ActiveRun.write in Python.
#include <cstddef>
#include <string>
#include <vector>

#include "geometry/scene/scene.h"

namespace saresgs {

struct RunPageOptions {
  std::string out;            // default: RUN_DIR/report.html
  std::string dataset;        // default: the path results.json names
  std::string viewer_script;  // default: findViewerScript's search
  // The model travels as its .ply when that fits (exact); above this many bytes (before
  // base64) as a .splat (degree 0, 8-bit colour), and above it again thinned to the most
  // opaque Gaussians, the page saying so.
  std::size_t model_budget_bytes = std::size_t{24} << 20;
  int threads = 0;  // rendering the test views (0: all)
};

struct RunPageResult {
  std::string path;                  // the page written
  std::size_t bytes = 0;             // its size
  std::vector<std::string> missing;  // what the page says it could not show, and why
  bool viewer = false;               // the 3D viewer is in the page
};

// Reads RUN_DIR (results.json, the .ply files) and the dataset (`scene` when the caller
// holds it, as `saresgs active` does; else loaded from results.json's path or
// options.dataset), renders the test views with the model the viewer shows, and writes the
// page atomically. Throws InputError naming the file when RUN_DIR holds no results.json
// (saying whether the run was interrupted) or results.json is malformed; anything else
// missing (a .ply, the dataset, the viewer script) is said on the page and in `missing`.
RunPageResult writeRunPage(const std::string& run_dir, const Scene* scene, const RunPageOptions& options = {});

// A job folder's name, SCENE__METHOD__VARIANT__sSEED (nbv/eval/ablation.cpp's job id), in
// its parts (one part, the whole name, when it is not of that form).
std::vector<std::string> jobNameParts(const std::string& name);

}  // namespace saresgs
