#include "nrslam/batch/baseline.h"

#include <map>
#include <sstream>

#include "nrslam/util/error.h"
#include "nrslam/util/text_table.h"

namespace nrslam {

Json MakeBaseline(const std::vector<RunResult>& results, const BaselineTolerance& tolerance) {
  Json runs = Json::object();
  for (const RunResult& r : results) {
    if (r.status == "failed") continue;
    runs[RunKey(r)] = {{"rmse_mm", r.rmse_mm}, {"frames_tracked", r.frames_tracked}};
    if (!r.revision.empty()) runs[RunKey(r)]["revision"] = r.revision;
    if (!r.code.empty()) runs[RunKey(r)]["code"] = r.code;
  }
  return {{"tolerance",
           {{"rmse_relative", tolerance.rmse_relative},
            {"rmse_absolute_mm", tolerance.rmse_absolute_mm},
            {"frames_tracked", tolerance.frames_tracked},
            {"pooled_rmse_relative", tolerance.pooled_rmse_relative}}},
          {"runs", runs}};
}

namespace {

// What a check reads of a baseline, or Error saying what is missing.
BaselineTolerance ToleranceOf(const Json& baseline) {
  BaselineTolerance tolerance;
  try {
    const Json& given = baseline.at("tolerance");
    tolerance.rmse_relative = given.at("rmse_relative");
    tolerance.rmse_absolute_mm = given.at("rmse_absolute_mm");
    tolerance.frames_tracked = given.at("frames_tracked");
    // Baselines written before the pooled check have none: they check run by run only.
    tolerance.pooled_rmse_relative = given.value("pooled_rmse_relative", 0.0);
    if (!(tolerance.pooled_rmse_relative >= 0)) throw Error("baseline: \"pooled_rmse_relative\" must be 0 or more");
    if (!baseline.at("runs").is_object()) throw Error("baseline: \"runs\" must map run names to their figures");
    for (const auto& [key, run] : baseline.at("runs").items()) {
      if (!run.is_object() || !run.value("rmse_mm", Json()).is_number() ||
          !run.value("frames_tracked", Json()).is_number()) {
        throw Error("baseline: run '" + key + "' needs \"rmse_mm\" and \"frames_tracked\" numbers");
      }
    }
  } catch (const Json::exception& e) {
    throw Error(std::string("baseline is malformed (needs \"tolerance\" and \"runs\"): ") + e.what());
  }
  return tolerance;
}

}  // namespace

Json ReadBaseline(const std::filesystem::path& file) {
  const Json baseline = ReadJsonFile(file);
  try {
    ToleranceOf(baseline);
  } catch (const Error& e) {
    throw Error(file.string() + ": " + e.what());
  }
  return baseline;
}

BaselineCheck CheckBaseline(const std::vector<RunResult>& results, const Json& baseline) {
  const BaselineTolerance tolerance = ToleranceOf(baseline);
  const Json& runs = baseline.at("runs");
  std::map<std::string, const RunResult*> by_key;
  for (const RunResult& r : results) by_key[RunKey(r)] = &r;
  std::vector<std::string> baseline_revisions, baseline_codes, run_codes;
  for (const RunResult& r : results) run_codes.push_back(r.code);
  BaselineCheck check;
  RmseChangeCounts pooled;  // over the runs with a figure on both sides
  TextTable table({"run", "RMSE before", "RMSE now", "allowed", "tracked before", "tracked now", "verdict"});
  for (const auto& [key, expected] : runs.items()) {
    baseline_revisions.push_back(expected.value("revision", ""));
    baseline_codes.push_back(expected.value("code", ""));
    const double rmse_before = expected.at("rmse_mm");
    const int tracked_before = expected.at("frames_tracked");
    const double allowed = rmse_before * (1.0 + tolerance.rmse_relative) + tolerance.rmse_absolute_mm;
    const auto found = by_key.find(key);
    std::string verdict = "ok";
    std::vector<std::string> row = {key, FormatFixed(rmse_before, 3)};
    if (found == by_key.end() || found->second->status == "failed") {
      verdict = found == by_key.end() ? "MISSING" : "FAILED: " + found->second->error;
      row.insert(row.end(), {"-", FormatFixed(allowed, 3), std::to_string(tracked_before), "-"});
    } else {
      const RunResult& now = *found->second;
      pooled.Add(rmse_before, now.rmse_mm);
      if (now.frames_tracked < tracked_before - tolerance.frames_tracked) {
        verdict = "WORSE: fewer frames tracked";
      } else if (now.rmse_mm > allowed) {
        verdict = "WORSE: RMSE +" + FormatFixed(100.0 * (now.rmse_mm / rmse_before - 1.0), 1) + " %";
      } else if (now.rmse_mm < rmse_before * (1.0 - tolerance.rmse_relative) - tolerance.rmse_absolute_mm) {
        verdict = "better (consider updating the baseline)";
      }
      row.insert(row.end(), {FormatFixed(now.rmse_mm, 3), FormatFixed(allowed, 3), std::to_string(tracked_before),
                             std::to_string(now.frames_tracked)});
    }
    check.passed &= verdict.rfind("ok", 0) == 0 || verdict.rfind("better", 0) == 0;
    row.push_back(verdict);
    table.AddRow(row);
  }
  std::ostringstream report;
  report << "Baseline check (RMSE may grow by " << FormatFixed(100 * tolerance.rmse_relative, 0) << " % + "
         << tolerance.rmse_absolute_mm << " mm per run";
  if (tolerance.pooled_rmse_relative > 0) {
    report << " and by " << FormatFixed(100 * tolerance.pooled_rmse_relative, 0) << " % over all runs (geometric mean)";
  }
  report << "; frames tracked may drop by " << tolerance.frames_tracked << "):\n"
         << "code of the baseline: " << DescribeRevisions(baseline_revisions) << "; of these runs: " << DescribeRevisions(results);
  const std::string same_code = CompareCode(baseline_codes, run_codes);
  report << (same_code.empty() ? "" : " (" + same_code + ")") << '\n';
  table.Print(report);
  const double ratio = pooled.GeometricMeanRatio();
  const bool pooled_passed =
      tolerance.pooled_rmse_relative == 0 || ratio <= 1.0 + tolerance.pooled_rmse_relative;
  report << "All runs together (better / same / worse): " << pooled.ToString()
         << "; RMSE ratio now / before, geometric mean: " << pooled.GeometricMeanRatioText();
  if (tolerance.pooled_rmse_relative > 0) {
    report << ", allowed " << FormatFixed(1.0 + tolerance.pooled_rmse_relative, 3) << (pooled_passed ? "" : ": WORSE");
  }
  report << "; signed-rank p = " << FormatFixed(pooled.SignedRankP(), 3) << '\n';
  if (!check.passed) {
    report << "FAILED: at least one run is worse than the baseline allows\n";
  } else if (!pooled_passed) {
    report << "FAILED: the runs together are worse than the baseline allows\n";
  } else {
    report << "PASSED\n";
  }
  check.passed &= pooled_passed;
  check.report = report.str();
  return check;
}

}  // namespace nrslam
