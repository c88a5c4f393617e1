// batch: the results of an evaluation — one row per run, read back from the run folders —
// as a table and as results.json / results.csv, and per swept value.
#pragma once

#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "nrslam/batch/evaluation_plan.h"
#include "nrslam/batch/paired_comparison.h"
#include "nrslam/system/run_files.h"
#include "nrslam/util/json_options.h"

namespace nrslam {

struct RunResult {
  std::string sequence;
  std::string label;                // sweep point, "" without sweeps
  std::vector<std::string> point;   // "path=value" per swept option
  std::string status = "failed";    // "ok", "lost", "not_initialised" (RunStatus) or "failed"
  std::string error;                // why it failed
  int init_frame = -1, frames_tracked = 0, frames_total = 0;
  int frames_evaluated = 0;         // frames with ground truth; 0: no RMSE (e.g. a plain video)
  InputEffects input;               // what damaged or unusual input did to the run (RunSummary)
  double rmse_mm = 0, rmse_median_mm = 0, fps = 0;
  double peak_memory_mb = -1;       // the run process's peak resident memory; negative: not recorded
  double ate_mm = -1;               // similarity-aligned trajectory error; negative: none
  double rmse_flat_mm = -1;         // what a map at one depth scores on the same points; negative: not recorded
  // The same frames at one scale per map (its drift counts) and at each frame's median ratio
  // (eval/depth_evaluation.h, OtherAlignments); negative: not recorded.
  double rmse_map_scale_mm = -1, rmse_median_scale_mm = -1;
  // How far from the map's scale new points were born (eval/birth_errors.h): how many were
  // scored, and the mean and median of their log depth errors (none: no birth scored).
  int births_evaluated = 0;
  std::optional<double> birth_log_error_mean, birth_log_error_median;
  DepthChange map_depth;  // how far the map that moved most drifted in depth (RunSummary)
  int maps_given_up = 0;  // maps ended for their depth change (RunSummary)
  std::string run_folder;
  std::string revision;             // the code that made the run (its config.json); "" when not recorded
  std::string code;                 // that code's fingerprint (CodeFingerprint()); "" when not recorded
  // A run that ends without tracking: from which frame, and why (the runner's note); for a run
  // that never initialised, frame -1 and the last frame's note. Empty when it ends tracking.
  int stop_frame = -1;
  std::string stop_reason;
  bool evaluated() const { return frames_evaluated > 0; }
  // Tracked to the end with ground truth: the runs whose RMSEs compare like with like.
  bool complete() const { return status == "ok" && evaluated(); }
};

// How tables and baselines name a run: "sequence", or "sequence [sweep point]".
std::string RunKey(const RunResult& result);
// The distinct revisions that made `revisions` (RunResult::revision; "" = not recorded), sorted
// and joined by ", ", e.g. "1a2b3c4d5e6f, not recorded": what code a set of results came from.
std::string DescribeRevisions(const std::vector<std::string>& revisions);
// The same over the runs that did not fail (a failed run wrote no config.json to name its
// code); "none: every run failed" when every one did.
std::string DescribeRevisions(const std::vector<RunResult>& results);
// Whether two sets of runs were made by the same code, by their code fingerprints
// (RunResult::code): "the same code" when every run on both sides records one and the same
// fingerprint (their commits may still differ, in documentation or tests), "other code" when
// every run records one and they differ, "" when a run does not record one (older runs).
std::string CompareCode(const std::vector<std::string>& codes_a, const std::vector<std::string>& codes_b);
// A finished run's status from its figures: "not_initialised", "lost" (it ends without tracking,
// or left frames after its initialisation untracked) or "ok". Image dropouts skipped with the
// map kept and unreadable frames do not make it "lost": they are the input's, which every run
// of the sequence meets.
std::string RunStatus(const RunResult& figures);
// Where and why a run that ends without tracking stopped: "lost from frame 12: only 7 points
// left after outlier rejection" or "never initialised: …"; "" when it ends tracking or failed.
std::string StopText(const RunResult& result);
// What the table prints under a run that did not fail, one line each: its StopText and what
// unreadable input and image dropouts cost it. Empty for a run that lost nothing.
std::vector<std::string> RunNotes(const RunResult& result);
// An RMSE figure of `result` as a table shows it: "no GT" when frames were tracked but none had
// ground truth, "sparse GT" when some had but too sparse to score, "-" when no frame was tracked.
std::string RmseCell(const RunResult& result, double rmse_mm);
// An RMSE that older results may lack (the flat map's, the map-scale one) as a table shows
// it: "-" when not recorded (negative).
std::string RecordedRmseCell(const RunResult& result, double rmse_mm);
// The frame a run initialised at, "-" when it never did.
std::string InitFrameCell(const RunResult& result);
// The mean of figures that may each be missing (negative): negative when any is, or none given.
double MeanOfRecorded(const std::vector<double>& figures);
// A figure in mm that may be missing, such as a trajectory error or a mean of the map-scale
// RMSE, as a table shows it: "-" when there is none (negative).
std::string MillimetresCell(double mm);
// A run's peak memory as a table shows it: whole MB, "-" when not recorded (negative).
std::string MegabytesCell(double mb);
// The same figure as a CSV field: empty when there is none (negative).
std::string RecordedField(double value);

// Reads each run's summary.json (or failure.json) from its folder.
std::vector<RunResult> CollectResults(const EvaluationPlan& plan);

Json ToJson(const std::vector<RunResult>& results);
std::vector<RunResult> ResultsFromJson(const Json& json);

// results.json and results.csv in `folder`, and the printed tables (PrintResults) as
// results.md (Markdown) and results.tex (a LaTeX tabular, booktabs).
void WriteResults(const std::vector<RunResult>& results, const std::filesystem::path& folder);
// Reads a folder's results.json; throws Error if it has none.
std::vector<RunResult> ReadResults(const std::filesystem::path& folder);

// One value of one swept option, over the sequences tracked to the end at every point of the
// sweep, so that every value is averaged over the same sequences (a value that loses a hard
// sequence would otherwise look better for it).
struct SweepValueSummary {
  std::string option, value;
  int runs = 0;                  // runs averaged: one per sequence complete at every point
  double mean_rmse_mm = 0, median_rmse_mm = 0;
  double mean_ate_mm = -1;       // negative: one of those runs has no trajectory error
  double mean_map_scale_mm = -1; // RMSE at one scale per map; negative: one of those runs has none recorded
  int short_runs = 0;            // runs at this value, over every sequence, failed or lost before the end
  // Paired with the option's default (nrslam_run's, when it is one of the swept values): each
  // run against the run of the same sequence and other swept values at the default, over the
  // same sequences as the means. Single runs are chaotic, so how many moved which way says
  // more than a difference of means. "Same" is equal to the printed 0.001 mm.
  bool is_default = false;
  bool paired = false;           // the default is among the swept values and this is not it
  RmseChangeCounts against_default;
};
// Per option, values in numeric order when they are numbers ("5" before "10"), else as text.
std::vector<SweepValueSummary> SummariseSweep(const std::vector<RunResult>& results);
// The columns of that summary as the text table and the HTML report show it, and one row's cells.
std::vector<std::string> SweepSummaryHeader();
std::vector<std::string> SweepSummaryCells(const SweepValueSummary& summary);

// The table a person reads: sequence, [sweep point], status, init frame, tracked/total,
// RMSE mean and median (mm), trajectory error (mm), fps; under it why each failed run failed
// and where and why each run that ends without tracking stopped. With sweeps, also
// SummariseSweep's table.
void PrintResults(const std::vector<RunResult>& results, std::ostream& out);

}  // namespace nrslam
