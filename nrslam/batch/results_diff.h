// batch: two evaluations of the same runs side by side, run for run: before and after a change
// of code (which a sweep cannot vary), or the same options on two machines. Runs pair by
// sequence and sweep point.
#pragma once

#include <map>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "nrslam/batch/paired_comparison.h"
#include "nrslam/batch/results.h"

namespace nrslam {

struct ResultsDiff {
  struct Row {
    std::string key;                 // RunKey
    std::optional<RunResult> a, b;   // absent: the run is not in that evaluation
    bool comparable() const { return a && b && a->complete() && b->complete(); }
  };
  std::vector<Row> rows;             // A's runs in A's order, then B's runs A lacks
  // Over the comparable rows only (single runs are chaotic: the counts say more than the means).
  int comparable = 0;
  double mean_rmse_a_mm = 0, mean_rmse_b_mm = 0, median_rmse_a_mm = 0, median_rmse_b_mm = 0;
  double mean_ate_a_mm = -1, mean_ate_b_mm = -1;  // negative: some comparable run has none
  RmseChangeCounts b_against_a;
  // Runs in both that one evaluation did not track to the end (lost or failed).
  int short_only_a = 0, short_only_b = 0, short_both = 0;
  int only_in_a = 0, only_in_b = 0;
  // What the runs both evaluations have were run with, where it differs (read from their
  // config.json): "path: value in A → value in B" → how many runs, e.g. a --set given to one
  // evaluation only. Runs whose config is missing or unreadable are counted apart.
  std::map<std::string, int> option_changes;
  int configs_compared = 0;          // runs in both whose two configs were read
  int other_sequence = 0;            // runs of the same name on another sequence folder
  int configs_unread = 0;
};

ResultsDiff DiffResults(const std::vector<RunResult>& a, const std::vector<RunResult>& b);

// The per-run table and the summary, naming the evaluations `name_a` and `name_b`.
void PrintDiff(const ResultsDiff& diff, const std::string& name_a, const std::string& name_b, std::ostream& out);

}  // namespace nrslam
