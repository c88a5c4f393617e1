// batch: each deformable run of an evaluation set beside its rigid baseline, the run of the
// same sequence whose options differ only in `tracking.rigid` (e.g. the manifest's "sim-3"
// and "sim-3-rigid", at the same sweep point). Each run's own RMSE covers its own frames, and a
// rigid run on a deforming scene often stops early, scored only on the first frames, before
// much has moved. So both are also scored over the frames both evaluated, and on the points
// both report (the same tracks, eval/common_points.h): rigid flags much of a deforming scene
// as outliers and is scored on what still fits.
#pragma once

#include <filesystem>
#include <map>
#include <ostream>
#include <string>
#include <vector>

#include "nrslam/batch/evaluation_plan.h"
#include "nrslam/batch/paired_comparison.h"
#include "nrslam/batch/results.h"
#include "nrslam/eval/common_points.h"

namespace nrslam {

// A run folder's per-frame RMSE (mm) from its metrics.csv: only the frames that have one.
std::map<int, double> ReadFrameRmse(const std::filesystem::path& run_folder);

// The mean of two runs' per-frame RMSEs over the frames both have one.
struct CommonFramesRmse {
  int frames = 0;
  double a_mm = 0, b_mm = 0;  // 0 when no frame is common
};
CommonFramesRmse MeanOverCommonFrames(const std::map<int, double>& a, const std::map<int, double>& b);

struct RigidComparison {
  RunResult deformable, rigid;
  CommonFramesRmse common;             // deformable as a, rigid as b
  CommonPointsComparison same_points;  // likewise; no frames when a run folder lacks points.csv
};

// Pairs every deformable run with the first rigid run of the same sequence folder whose
// options are otherwise equal (a sweep of `tracking.rigid` itself pairs too), when both were
// evaluated against ground truth. `results` is CollectResults(plan): one per run, in order.
std::vector<RigidComparison> CompareWithRigid(const EvaluationPlan& plan, const std::vector<RunResult>& results);

// Over all pairs, how often the deformable run is the more accurate ("better": its RMSE below
// its rigid partner's, "same" to the printed 0.001 mm): by each run's own RMSE, over the common
// frames, and on the same points. A pair without common frames (or points) is left out of that
// count. Single runs are chaotic, so over many renderings these counts say more than any one row.
struct RigidComparisonTally {
  RmseChangeCounts own, common, same_points;
};
RigidComparisonTally TallyRigidComparisons(const std::vector<RigidComparison>& comparisons);
// One line: each count with its sign test.
std::string RigidComparisonTallyText(const RigidComparisonTally& tally);

// The columns as the text table, the CSV file and the HTML report show them, and one pair's
// cells. The ratio is rigid / deformable: above 1, the deformable run is the more accurate.
std::vector<std::string> RigidComparisonHeader();
std::vector<std::string> RigidComparisonCells(const RigidComparison& comparison);

// A titled text table and the tally; nothing when there are no pairs.
void PrintRigidComparison(const std::vector<RigidComparison>& comparisons, std::ostream& out);
// `file` as CSV (header only when there are no pairs).
void WriteRigidComparison(const std::vector<RigidComparison>& comparisons, const std::filesystem::path& file);

}  // namespace nrslam
