#include "report/grid_page.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <sstream>

#include "geometry/error.h"
#include "geometry/io/atomic_file.h"
#include "geometry/io/json_file.h"
#include "report/html_page.h"
#include "report/run_page.h"

namespace saresgs {

namespace fs = std::filesystem;

namespace {

std::string trim(std::string s) {
  const auto sp = [](unsigned char c) { return std::isspace(c) != 0; };
  while (!s.empty() && sp(static_cast<unsigned char>(s.back()))) s.pop_back();
  std::size_t i = 0;
  while (i < s.size() && sp(static_cast<unsigned char>(s[i]))) ++i;
  return s.substr(i);
}

std::vector<std::string> tableCells(const std::string& line) {
  std::string t = trim(line);
  if (!t.empty() && t.front() == '|') t.erase(0, 1);
  if (!t.empty() && t.back() == '|') t.pop_back();
  std::vector<std::string> cells;
  std::string cur;
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (t[i] == '\\' && i + 1 < t.size() && t[i + 1] == '|') {
      cur += '|';
      ++i;
    } else if (t[i] == '|') {
      cells.push_back(trim(cur));
      cur.clear();
    } else {
      cur += t[i];
    }
  }
  cells.push_back(trim(cur));
  return cells;
}

bool alignmentRow(const std::vector<std::string>& cells) {
  for (const std::string& c : cells)
    if (c.empty() || c.find_first_not_of(":-") != std::string::npos) return false;
  return true;
}

struct JobName {
  std::string scene, method, variant, seed;
};
JobName splitJob(const std::string& name) {
  const std::vector<std::string> parts = jobNameParts(name);
  JobName j;
  if (parts.size() >= 4) {
    j.scene = parts[0], j.method = parts[1], j.variant = parts[2], j.seed = parts[3];
  } else {
    j.scene = name;
  }
  return j;
}

}  // namespace

std::vector<MarkdownBlock> parseMarkdown(const std::string& text) {
  std::vector<MarkdownBlock> blocks;
  std::istringstream in(text);
  std::string line;
  MarkdownBlock* open = nullptr;  // a paragraph or table being filled
  while (std::getline(in, line)) {
    const std::string t = trim(line);
    if (t.empty()) {
      open = nullptr;
      continue;
    }
    if (t.front() == '#') {
      MarkdownBlock b;
      b.kind = MarkdownBlock::Kind::kHeading;
      while (b.level < static_cast<int>(t.size()) && t[static_cast<std::size_t>(b.level)] == '#') ++b.level;
      b.text = trim(t.substr(static_cast<std::size_t>(b.level)));
      blocks.push_back(std::move(b));
      open = nullptr;
      continue;
    }
    if (t.front() == '|') {
      if (!open || open->kind != MarkdownBlock::Kind::kTable) {
        blocks.push_back({MarkdownBlock::Kind::kTable, 0, "", {}});
        open = &blocks.back();
      }
      std::vector<std::string> cells = tableCells(t);
      if (open->rows.size() == 1 && alignmentRow(cells)) continue;
      open->rows.push_back(std::move(cells));
      continue;
    }
    if (!open || open->kind != MarkdownBlock::Kind::kParagraph) {
      blocks.push_back({MarkdownBlock::Kind::kParagraph, 0, "", {}});
      open = &blocks.back();
    } else {
      open->text += ' ';
    }
    open->text += t;
  }
  return blocks;
}

