#include "nrslam/batch/rigid_comparison.h"

#include <cmath>
#include <exception>
#include <sstream>

#include "nrslam/batch/run_folder.h"
#include "nrslam/util/csv.h"
#include "nrslam/util/error.h"
#include "nrslam/util/text_file.h"
#include "nrslam/util/text_table.h"

namespace nrslam {
namespace {

// What makes two runs a deformable run and its rigid baseline: the sequence and every option
// but `tracking.rigid`.
std::string BaselineKey(const RunJob& run) {
  Json options = run.options;
  options["tracking"]["rigid"] = false;
  return run.sequence_folder.string() + '\n' + options.dump();
}

bool IsRigid(const RunJob& run) { return run.options.at("tracking").at("rigid").get<bool>(); }

std::string Ratio(double rigid_mm, double deformable_mm) {
  return deformable_mm > 0 ? FormatFixed(rigid_mm / deformable_mm, 2) : "-";
}

}  // namespace

std::map<int, double> ReadFrameRmse(const std::filesystem::path& run_folder) {
  std::map<int, double> rmse;
  for (const auto& row : ReadCsv(run_folder / "metrics.csv")) {
    const double frame = Number(row, "frame"), value = Number(row, "rmse_mm");
    if (!std::isnan(frame) && !std::isnan(value)) rmse[static_cast<int>(frame)] = value;
  }
  return rmse;
}

CommonFramesRmse MeanOverCommonFrames(const std::map<int, double>& a, const std::map<int, double>& b) {
  CommonFramesRmse common;
  for (const auto& [frame, a_mm] : a) {
    const auto found = b.find(frame);
    if (found == b.end()) continue;
    ++common.frames;
    common.a_mm += a_mm;
    common.b_mm += found->second;
  }
  if (common.frames > 0) {
    common.a_mm /= common.frames;
    common.b_mm /= common.frames;
  }
  return common;
}

std::vector<RigidComparison> CompareWithRigid(const EvaluationPlan& plan, const std::vector<RunResult>& results) {
  if (results.size() != plan.runs.size()) throw Error("rigid comparison: results do not match the plan's runs");
  std::map<std::string, size_t> rigid_runs;
  for (size_t i = 0; i < plan.runs.size(); ++i) {
    if (!plan.runs[i].is_external() && IsRigid(plan.runs[i]) && results[i].status != "failed" && results[i].evaluated()) {
      rigid_runs.emplace(BaselineKey(plan.runs[i]), i);  // the first one of a key stays
    }
  }
  std::vector<RigidComparison> comparisons;
  for (size_t i = 0; i < plan.runs.size(); ++i) {
    if (plan.runs[i].is_external() || IsRigid(plan.runs[i]) || results[i].status == "failed" || !results[i].evaluated()) continue;
    const auto rigid = rigid_runs.find(BaselineKey(plan.runs[i]));
    if (rigid == rigid_runs.end()) continue;
    RigidComparison comparison{results[i], results[rigid->second], {}, {}};
    const std::filesystem::path& deformable_folder = plan.runs[i].run_folder;
    const std::filesystem::path& rigid_folder = plan.runs[rigid->second].run_folder;
    try {
      comparison.common = MeanOverCommonFrames(ReadFrameRmse(deformable_folder), ReadFrameRmse(rigid_folder));
    } catch (const Error&) {
      // A run folder without metrics.csv (e.g. merged from elsewhere without it): no common frames.
    }
    try {
      comparison.same_points = CompareRunFolders(deformable_folder, rigid_folder);
    } catch (const std::exception&) {
      // Likewise without points.csv, with a config.json that does not parse or its sequence
      // gone: no common points, and the table is still printed.
    }
    comparisons.push_back(comparison);
  }
  return comparisons;
}

RigidComparisonTally TallyRigidComparisons(const std::vector<RigidComparison>& comparisons) {
  RigidComparisonTally tally;
  for (const RigidComparison& c : comparisons) {
    tally.own.Add(c.rigid.rmse_mm, c.deformable.rmse_mm);
    if (c.common.frames > 0) tally.common.Add(c.common.b_mm, c.common.a_mm);
    if (c.same_points.frames > 0) tally.same_points.Add(c.same_points.b_common.rmse_mm, c.same_points.a_common.rmse_mm);
  }
  return tally;
}

std::string RigidComparisonTallyText(const RigidComparisonTally& tally) {
  const auto count = [](const RmseChangeCounts& counts) {
    // The ratio the other way up, as the table's: rigid / deformable, above 1 where deformable wins.
    return counts.ToString() + " (sign test p = " + FormatFixed(counts.SignTestP(), 3) + "; ratio, geometric mean " +
           counts.GeometricMeanRatioText(true) + ", signed-rank p = " + FormatFixed(counts.SignedRankP(), 3) + ")";
  };
  return "Deformable better / same / worse than rigid: own RMSE " + count(tally.own) + "; common frames " +
         count(tally.common) + "; same points " + count(tally.same_points) + ".";
}

std::vector<std::string> RigidComparisonHeader() {
  return {"deformable run", "rigid run",     "def mm",        "rigid mm",        "ratio",
          "tracked def / rigid", "common frames", "def mm common", "rigid mm common", "ratio common",
          "same-point frames", "same points/frame", "def mm same points", "rigid mm same points",
          "ratio same points"};
}

std::vector<std::string> RigidComparisonCells(const RigidComparison& c) {
  const bool common = c.common.frames > 0;
  const bool same = c.same_points.frames > 0;
  return {RunKey(c.deformable),
          RunKey(c.rigid),
          FormatFixed(c.deformable.rmse_mm, 3),
          FormatFixed(c.rigid.rmse_mm, 3),
          Ratio(c.rigid.rmse_mm, c.deformable.rmse_mm),
          std::to_string(c.deformable.frames_tracked) + " / " + std::to_string(c.rigid.frames_tracked),
          std::to_string(c.common.frames),
          common ? FormatFixed(c.common.a_mm, 3) : "-",
          common ? FormatFixed(c.common.b_mm, 3) : "-",
          common ? Ratio(c.common.b_mm, c.common.a_mm) : "-",
          std::to_string(c.same_points.frames),
          same ? FormatFixed(c.same_points.mean_common_points, 0) : "-",
          same ? FormatFixed(c.same_points.a_common.rmse_mm, 3) : "-",
          same ? FormatFixed(c.same_points.b_common.rmse_mm, 3) : "-",
          same ? Ratio(c.same_points.b_common.rmse_mm, c.same_points.a_common.rmse_mm) : "-"};
}

void PrintRigidComparison(const std::vector<RigidComparison>& comparisons, std::ostream& out) {
  if (comparisons.empty()) return;
  out << "\nDeformable against rigid: the same sequence and options but tracking.rigid. Ratio = rigid / deformable\n"
         "RMSE, above 1 where the deformable run is more accurate; \"common\": both over the frames both evaluated;\n"
         "\"same points\": both on the points both report (the same tracks), over the frames where both have enough.\n";
  TextTable table(RigidComparisonHeader());
  for (const RigidComparison& c : comparisons) table.AddRow(RigidComparisonCells(c));
  table.Print(out);
  out << RigidComparisonTallyText(TallyRigidComparisons(comparisons)) << '\n';
}

void WriteRigidComparison(const std::vector<RigidComparison>& comparisons, const std::filesystem::path& file) {
  std::ostringstream csv;
  csv << "deformable_run,rigid_run,deformable_rmse_mm,rigid_rmse_mm,deformable_frames_tracked,rigid_frames_tracked,"
         "frames_total,common_frames,deformable_common_rmse_mm,rigid_common_rmse_mm,same_points_frames,"
         "same_points_per_frame,deformable_same_points_rmse_mm,rigid_same_points_rmse_mm\n";
  for (const RigidComparison& c : comparisons) {
    csv << CsvField(RunKey(c.deformable)) << ',' << CsvField(RunKey(c.rigid)) << ',' << c.deformable.rmse_mm << ','
        << c.rigid.rmse_mm << ',' << c.deformable.frames_tracked << ',' << c.rigid.frames_tracked << ','
        << c.deformable.frames_total << ',' << c.common.frames << ',';
    if (c.common.frames > 0) csv << c.common.a_mm << ',' << c.common.b_mm;
    else csv << ',';
    csv << ',' << c.same_points.frames << ',';
    if (c.same_points.frames > 0) {
      csv << c.same_points.mean_common_points << ',' << c.same_points.a_common.rmse_mm << ','
          << c.same_points.b_common.rmse_mm;
    } else {
      csv << ",,";
    }
    csv << '\n';
  }
  WriteTextFile(file, csv.str());
}

}  // namespace nrslam
