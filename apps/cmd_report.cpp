// saresgs report: one self-contained HTML page of a finished active run (report/run_page.h)
// or of an ablation grid (report/grid_page.h).
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "apps/cli_checks.h"
#include "apps/commands.h"
#include "report/grid_page.h"
#include "report/run_page.h"
#include "splat/thread_limit.h"

namespace saresgs::apps {

namespace {

struct ReportArgs {
  std::string dir;
  RunPageOptions page;
  bool run_reports = false;
  int threads = 0;
};

int runReport(const ReportArgs& a) {
  namespace fs = std::filesystem;
  const auto thread_limit = limitThreads(a.threads);
  // A grid: runs/ and no results.json of its own.
  if (!fs::exists(fs::path(a.dir) / "results.json") && fs::is_directory(fs::path(a.dir) / "runs")) {
    GridPageOptions g;
    g.out = a.page.out;
    g.run_reports = a.run_reports;
    g.threads = a.threads;
    const GridPageResult r = writeGridPage(a.dir, g);
    for (const std::string& p : r.problems) std::cerr << "report: " << p << "\n";
    std::printf("wrote %s (%.1f MB): %zu jobs, %zu tables%s\n", r.path.c_str(),
                static_cast<double>(r.bytes) / (1024.0 * 1024.0), r.jobs, r.tables,
                r.run_reports_written ? (", and " + std::to_string(r.run_reports_written) + " run pages").c_str() : "");
    return 0;
  }
  RunPageOptions page = a.page;
  page.threads = a.threads;
  const RunPageResult r = writeRunPage(a.dir, nullptr, page);
  for (const std::string& m : r.missing) std::cerr << "report: " << m << "\n";
  std::printf("wrote %s (%.1f MB%s)\n", r.path.c_str(), static_cast<double>(r.bytes) / (1024.0 * 1024.0),
              r.viewer ? ", with the 3D viewer" : ", without the 3D viewer");
  return 0;
}

}  // namespace

void addReportCommand(CLI::App& app, Action& action) {
  auto a = std::make_shared<ReportArgs>();
  CLI::App* sub = app.add_subcommand(
      "report",
      "Write one self-contained HTML page of a finished active run (the model in a splat viewer, the "
      "cameras, the curve, every test view, why each view was chosen) or of an ablation grid");
  sub->add_option("dir", a->dir, "A run's folder (`saresgs active --out`) or a grid's (`saresgs ablate --out`)")
      ->required();
  sub->add_option("--out", a->page.out, "The page to write (default: DIR/report.html)");
  sub->add_option("--dataset", a->page.dataset, "The dataset, when it is no longer where results.json says");
  sub->add_option(
      "--viewer-script", a->page.viewer_script,
      "The bundled viewer (default: $SARESGS_REPORT_VIEWER, else what scripts/install_node_tools.sh built)");
  sub->add_option("--model-budget-bytes", a->page.model_budget_bytes,
                  "Largest model embedded as its .ply, in bytes; a larger one goes in as a .splat")
      ->check(CLI::Range(std::size_t{1} << 10, std::size_t{1} << 30));
  sub->add_flag("--run-reports", a->run_reports, "A grid: also write each finished job's run page where it is missing");
  sub->add_option("--threads", a->threads, "Threads for rendering the test views (0: all)")
      ->check(CLI::NonNegativeNumber);
  sub->callback([&action, a] { action = [a] { return runReport(*a); }; });
}

}  // namespace saresgs::apps
