#include "nrslam/batch/results_diff.h"

#include <algorithm>
#include <filesystem>
#include <map>

#include "nrslam/system/system_options.h"
#include "nrslam/util/json_options.h"
#include "nrslam/util/median.h"
#include "nrslam/util/text_table.h"

namespace nrslam {
namespace {

// What a run ran with, from its config.json. kNone for a run that has no options to compare
// (failed, scored from another system, or a result with no folder).
struct RunConfig {
  enum Kind { kNone, kRead, kUnreadable } kind = kNone;
  Json options;           // parsed back through SystemOptions: an option newer than the run reads as its default
  std::string sequence;
};

RunConfig ReadRunConfig(const RunResult& run) {
  const std::filesystem::path file = std::filesystem::path(run.run_folder) / "config.json";
  if (run.run_folder.empty() || run.status == "failed" || !std::filesystem::exists(file)) return {};
  try {
    const Json config = ReadJsonFile(file);
    if (!config.contains("options")) return {};
    return {RunConfig::kRead, OptionsFromJson<SystemOptions>(config.at("options"), file.string()),
            config.value("sequence", "")};
  } catch (const std::exception&) {
    return {RunConfig::kUnreadable, Json(), ""};
  }
}

// Counts, into `diff`, how the options of the runs A and B both have differ.
void CountConfigChanges(const RunResult& a, const RunResult& b, ResultsDiff* diff) {
  const RunConfig config_a = ReadRunConfig(a), config_b = ReadRunConfig(b);
  if (config_a.kind == RunConfig::kUnreadable || config_b.kind == RunConfig::kUnreadable) {
    ++diff->configs_unread;
    return;
  }
  if (config_a.kind != RunConfig::kRead || config_b.kind != RunConfig::kRead) return;
  ++diff->configs_compared;
  if (config_a.sequence != config_b.sequence) ++diff->other_sequence;
  // The same leaves in the same order both ways: "path=value in B" and "path=value in A".
  const std::vector<std::string> to_b = ChangedAssignments(config_a.options, config_b.options);
  const std::vector<std::string> to_a = ChangedAssignments(config_b.options, config_a.options);
  for (size_t i = 0; i < to_b.size(); ++i) {
    const size_t equals = to_b[i].find('=');
    ++diff->option_changes[to_b[i].substr(0, equals) + ": " + to_a[i].substr(equals + 1) + " → " +
                           to_b[i].substr(equals + 1)];
  }
}

// RMSE and frames of one side of a row, as the table shows them.
std::vector<std::string> SideCells(const std::optional<RunResult>& run) {
  if (!run) return {"absent", "-", "-"};
  if (run->status == "failed") return {"FAILED", "-", "-"};
  return {RmseCell(*run, run->rmse_mm), std::to_string(run->frames_tracked) + "/" + std::to_string(run->frames_total),
          MillimetresCell(run->ate_mm)};
}

}  // namespace

ResultsDiff DiffResults(const std::vector<RunResult>& a, const std::vector<RunResult>& b) {
  ResultsDiff diff;
  std::map<std::string, size_t> row_of;
  for (const RunResult& run : a) {
    row_of[RunKey(run)] = diff.rows.size();
    diff.rows.push_back({RunKey(run), run, std::nullopt});
  }
  for (const RunResult& run : b) {
    const auto found = row_of.find(RunKey(run));
    if (found != row_of.end()) {
      diff.rows[found->second].b = run;
    } else {
      diff.rows.push_back({RunKey(run), std::nullopt, run});
    }
  }
  std::vector<double> rmse_a, rmse_b, ate_a, ate_b;
  for (const ResultsDiff::Row& row : diff.rows) {
    if (!row.a || !row.b) {
      ++(row.a ? diff.only_in_a : diff.only_in_b);
      continue;
    }
    CountConfigChanges(*row.a, *row.b, &diff);
    if (!row.comparable()) {
      const bool a_short = !row.a->complete(), b_short = !row.b->complete();
      ++(a_short && b_short ? diff.short_both : a_short ? diff.short_only_a : diff.short_only_b);
      continue;
    }
    rmse_a.push_back(row.a->rmse_mm);
    rmse_b.push_back(row.b->rmse_mm);
    ate_a.push_back(row.a->ate_mm);
    ate_b.push_back(row.b->ate_mm);
    diff.b_against_a.Add(row.a->rmse_mm, row.b->rmse_mm);
  }
  diff.comparable = static_cast<int>(rmse_a.size());
  if (diff.comparable > 0) {
    diff.mean_rmse_a_mm = Mean(rmse_a);
    diff.mean_rmse_b_mm = Mean(rmse_b);
    diff.median_rmse_a_mm = Median(rmse_a);
    diff.median_rmse_b_mm = Median(rmse_b);
    const auto all_present = [](const std::vector<double>& ate) {
      return std::all_of(ate.begin(), ate.end(), [](double mm) { return mm >= 0; });
    };
    if (all_present(ate_a)) diff.mean_ate_a_mm = Mean(ate_a);
    if (all_present(ate_b)) diff.mean_ate_b_mm = Mean(ate_b);
  }
  return diff;
}

void PrintDiff(const ResultsDiff& diff, const std::string& name_a, const std::string& name_b, std::ostream& out) {
  std::vector<std::string> revisions_a, revisions_b, codes_a, codes_b;
  for (const ResultsDiff::Row& row : diff.rows) {
    if (row.a) {
      revisions_a.push_back(row.a->revision);
      codes_a.push_back(row.a->code);
    }
    if (row.b) {
      revisions_b.push_back(row.b->revision);
      codes_b.push_back(row.b->code);
    }
  }
  out << "A: " << name_a << " (code: " << DescribeRevisions(revisions_a) << ")\nB: " << name_b
      << " (code: " << DescribeRevisions(revisions_b) << ")\n";
  const std::string same_code = CompareCode(codes_a, codes_b);
  if (!same_code.empty()) out << "A and B: " << same_code << " (by the code fingerprints of their runs)\n";
  const std::string compared = std::to_string(diff.configs_compared) + " run(s) both have";
  if (diff.configs_compared == 0) {
    out << "Options: no run both have records them\n";
  } else if (diff.option_changes.empty()) {
    out << "Options: the same in all " << compared << '\n';
  } else {
    out << "Options that differ over the " << compared << ", A → B (runs):\n";
    for (const auto& [change, runs] : diff.option_changes) out << "  " << change << " (" << runs << ")\n";
  }
  if (diff.other_sequence > 0) out << diff.other_sequence << " run(s) of the same name ran on another sequence folder\n";
  if (diff.configs_unread > 0) out << diff.configs_unread << " run(s) with a config.json that could not be read\n";
  out << '\n';
  TextTable table({"run", "A RMSE mm", "A tracked", "A ATE mm", "B RMSE mm", "B tracked", "B ATE mm", "B - A mm"});
  for (const ResultsDiff::Row& row : diff.rows) {
    std::vector<std::string> cells = {row.key};
    for (const std::optional<RunResult>* side : {&row.a, &row.b}) {
      const std::vector<std::string> side_cells = SideCells(*side);
      cells.insert(cells.end(), side_cells.begin(), side_cells.end());
    }
    cells.push_back(row.comparable() ? FormatFixed(row.b->rmse_mm - row.a->rmse_mm, 3) : "-");
    table.AddRow(cells);
  }
  table.Print(out);
  out << "\nOver the " << diff.comparable << " run(s) tracked to the end with ground truth in both:\n";
  if (diff.comparable > 0) {
    TextTable summary({"evaluation", "mean RMSE mm", "median mm", "mean ATE mm"});
    summary.AddRow({"A", FormatFixed(diff.mean_rmse_a_mm, 3), FormatFixed(diff.median_rmse_a_mm, 3), MillimetresCell(diff.mean_ate_a_mm)});
    summary.AddRow({"B", FormatFixed(diff.mean_rmse_b_mm, 3), FormatFixed(diff.median_rmse_b_mm, 3), MillimetresCell(diff.mean_ate_b_mm)});
    summary.Print(out);
    out << "B against A, run for run (better / same / worse): " << diff.b_against_a.ToString()
        << "; two-sided sign test over the runs that moved: p = " << FormatFixed(diff.b_against_a.SignTestP(), 3)
        << "\nRMSE ratio B / A, geometric mean over the runs: " << diff.b_against_a.GeometricMeanRatioText()
        << "; two-sided Wilcoxon signed-rank test of log(B / A) over the runs that moved: p = "
        << FormatFixed(diff.b_against_a.SignedRankP(), 3) << '\n';
  }
  out << "Not tracked to the end (lost or failed): in A only " << diff.short_only_a << ", in B only "
      << diff.short_only_b << ", in both " << diff.short_both << '\n';
  if (diff.only_in_a + diff.only_in_b > 0) {
    out << "Runs in one evaluation only: " << diff.only_in_a << " in A, " << diff.only_in_b << " in B\n";
  }
}

}  // namespace nrslam