GridPageResult writeGridPage(const std::string& grid_dir, const GridPageOptions& o) {
  const fs::path dir(grid_dir);
  const fs::path runs = dir / "runs";
  if (!fs::is_directory(runs))
    throw InputError(grid_dir, "runs", "no runs/ folder: expected the --out folder of `saresgs ablate`");
  GridPageResult res;
  res.path = o.out.empty() ? (dir / "report.html").string() : o.out;

  // The tables, as the grid wrote them.
  nlohmann::json tables = nlohmann::json::array();
  std::vector<fs::path> md;
  if (fs::is_directory(dir / "tables"))
    for (const auto& e : fs::directory_iterator(dir / "tables"))
      if (e.path().extension() == ".md") md.push_back(e.path());
  std::sort(md.begin(), md.end());
  for (const fs::path& p : md) {
    nlohmann::json blocks = nlohmann::json::array();
    for (const MarkdownBlock& b : parseMarkdown(readFile(p.string()))) {
      if (b.kind == MarkdownBlock::Kind::kHeading)
        blocks.push_back({{"heading", b.text}, {"level", b.level}});
      else if (b.kind == MarkdownBlock::Kind::kParagraph)
        blocks.push_back({{"text", b.text}});
      else {
        blocks.push_back({{"table", b.rows}});
        ++res.tables;
      }
    }
    tables.push_back({{"file", p.filename().string()}, {"blocks", blocks}});
  }

  // The jobs.
  std::vector<fs::path> job_dirs;
  for (const auto& e : fs::directory_iterator(runs))
    if (e.is_directory()) job_dirs.push_back(e.path());
  std::sort(job_dirs.begin(), job_dirs.end());
  // links relative to where the page is written, so that they work from any --out
  const fs::path page_dir = fs::absolute(fs::path(res.path)).parent_path();
  const auto link = [&](const fs::path& file) {
    return fs::absolute(file).lexically_normal().lexically_relative(page_dir).generic_string();
  };
  nlohmann::json jobs = nlohmann::json::array();
  // scene -> method label -> views -> progress PSNRs over seeds
  std::map<std::string, std::map<std::string, std::map<int, std::vector<double>>>> curves;
  for (const fs::path& jd : job_dirs) {
    const std::string name = jd.filename().string();
    const JobName jn = splitJob(name);
    nlohmann::json j = {
        {"name", name}, {"scene", jn.scene}, {"method", jn.method}, {"variant", jn.variant}, {"seed", jn.seed}};
    // an active job's results.json, a prefilter sweep's sweep.json
    const fs::path rp =
        fs::exists(jd / "sweep.json") && !fs::exists(jd / "results.json") ? jd / "sweep.json" : jd / "results.json";
    if (!fs::exists(rp)) {
      j["status"] = fs::exists(jd / "checkpoint.json") ? "running or interrupted" : "not started";
      jobs.push_back(std::move(j));
      continue;
    }
    nlohmann::json r;
    try {
      r = readJsonFile(rp.string());
    } catch (const std::exception& e) {
      res.problems.push_back(std::string(e.what()));
      j["status"] = "unreadable results.json";
      jobs.push_back(std::move(j));
      continue;
    }
    if (!r.is_object() || !r.contains("steps")) {  // a sweep or another kind of job
      j["status"] = "finished (a sweep: no run page)";
      j["link"] = link(rp);
      jobs.push_back(std::move(j));
      continue;
    }
    j["status"] = "finished";
    const auto num = [&](const nlohmann::json& v, const char* k) -> nlohmann::json {
      return v.is_object() && v.contains(k) && v[k].is_number() ? v[k] : nlohmann::json();
    };
    j["psnr"] = num(r, "psnr");
    j["ssim"] = num(r, "ssim");
    if (r.contains("final_fit") && r["final_fit"].is_object()) {
      j["final_psnr"] = num(r["final_fit"], "psnr");
      j["final_ssim"] = num(r["final_fit"], "ssim");
    }
    if (r.contains("seconds") && r["seconds"].is_object()) j["seconds"] = num(r["seconds"], "end_to_end_this_process");
    if (r.contains("selected_view_indices") && r["selected_view_indices"].is_array())
      j["views"] = r["selected_view_indices"].size();
    if (o.run_reports && !fs::exists(jd / "report.html")) {
      try {
        RunPageOptions ro;
        ro.threads = o.threads;
        writeRunPage(jd.string(), nullptr, ro);
        ++res.run_reports_written;
      } catch (const std::exception& e) {
        res.problems.push_back(name + ": its run page: " + e.what());
      }
    }
    j["link"] = link(fs::exists(jd / "report.html") ? jd / "report.html" : rp);
    const std::string label = jn.variant.empty() || jn.variant == "default" ? jn.method : jn.method + " " + jn.variant;
    if (r["steps"].is_array())
      for (const auto& s : r["steps"])
        if (s.is_object() && s.contains("views_before") && s.contains("progress_psnr") &&
            s["progress_psnr"].is_number())
          curves[jn.scene][label][s["views_before"].get<int>()].push_back(s["progress_psnr"].get<double>());
    jobs.push_back(std::move(j));
  }
  res.jobs = jobs.size();
  nlohmann::json curve_json = nlohmann::json::object();
  for (const auto& [scene, methods] : curves) {
    nlohmann::json m = nlohmann::json::object();
    for (const auto& [label, by_views] : methods) {
      nlohmann::json pts = nlohmann::json::array();
      for (const auto& [views, v] : by_views) {
        double sum = 0;
        for (double x : v) sum += x;
        pts.push_back({views, sum / static_cast<double>(v.size()), v.size()});
      }
      m[label] = pts;
    }
    curve_json[scene] = m;
  }

  // The grid's PNG plots.
  nlohmann::json plots = nlohmann::json::array();
  std::vector<fs::path> pngs;
  if (fs::is_directory(dir / "plots"))
    for (const auto& e : fs::directory_iterator(dir / "plots"))
      if (e.path().extension() == ".png") pngs.push_back(e.path());
  std::sort(pngs.begin(), pngs.end());
  for (const fs::path& p : pngs)
    plots.push_back({{"name", p.stem().string()}, {"src", dataUrl("image/png", readFile(p.string()))}});

  fs::path named = fs::absolute(dir).lexically_normal();
  if (named.filename().empty()) named = named.parent_path();
  nlohmann::json data = {{"kind", "grid"},
                         {"title", "grid " + named.filename().string()},
                         {"grid_dir", dir.string()},
                         {"tables", tables},
                         {"jobs", jobs},
                         {"curves", curve_json},
                         {"plots", plots},
                         {"problems", res.problems}};
  PageParts parts;
  parts.title = "saresgs report: " + data["title"].get<std::string>();
  parts.data = std::move(data);
  const std::string html = pageHtml(parts);
  writeFileAtomic(res.path, html);
  res.bytes = html.size();
  return res;
}

}  // namespace saresgs
