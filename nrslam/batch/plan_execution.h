// batch: running an evaluation's plan (evaluation_plan.h) — preparing its sequences into the
// cache, then its runs a few processes at a time, each one's failure recorded in its folder —
// or writing it out as shell commands for a scheduler; and telling which runs finished before.
#pragma once

#include <atomic>
#include <filesystem>
#include <functional>
#include <string>

#include "nrslam/batch/evaluation_plan.h"

namespace nrslam {

struct Programs {
  std::filesystem::path simulate;  // nrslam_simulate
  std::filesystem::path run;       // nrslam_run
  std::filesystem::path import;    // nrslam_import
  std::filesystem::path eval;      // nrslam_eval, which scores external results
};

// The shell command that prepares a sequence into the cache (atomically, so concurrent or
// interrupted ones never leave a half-written sequence behind), if not there yet.
std::string PrepareShellLine(const PrepareJob& prepare, const Programs& programs);
// The shell command of one run, self-contained: prepares its sequence first if needed.
std::string RunShellLine(const EvaluationPlan& plan, const RunJob& run, const Programs& programs);

// A run whose folder already holds a summary.json, and a config.json with this run's options,
// sequence and code fingerprint (CodeFingerprint()), finished before: it is not run again. A
// folder from other options (an --out reused after changing --set or the manifest) or other
// code is run again rather than reported stale.
bool RunIsFinished(const RunJob& run);

// What ExecutePlan would do, for `nrslam_eval --dry-run`: a line counting the sequences to
// render or import and those already in the cache, a line counting the runs to run and those
// finished before (RunIsFinished), then one line per sequence and per run with its state.
std::string DescribePlan(const EvaluationPlan& plan);

// A run records the code fingerprint of the nrslam_run that made it, and RunIsFinished counts
// it only when that is this program's. An nrslam_run built from other code (one tool rebuilt
// and not the others) would have every run it finishes count as unfinished, and run again by
// every evaluation: throws Error naming both fingerprints. Nothing happens when the program
// does not answer --version; the runs then fail and say why.
void CheckRunProgramCode(const std::filesystem::path& run_program);

// Prepares what is missing, then runs what is not finished, `jobs` processes at a time.
// `progress` gets one line per finished step. Failures are recorded in the run folders
// (failure.json), never thrown; only an nrslam_run of other code throws, before anything
// is run (CheckRunProgramCode). A run still going after `run_timeout_seconds` (wall clock;
// 0: no limit) is killed and recorded as failed, so one sequence that hangs cannot stall a
// batch; it is run again by the next evaluation into the same folder. Once `*stop` is true
// (nrslam_eval sets it on SIGINT and SIGTERM) nothing more starts, the running programs are
// sent SIGTERM, and those runs are left unfinished without a failure: the next evaluation
// into the same folder runs them.
void ExecutePlan(const EvaluationPlan& plan, const Programs& programs, int jobs,
                 const std::function<void(const std::string&)>& progress, double run_timeout_seconds = 0,
                 const std::atomic<bool>* stop = nullptr);

}  // namespace nrslam
