// batch: what an evaluation runs — the renders of the manifest's presets into the cache and
// one nrslam_run per (sequence, sweep point) — and running it with a few processes at a time.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "nrslam/batch/manifest.h"

namespace nrslam {

// One swept option: every value is run, in a grid with the other sweeps.
struct Sweep {
  std::string path;                 // resolved run option path
  std::vector<std::string> values;  // as given on the command line
};
// Parses "name=v1,v2,v3" (name as for ResolveRunOption); throws Error when malformed.
Sweep ParseSweep(const std::string& text);

struct RenderJob {
  std::string preset;
  std::vector<std::string> simulate;  // simulator assignments
  std::filesystem::path folder;       // the cached sequence: cache/<preset>-<hash of options>
};

struct RunJob {
  std::string sequence;                      // manifest name
  std::vector<std::string> point;            // the sweep point: "path=value" per sweep
  std::string label;                         // "k=0.5,max_degree_D=3", or "" without sweeps
  std::filesystem::path sequence_folder;
  std::filesystem::path run_folder;          // out/runs/<sequence>[/<label>]
  std::vector<std::string> arguments;        // nrslam_run's arguments (no program name)
  int render = -1;                           // index into EvaluationPlan::renders, or -1
};

struct EvaluationPlan {
  std::vector<RenderJob> renders;
  std::vector<RunJob> runs;
};

// Expands the manifest × the sweep grid; `extra` assignments apply to every run (after the
// manifest's). Validates every run's options.
EvaluationPlan PlanEvaluation(const Manifest& manifest, const std::vector<std::string>& extra,
                              const std::vector<Sweep>& sweeps, const std::filesystem::path& out,
                              const std::filesystem::path& cache);

struct Programs {
  std::filesystem::path simulate;  // nrslam_simulate
  std::filesystem::path run;       // nrslam_run
};

// The shell command that renders a preset into the cache (atomically, so concurrent or
// interrupted renders never leave a half-written sequence behind), if not there yet.
std::string RenderShellLine(const RenderJob& render, const Programs& programs);
// The shell command of one run, self-contained: renders its sequence first if needed.
std::string RunShellLine(const EvaluationPlan& plan, const RunJob& run, const Programs& programs);

// A run whose folder already holds a summary.json finished before: it is not run again.
bool RunIsFinished(const RunJob& run);

// Renders what is missing, then runs what is not finished, `jobs` processes at a time.
// `progress` gets one line per finished step. Failures are recorded in the run folders
// (failure.json), never thrown.
void ExecutePlan(const EvaluationPlan& plan, const Programs& programs, int jobs,
                 const std::function<void(const std::string&)>& progress);

}  // namespace nrslam
