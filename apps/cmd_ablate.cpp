// saresgs ablate: runs an ablation grid of active runs and prefilter sweeps as
// independent jobs (listable, shardable, skipped when finished), and merges finished
// jobs into tables and plots. The grid format is in nbv/ablation.h.
#include <sys/file.h>
#include <unistd.h>
#include <fcntl.h>

#include <chrono>
#include <cstdio>
#include <set>
#include <thread>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "apps/cli.h"
#include "apps/commands.h"
#include "geometry/error.h"
#include "geometry/io/atomic_file.h"
#include "geometry/synth/from_manifest.h"
#include "nbv/eval/ablation.h"
#include "report/grid_page.h"
#include "nbv/eval/prefilter_sweep.h"

namespace saresgs::apps {

namespace {

namespace fs = std::filesystem;

struct AblateArgs {
  std::string config, out, shard, inputs;
  bool list = false, allow_partial = false;
};

std::string commandLine(const std::vector<std::string>& args) {
  std::string s = "saresgs";
  for (const auto& a : args) s += " " + (a.find_first_of(" \"'") == std::string::npos ? a : "'" + a + "'");
  return s;
}

std::vector<std::string> activeArgs(const AblationJob& j, const std::string& out) {
  std::vector<std::string> a{"active"};
  a.insert(a.end(), j.args.begin(), j.args.end());
  if (!j.replay_of.empty()) a.insert(a.end(), {"--replay", replaySource(out, j)});
  a.insert(a.end(), {"--out", jobFolder(out, j)});
  return a;
}

// Generates a missing synthetic dataset once, even when several shards start together:
// an exclusive lock on DATASET.lock, then a second look.
void ensureDataset(const AblationScene& sc) {
  if (fs::exists(sc.dataset)) return;
  if (sc.layout.empty())
    throw InputError(sc.dataset, "dataset", "missing, and the grid gives no layout to generate it");
  if (fs::path(sc.dataset).has_parent_path()) fs::create_directories(fs::path(sc.dataset).parent_path());
  const std::string lock = sc.dataset + ".lock";
  const int fd = ::open(lock.c_str(), O_CREAT | O_RDWR, 0644);
  if (fd < 0) throw std::runtime_error("cannot open lock file " + lock);
  ::flock(fd, LOCK_EX);
  int rc = 0;
  if (!fs::exists(sc.dataset)) {
    std::cerr << "[ablate] generating " << sc.layout << " into " << sc.dataset << "\n";
    rc = runCli({"scene", "--layout", sc.layout, "--seed", std::to_string(sc.scene_seed), "--out", sc.dataset});
  }
  ::flock(fd, LOCK_UN);
  ::close(fd);
  if (rc != 0) throw std::runtime_error("generating " + sc.dataset + " failed");
}

// An exclusive hold on one job of an output folder (runs/<job>.lock, flock): two runners
// on one folder (a shard started twice, a resubmitted array task beside the old one)
// never run the same job at once. The kernel drops the hold when its process dies, so a
// killed runner's job is free for the next one, which resumes it from its checkpoint.
class JobLock {
 public:
  explicit JobLock(const std::string& path) : fd_(::open(path.c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0644)) {
    if (fd_ < 0) throw std::runtime_error("cannot open lock file " + path);
    held_ = ::flock(fd_, LOCK_EX | LOCK_NB) == 0;
  }
  ~JobLock() {
    if (held_) ::flock(fd_, LOCK_UN);
    ::close(fd_);
  }
  JobLock(const JobLock&) = delete;
  JobLock& operator=(const JobLock&) = delete;
  bool held() const { return held_; }

