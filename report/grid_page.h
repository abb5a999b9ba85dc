#pragma once
// The report of an ablation grid (`saresgs ablate --out GRID_DIR`) as one HTML page
// (html_page.h): every Markdown table the grid wrote (GRID_DIR/tables/*.md) as a sortable
// table, the PSNR-against-views curve of each method per scene (mean over seeds, from the
// jobs' results.json), every job with its numbers and a link to its run report, and the
// grid's PNG plots.
#include <string>
#include <vector>

namespace saresgs {

struct GridPageOptions {
  std::string out;  // default: GRID_DIR/report.html
  // Also write each finished job's run page (GRID_DIR/runs/JOB/report.html) where it is
  // missing; otherwise a job links to its page when it has one, else to its results.json.
  bool run_reports = false;
  int threads = 0;
};

struct GridPageResult {
  std::string path;
  std::size_t bytes = 0;
  std::size_t jobs = 0, tables = 0, run_reports_written = 0;
  std::vector<std::string> problems;  // jobs or files that could not be read, and why
};

// Throws InputError naming GRID_DIR when it has no runs/ folder.
GridPageResult writeGridPage(const std::string& grid_dir, const GridPageOptions& options = {});

// The Markdown the grid writes, read back: headings, paragraphs and pipe tables in order
// (a table's cells trimmed, its alignment row dropped). Exposed for its tests.
struct MarkdownBlock {
  enum class Kind { kHeading, kParagraph, kTable } kind = Kind::kParagraph;
  int level = 0;                               // headings: the number of '#'
  std::string text;                            // headings and paragraphs
  std::vector<std::vector<std::string>> rows;  // tables: the header first
};
std::vector<MarkdownBlock> parseMarkdown(const std::string& text);

}  // namespace saresgs
