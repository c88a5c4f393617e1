// batch: runs that differ only in the simulator's scene seed, summarised together. Single
// runs are chaotic (docs/mapping.md), so a preset is best judged over several renderings of
// it (e.g. colon-seeds-monocular.json: seeds 1–3 of each colon preset); this gives, per
// preset, mode and sweep point, the mean and spread of the RMSE over its seeds.
#pragma once

#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include "nrslam/batch/evaluation_plan.h"
#include "nrslam/batch/results.h"

namespace nrslam {

struct SeedGroup {
  // The preset, any other simulator settings, "rigid" for a rigid group and the sweep point:
  // "sim-3", "sim-3 camera.width=320 rigid [k=2]"; and where two groups would still share a
  // name (their options differ per sequence), the first member: "sim-3 (mine-1, ...)".
  std::string name;
  std::vector<std::string> sequences;  // manifest names of the members, in manifest order
  std::vector<std::string> seeds;      // their scene seeds, as the manifest gives them
  // Over the members scored against ground truth (not failed, some frame evaluated), each by
  // its own RMSE over the frames it tracked, as the results table gives it. A run that loses
  // the track is scored on fewer frames: `to_end` says how many were tracked to the end.
  int scored = 0, to_end = 0;
  double mean_rmse_mm = 0, sd_rmse_mm = 0, median_rmse_mm = 0, min_rmse_mm = 0, max_rmse_mm = 0;
  double mean_ate_mm = -1;        // negative: a scored member has no trajectory error
  double mean_map_scale_mm = -1;  // RMSE at one scale per map; negative: a scored member has none recorded
};

// Groups the runs of rendered presets whose render settings other than the seed and whose
// run options are all equal, in the order of each group's first run. Only groups of two or
// more runs are returned. `results` is CollectResults(plan): one per run, in order.
std::vector<SeedGroup> GroupBySeed(const EvaluationPlan& plan, const std::vector<RunResult>& results);

std::vector<std::string> SeedGroupHeader();
std::vector<std::string> SeedGroupCells(const SeedGroup& group);
// Prints nothing without groups.
void PrintSeedGroups(const std::vector<SeedGroup>& groups, std::ostream& out);
// The groups as CSV, one row each (members separated by spaces; empty fields where no member
// was scored, and no sd from a single one).
void WriteSeedGroups(const std::vector<SeedGroup>& groups, const std::filesystem::path& file);

}  // namespace nrslam