 private:
  int fd_;
  bool held_ = false;
};

std::string jobLockPath(const std::string& out, const AblationJob& j) { return jobFolder(out, j) + ".lock"; }

const AblationScene& sceneOf(const AblationGrid& g, const std::string& name) {
  for (const auto& s : g.scenes)
    if (s.name == name) return s;
  throw std::logic_error("unknown scene " + name);
}

void runSweep(const AblationGrid& g, const AblationJob& j, const std::string& out) {
  const AblationScene& sc = sceneOf(g, j.scene);
  const Scene scene = loadDataset(sc.dataset, {});
  const std::optional<SyntheticScene> truth = rebuildSyntheticScene(sc.dataset, scene);
  if (!truth)
    throw InputError(sc.dataset, "manifest.json",
                     "the prefilter sweep lifts SA-Points from ground-truth renders: needs a `saresgs scene` dataset");
  const ViewRenderer render = [&](const Camera& c) { return truth->render(c); };
  const DepthRenderer depth = [&](const Camera& c) { return truth->renderDepth(c); };
  // The occupancy grid of the scene's type (the paper's m = 5 indoors, 2 outdoors), as the
  // active loop chooses it from the same manifest.
  PrefilterConfig grid;
  const std::string layout = truth->manifest.value("layout", std::string());
  const std::optional<SceneType> type = sceneTypeOfLayout(layout);
  if (type) applySceneType(grid, *type);
  PrefilterRegime regime;
  SweepReport report;
  report.scene = j.scene;
  report.dataset = sc.dataset;
  report.lifting = toString(g.sweep->lifting);
  report.reference = "exact encoding of the Embree-visible sets, same score";
  report.rows = prefilterSweep(scene, *g.sweep, render, depth, 0, grid, &regime);
  report.scene_type = type ? toString(*type) : "";
  report.resolution = regime.resolution;
  report.min_points = regime.min_points;
  report.scene_voxels = regime.scene_voxels;
  fs::create_directories(jobFolder(out, j));
  writeFileAtomic(jobResultFile(out, j), toJson(report).dump(2) + "\n");
}

// Tables, plots and an index page for every finished job of the grid.
int writeSummary(const AblationGrid& g, const std::vector<AblationJob>& jobs, const std::string& out,
                 bool allow_partial) {
  const std::vector<JobResult> results = loadFinishedJobs(out, jobs);
  std::vector<std::string> missing;
  for (const auto& j : jobs)
    if (!jobFinished(out, j)) missing.push_back(j.id);
  fs::create_directories(out + "/tables");
  fs::create_directories(out + "/plots");
  std::ostringstream page;
  page << "# Ablation results\n\nGrid: `" << g.source << "`, " << results.size() << " of " << jobs.size()
       << " jobs finished. Made by `saresgs ablate --config " << g.source << " --out " << out
       << "` (or its shards and `saresgs ablate merge`). Each job's own results are in `runs/<job>/`.\n\n";
  if (!missing.empty()) {
    page << "**Partial:** missing";
    for (const auto& m : missing) page << " `" << m << "`";
    page << "\n\n";
  }
  for (const Table& t : ablationTables(g, results)) {
    writeFileAtomic(out + "/tables/" + t.name + ".md", t.markdown());
    writeFileAtomic(out + "/tables/" + t.name + ".csv", t.csv());
    page << t.markdown() << "\n(CSV: `tables/" << t.name << ".csv`)\n\n";
  }
  for (const NamedPlot& p : ablationPlots(g, results)) {
    writeImage(out + "/plots/" + p.name + ".png", p.image);
    page << "![" << p.name << "](plots/" << p.name << ".png)\n\n";
  }
  writeFileAtomic(out + "/README.md", page.str());
  std::cerr << "[ablate] wrote " << out << "/README.md, tables/ and plots/ from " << results.size() << " of "
            << jobs.size() << " jobs\n";
  // The same as one page to look at (report/grid_page.h); a page that cannot be made is
  // said, the tables stand.
  try {
    const GridPageResult r = writeGridPage(out);
    std::cerr << "[ablate] wrote " << r.path << ": open it in a browser\n";
  } catch (const std::exception& e) {
    std::cerr << "[ablate] no report.html: " << e.what() << "\n";
  }
  if (!missing.empty()) {
    std::cerr << "[ablate] " << missing.size() << " jobs not finished";
    if (!allow_partial) std::cerr << " (pass --allow-partial to accept)";
    std::cerr << "\n";
    return allow_partial ? 0 : 2;
  }
  return 0;
}

// Every active job's command line (preset, seed, threads, method_args, a variant's args) is
// parsed when the config is read, so that a bad value stops the grid before any job runs.
void checkJobArguments(const AblationGrid& g, const std::vector<AblationJob>& jobs) {
  for (const AblationJob& j : jobs) {
    if (j.kind != AblationJob::Kind::kActive) continue;
    try {
      checkActiveArguments(j.args);
    } catch (const std::exception& e) {
      std::string field;
      if (g.method_args.count(j.method)) field = "method_args." + j.method;
      for (std::size_t v = 0; v < g.variants.size(); ++v)
        if (g.variants[v].name == j.variant && !g.variants[v].args.empty())
          field += (field.empty() ? "" : " + ") + std::string("variants[") + std::to_string(v) + "].args";
      if (field.empty()) field = "preset/threads/seeds";
      throw InputError(g.source, field, "job " + j.id + ": " + e.what());
    }
  }
}

int runAblate(const AblateArgs& a) {
  const AblationGrid g = readAblationGrid(a.config);
  const std::vector<AblationJob> all = expandGrid(g);
  checkJobArguments(g, all);
  int si = 0, sn = 1;
  if (!a.shard.empty()) std::tie(si, sn) = parseShard(a.shard);
  const std::vector<AblationJob> jobs = shardJobs(all, si, sn);
  if (a.list) {
    for (const auto& j : jobs) {
      std::printf("%s %s\n", jobFinished(a.out, j) ? "[done]" : "[todo]", j.id.c_str());
      if (j.kind == AblationJob::Kind::kActive)
        std::printf("    %s\n", commandLine(activeArgs(j, a.out)).c_str());
      else
        std::printf("    prefilter sweep of %s (in-process)\n", j.scene.c_str());
    }
    return 0;
  }
  fs::create_directories(a.out + "/runs");
  int failed = 0, done = 0;
  // A replay job whose source run is not finished goes to the back of the queue; when only
  // such jobs are left, the runner waits for another shard to finish their sources.
  std::vector<std::size_t> queue(jobs.size());
  for (std::size_t k = 0; k < jobs.size(); ++k) queue[k] = k;
  std::size_t deferred_in_a_row = 0, held_elsewhere_in_a_row = 0;
  std::set<std::string> failed_ids;
  while (!queue.empty()) {
    const std::size_t k = queue.front();
    queue.erase(queue.begin());
    const AblationJob& j = jobs[k];
    if (!j.replay_of.empty() && !jobFinished(a.out, j) && !fs::exists(replaySource(a.out, j))) {
      if (failed_ids.count(j.replay_of)) {
        std::cerr << "[ablate] " << j.id << " failed: the run it replays, " << j.replay_of << ", failed\n";
        ++failed;
        continue;
      }
      queue.push_back(k);
      if (++deferred_in_a_row >= queue.size()) {
        std::cerr << "[ablate] " << queue.size() << " replay jobs wait for their source runs ("
                  << replaySource(a.out, j) << ", ...): checking again in 30 s\n";
        std::this_thread::sleep_for(std::chrono::seconds(30));
        deferred_in_a_row = 0;
      }
      continue;
    }
    deferred_in_a_row = 0;
    if (jobFinished(a.out, j)) {
      std::cerr << "[ablate] " << k + 1 << "/" << jobs.size() << " " << j.id << ": finished before, skipped\n";
      ++done;
      continue;
    }
    // Another runner on this folder holds the job: it goes to the back of the queue; when
    // only held jobs are left, this runner waits for them (finished there, or free again
    // because that runner died, in which case it runs them here).
    const JobLock lock(jobLockPath(a.out, j));
    if (!lock.held()) {
      queue.push_back(k);
      if (++held_elsewhere_in_a_row >= queue.size()) {
        std::cerr << "[ablate] " << queue.size() << " jobs are running in another process (" << j.id
                  << ", ...): checking again in 5 s\n";
        std::this_thread::sleep_for(std::chrono::seconds(5));
        held_elsewhere_in_a_row = 0;
      }
      continue;
    }
    held_elsewhere_in_a_row = 0;
    if (jobFinished(a.out, j)) {  // finished by the runner that held it a moment ago
      std::cerr << "[ablate] " << k + 1 << "/" << jobs.size() << " " << j.id << ": finished by another runner\n";
      ++done;
      continue;
    }
    std::cerr << "[ablate] " << k + 1 << "/" << jobs.size() << " " << j.id << "\n";
    try {
      ensureDataset(sceneOf(g, j.scene));
      if (j.kind == AblationJob::Kind::kSweep) {
        runSweep(g, j, a.out);
      } else {
        std::vector<std::string> args = activeArgs(j, a.out);
        // A job killed midway continues from its last checkpoint.
        if (fs::exists(jobFolder(a.out, j) + "/checkpoint.json")) args.push_back("--resume");
        if (runCli(args) != 0) throw std::runtime_error(commandLine(args) + " failed");
      }
      ++done;
    } catch (const std::exception& e) {
      std::cerr << "[ablate] " << j.id << " failed: " << e.what() << "\n";
      failed_ids.insert(j.id);
      ++failed;
    }
  }
  std::cerr << "[ablate] " << done << " of " << jobs.size() << " jobs finished"
            << (failed ? ", " + std::to_string(failed) + " failed" : "") << "\n";
  if (sn > 1) {
    std::cerr << "[ablate] shard " << si << "/" << sn
              << " done; when every shard is, run: saresgs ablate merge --config " << a.config << " --out " << a.out
              << " [--inputs OTHER_OUT,...]\n";
    return failed ? 1 : 0;
  }
  const int rc = writeSummary(g, all, a.out, false);
  return failed ? 1 : rc;
}

int runMerge(const AblateArgs& a) {
  const AblationGrid g = readAblationGrid(a.config);
  const std::vector<AblationJob> all = expandGrid(g);
  checkJobArguments(g, all);
  std::stringstream ss(a.inputs);
  for (std::string in; std::getline(ss, in, ',');) {
    if (in.empty()) continue;
    if (!fs::is_directory(in)) throw InputError(in, "--inputs", "not a folder");
    if (fs::exists(a.out) && fs::equivalent(in, a.out)) continue;
    for (const auto& j : all) {
      if (jobFinished(a.out, j) || !jobFinished(in, j)) continue;
      // Copy beside, then rename: a merge cut short leaves no half-copied job behind.
      const fs::path dst = jobFolder(a.out, j), tmp = dst.string() + ".merge-tmp";
      fs::remove_all(tmp);
      fs::remove_all(dst);
      fs::create_directories(tmp.parent_path());
      fs::copy(jobFolder(in, j), tmp, fs::copy_options::recursive);
      fs::rename(tmp, dst);
      std::cerr << "[ablate] merged " << j.id << " from " << in << "\n";
    }
  }
  return writeSummary(g, all, a.out, a.allow_partial);
}

}  // namespace

void addAblateCommand(CLI::App& app, Action& action) {
  auto a = std::make_shared<AblateArgs>();
  CLI::App* sub = app.add_subcommand(
      "ablate", "Run an ablation grid of active runs and prefilter sweeps; `ablate merge` makes its tables");
  sub->add_option("--config", a->config, "Grid JSON (format: nbv/ablation.h)");
  sub->add_option("--out", a->out, "Output folder (runs/, tables/, plots/, README.md)");
  sub->add_option("--shard", a->shard, "Run only jobs i, i+n, ... (i/n)");
  sub->add_flag("--list", a->list, "Print the jobs (and their `saresgs active` command lines) and exit");
  CLI::App* merge =
      sub->add_subcommand("merge", "Collect finished jobs (from --inputs) into OUT and write the tables and plots");
  merge->add_option("--config", a->config, "Grid JSON")->required();
  merge->add_option("--out", a->out, "Output folder")->required();
  merge->add_option("--inputs", a->inputs, "Comma-separated shard output folders to copy finished jobs from");
  merge->add_flag("--allow-partial", a->allow_partial, "Exit 0 even when some jobs are not finished");
  merge->callback([&action, a] { action = [a] { return runMerge(*a); }; });
  sub->callback([&action, a, sub, merge] {
    if (merge->parsed()) return;
    if (a->config.empty() || a->out.empty()) throw CLI::RequiredError("ablate needs --config and --out");
    action = [a] { return runAblate(*a); };
  });
}

}  // namespace saresgs::apps
