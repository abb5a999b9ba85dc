#pragma once
// Running an ablation grid (nbv/eval/ablation.h) as independent jobs: one shard's queue with
// a lock per job (two runners on one folder never run the same job; a killed runner's job
// is resumed by the next from its checkpoint), replay jobs deferred until their source run
// has finished, missing synthetic datasets generated once; the merge of shard folders; and
// the tables, plots and index page of the finished jobs. The front end parses the flags and
// says how an active job runs (`saresgs active ARGS` in process, `runJob`).
#include <functional>
#include <string>
#include <vector>

#include "nbv/eval/ablation.h"

namespace saresgs {

// Runs one command line of the program (`active ...`, `scene ...`, without the program's
// name); returns its exit code.
using CommandRunner = std::function<int(const std::vector<std::string>& args)>;

// `saresgs active` arguments of an active job, writing into OUT/runs/<id> (and replaying
// its source run when it has one).
std::vector<std::string> activeJobArgs(const AblationJob& j, const std::string& out);
// "saresgs ARGS" with the arguments that need it quoted: what a person can paste.
std::string commandLineText(const std::vector<std::string>& args);

struct ShardOutcome {
  int done = 0;    // finished, before or now
  int failed = 0;  // failed now (or left because the run they replay failed)
};

// Runs the jobs (one shard's, from shardJobs) into OUT/runs/, skipping finished ones and
// waiting for jobs another runner holds. Progress and failures go to stderr.
ShardOutcome runAblationJobs(const AblationGrid& g, const std::vector<AblationJob>& jobs, const std::string& out,
                             const CommandRunner& run);

// Copies every job finished in one of `inputs` (and not in OUT) into OUT, each through a
// temporary folder renamed into place. Throws InputError for an input that is no folder.
void mergeAblationInputs(const std::vector<AblationJob>& jobs, const std::vector<std::string>& inputs,
                         const std::string& out);

struct AblationSummary {
  std::size_t finished = 0;
  std::vector<std::string> missing;  // ids of the jobs not finished
};

// The tables (.md and .csv) and plots (.png) under OUT, and an index page beside them (every table and plot, and
// what is missing) from the finished jobs of `jobs`.
AblationSummary writeAblationSummary(const AblationGrid& g, const std::vector<AblationJob>& jobs,
                                     const std::string& out);

}  // namespace saresgs
