// batch: what an evaluation runs — the renders of the manifest's presets into the cache and
// one nrslam_run per (sequence, sweep point) — and running it with a few processes at a time.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "nrslam/batch/manifest.h"

namespace nrslam {

// One swept option: every value is run, in a grid with the other sweeps. A run option
// ("deformation.k") changes how each sequence is run; a simulator option ("simulate." and its
// nrslam_simulate path, e.g. "simulate.deformation.amplitude_mm") changes the data: each value
// renders the manifest's presets anew, as a study of how the system copes with, say, a larger
// deformation needs.
struct Sweep {
  std::string path;                 // resolved: a run option path, or "simulate." + a simulator path
  std::vector<std::string> values;  // as given on the command line
};
// Parses "name=v1,v2,v3" (name as for ResolveRunOption, or "simulate." and a simulator option
// by its path or unique last name); throws Error when malformed or unknown.
Sweep ParseSweep(const std::string& text);
// Whether a sweep point's "path=value" sets a simulator option ("simulate.…").
bool IsSimulatorAssignment(const std::string& assignment);
// Such an assignment as nrslam_simulate --set takes it: "simulate.deformation.amplitude_mm=5"
// gives "deformation.amplitude_mm=5".
std::string SimulatorAssignment(const std::string& assignment);

// A simulator assignment that sets the scene seed: "seed=3".
bool IsSeedAssignment(const std::string& assignment);
// Scene seeds as --seeds gives them: "1-3,7" is 1, 2, 3, 7, in that order. Throws Error when
// malformed or when a seed comes twice.
std::vector<uint64_t> ParseSeedList(const std::string& text);
// The manifest with each rendered preset once per seed, named "<name>-seed<s>", its simulator
// seed set to s whatever the manifest gave: single renderings are chaotic, and the seed groups
// of the results summarise such copies. Sequences on disk and external results (scored
// against one rendering) stay as they are. Throws Error when a new name is already taken.
Manifest WithSceneSeeds(const Manifest& manifest, const std::vector<uint64_t>& seeds);

// A sequence made before its runs, into the cache: a preset rendered (nrslam_simulate) or a
// dataset imported (nrslam_import). Its folder name is keyed by what makes it.
struct PrepareJob {
  std::string description;              // "sim-3" or "hamlyn /data/h01", for messages
  bool import = false;                  // nrslam_import rather than nrslam_simulate
  std::vector<std::string> arguments;   // the program's arguments, without --out
  std::filesystem::path folder;         // cache/<name>-<hash of the arguments>
};

struct RunJob {
  std::string sequence;                      // manifest name
  std::vector<std::string> point;            // the sweep point: "path=value" per sweep
  std::string label;                         // "k=0.5,max_degree_D=3", or "" without sweeps
  std::filesystem::path sequence_folder;
  std::filesystem::path run_folder;          // out/runs/<sequence>[/<label>]
  std::vector<std::string> arguments;        // the program's arguments (no program name)
  Json options;                              // the options those arguments resolve to (null: external)
  // An external result scored by `nrslam_eval score` instead of an nrslam_run: what its
  // config.json records (ToJson of system/external_result.h); null for a run of ours.
  Json external;
  int prepare = -1;                          // index into EvaluationPlan::prepares, or -1
  bool is_external() const { return !external.is_null(); }
};

struct EvaluationPlan {
  std::vector<PrepareJob> prepares;
  std::vector<RunJob> runs;
};

// How messages and tables name a run: "sequence", or "sequence [sweep point]".
std::string RunName(const std::string& sequence, const std::string& label);

// Expands the manifest × the sweep grid (an external result is scored once, at no sweep point); `extra` assignments apply to every run (after the
// manifest's). Validates every run's options.
EvaluationPlan PlanEvaluation(const Manifest& manifest, const std::vector<std::string>& extra,
                              const std::vector<Sweep>& sweeps, const std::filesystem::path& out,
                              const std::filesystem::path& cache);

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
