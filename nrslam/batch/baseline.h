// batch: the regression baseline: a results file's RMSE and frames per run with the tolerance
// a later evaluation is allowed, and the check of an evaluation against it (nrslam_eval
// --write-baseline / --check-baseline).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "nrslam/batch/results.h"
#include "nrslam/util/json_options.h"

namespace nrslam {

// A regression baseline: per run key (sequence [label]), RMSE and frames tracked, plus the
// tolerance a later result is allowed.
struct BaselineTolerance {
  double rmse_relative = 0.10;    // RMSE may grow by this fraction ...
  double rmse_absolute_mm = 0.02; // ... plus this much (noise floor on near-zero RMSE)
  int frames_tracked = 0;         // frames tracked may drop by this many
  // All runs together: the geometric mean of their RMSE ratios (now ÷ before) may exceed 1 by
  // this fraction; 0 = no such check. Why: monocular runs are chaotic (one run can move by a
  // third when nothing is wrong), so a per-run tolerance that lets that through misses a change
  // that makes every run 15 % worse; over a few dozen runs the chaos averages out.
  double pooled_rmse_relative = 0;
};
Json MakeBaseline(const std::vector<RunResult>& results, const BaselineTolerance& tolerance);

struct BaselineCheck {
  bool passed = true;
  std::string report;  // a table of every baselined run: before, now, verdict
};
// Fails on a run that is worse than tolerated, failed, or missing from the results, or on
// runs worse together than the pooled tolerance allows (the report always gives that ratio,
// with the better / same / worse counts and the signed-rank test, as `nrslam_eval diff`). Throws
// Error when `baseline` lacks what a check needs (a tolerance, and per run its RMSE and frames).
BaselineCheck CheckBaseline(const std::vector<RunResult>& results, const Json& baseline);
// A baseline file, read and checked as CheckBaseline needs it: nrslam_eval reads it before any
// run, so a wrong path or a damaged file fails at once and not after the evaluation.
Json ReadBaseline(const std::filesystem::path& file);

}  // namespace nrslam
