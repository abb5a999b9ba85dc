#include "nbv/eval/ablation_runner.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <set>
#include <sstream>
#include <thread>

#include "geometry/error.h"
#include "geometry/image/image.h"
#include "geometry/io/atomic_file.h"
#include "geometry/synth/from_manifest.h"
#include "nbv/eval/prefilter_sweep.h"

namespace saresgs {

namespace {

namespace fs = std::filesystem;

// Generates a missing synthetic dataset once, even when several shards start together:
// an exclusive lock on DATASET.lock, then a second look.
void ensureDataset(const AblationScene& sc, const CommandRunner& run) {
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
    rc = run({"scene", "--layout", sc.layout, "--seed", std::to_string(sc.scene_seed), "--out", sc.dataset});
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

}  // namespace

std::string commandLineText(const std::vector<std::string>& args) {
  std::string s = "saresgs";
  for (const auto& a : args) s += " " + (a.find_first_of(" \"'") == std::string::npos ? a : "'" + a + "'");
  return s;
}

std::vector<std::string> activeJobArgs(const AblationJob& j, const std::string& out) {
  std::vector<std::string> a{"active"};
  a.insert(a.end(), j.args.begin(), j.args.end());
  if (!j.replay_of.empty()) a.insert(a.end(), {"--replay", replaySource(out, j)});
  a.insert(a.end(), {"--out", jobFolder(out, j)});
  return a;
}

ShardOutcome runAblationJobs(const AblationGrid& g, const std::vector<AblationJob>& jobs, const std::string& out,
                             const CommandRunner& run) {
  fs::create_directories(out + "/runs");
  ShardOutcome r;
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
    if (!j.replay_of.empty() && !jobFinished(out, j) && !fs::exists(replaySource(out, j))) {
      if (failed_ids.count(j.replay_of)) {
        std::cerr << "[ablate] " << j.id << " failed: the run it replays, " << j.replay_of << ", failed\n";
        ++r.failed;
        continue;
      }
      queue.push_back(k);
      if (++deferred_in_a_row >= queue.size()) {
        std::cerr << "[ablate] " << queue.size() << " replay jobs wait for their source runs (" << replaySource(out, j)
                  << ", ...): checking again in 30 s\n";
        std::this_thread::sleep_for(std::chrono::seconds(30));
        deferred_in_a_row = 0;
      }
      continue;
    }
    deferred_in_a_row = 0;
    if (jobFinished(out, j)) {
      std::cerr << "[ablate] " << k + 1 << "/" << jobs.size() << " " << j.id << ": finished before, skipped\n";
      ++r.done;
      continue;
    }
    // Another runner on this folder holds the job: it goes to the back of the queue; when
    // only held jobs are left, this runner waits for them (finished there, or free again
    // because that runner died, in which case it runs them here).
    const JobLock lock(jobLockPath(out, j));
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
    if (jobFinished(out, j)) {  // finished by the runner that held it a moment ago
      std::cerr << "[ablate] " << k + 1 << "/" << jobs.size() << " " << j.id << ": finished by another runner\n";
      ++r.done;
      continue;
    }
    std::cerr << "[ablate] " << k + 1 << "/" << jobs.size() << " " << j.id << "\n";
    try {
      ensureDataset(sceneOf(g, j.scene), run);
      if (j.kind == AblationJob::Kind::kSweep) {
        runSweep(g, j, out);
      } else {
        std::vector<std::string> args = activeJobArgs(j, out);
        // A job killed midway continues from its last checkpoint.
        if (fs::exists(jobFolder(out, j) + "/checkpoint.json")) args.push_back("--resume");
        if (run(args) != 0) throw std::runtime_error(commandLineText(args) + " failed");
      }
      ++r.done;
    } catch (const std::exception& e) {
      std::cerr << "[ablate] " << j.id << " failed: " << e.what() << "\n";
      failed_ids.insert(j.id);
      ++r.failed;
    }
  }
  return r;
}

void mergeAblationInputs(const std::vector<AblationJob>& jobs, const std::vector<std::string>& inputs,
                         const std::string& out) {
  for (const std::string& in : inputs) {
    if (in.empty()) continue;
    if (!fs::is_directory(in)) throw InputError(in, "--inputs", "not a folder");
    if (fs::exists(out) && fs::equivalent(in, out)) continue;
    for (const auto& j : jobs) {
      if (jobFinished(out, j) || !jobFinished(in, j)) continue;
      // Copy beside, then rename: a merge cut short leaves no half-copied job behind.
      const fs::path dst = jobFolder(out, j), tmp = dst.string() + ".merge-tmp";
      fs::remove_all(tmp);
      fs::remove_all(dst);
      fs::create_directories(tmp.parent_path());
      fs::copy(jobFolder(in, j), tmp, fs::copy_options::recursive);
      fs::rename(tmp, dst);
      std::cerr << "[ablate] merged " << j.id << " from " << in << "\n";
    }
  }
}

AblationSummary writeAblationSummary(const AblationGrid& g, const std::vector<AblationJob>& jobs,
                                     const std::string& out) {
  const std::vector<JobResult> results = loadFinishedJobs(out, jobs);
  AblationSummary s;
  s.finished = results.size();
  for (const auto& j : jobs)
    if (!jobFinished(out, j)) s.missing.push_back(j.id);
  fs::create_directories(out + "/tables");
  fs::create_directories(out + "/plots");
  std::ostringstream page;
  page << "# Ablation results\n\nGrid: `" << g.source << "`, " << results.size() << " of " << jobs.size()
       << " jobs finished. Made by `saresgs ablate --config " << g.source << " --out " << out
       << "` (or its shards and `saresgs ablate merge`). Each job's own results are in `runs/<job>/`.\n\n";
  if (!s.missing.empty()) {
    page << "**Partial:** missing";
    for (const auto& m : s.missing) page << " `" << m << "`";
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
  return s;
}

}  // namespace saresgs
