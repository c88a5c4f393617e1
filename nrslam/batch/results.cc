#include "nrslam/batch/results.h"

#include <algorithm>
#include <cstdlib>
#include <map>
#include <set>
#include <sstream>

#include "nrslam/system/run_sequence.h"
#include "nrslam/system/system_options.h"
#include "nrslam/util/csv.h"
#include "nrslam/util/folder.h"
#include "nrslam/util/json_options.h"
#include "nrslam/util/median.h"
#include "nrslam/util/text_file.h"
#include "nrslam/util/text_table.h"

namespace nrslam {

namespace {

// json[key] when it is a number; `fallback` when it is missing or null (not recorded).
double NumberOr(const Json& json, const char* key, double fallback) {
  const auto found = json.find(key);
  return found != json.end() && found->is_number() ? found->get<double>() : fallback;
}

std::optional<double> OptionalNumber(const Json& json, const char* key) {
  const auto found = json.find(key);
  return found != json.end() && found->is_number() ? std::optional<double>(found->get<double>()) : std::nullopt;
}

// The figures a run's summary.json and a results.json row share, under the same keys.
void ReadFigures(const Json& json, RunResult* result) {
  result->init_frame = json.value("init_frame", -1);
  result->frames_tracked = json.value("frames_tracked", 0);
  result->frames_total = json.value("frames_total", 0);
  // Results written before the field existed always had ground truth for every tracked frame.
  result->frames_evaluated = json.value("frames_evaluated", result->frames_tracked);
  result->input = json.get<InputEffects>();
  result->rmse_mm = json.value("rmse_mm", 0.0);
  result->rmse_median_mm = json.value("rmse_median_mm", 0.0);
  result->rmse_flat_mm = NumberOr(json, "rmse_flat_mm", -1.0);
  result->rmse_map_scale_mm = NumberOr(json, "rmse_map_scale_mm", -1.0);
  result->rmse_median_scale_mm = NumberOr(json, "rmse_median_scale_mm", -1.0);
  result->fps = json.value("fps", 0.0);
  result->peak_memory_mb = NumberOr(json, "peak_memory_mb", -1.0);
  result->ate_mm = NumberOr(json, "ate_rmse_mm", -1.0);
  result->births_evaluated = json.value("births_evaluated", 0);
  result->birth_log_error_mean = OptionalNumber(json, "birth_log_error_mean");
  result->birth_log_error_median = OptionalNumber(json, "birth_log_error_median");
  result->map_depth = json.get<DepthChange>();
  result->maps_given_up = json.value("maps_given_up", 0);
  const auto reason = json.find("stop_reason");
  if (reason != json.end() && reason->is_string()) {
    result->stop_reason = reason->get<std::string>();
    result->stop_frame = result->init_frame < 0 ? -1 : json.value("stop_frame", -1);
  }
}

// Sequence -> whether every run of it (every sweep point) tracked to the end with ground truth.
std::map<std::string, bool> CompleteSequences(const std::vector<RunResult>& results) {
  std::map<std::string, bool> complete;
  for (const RunResult& r : results) {
    bool& all = complete.emplace(r.sequence, true).first->second;
    all = all && r.complete();
  }
  return complete;
}

// Whether "path=value" sets the value `defaults` (nrslam_run's options, as JSON) has: parsed as
// the option's type, so "1.10" is 1.1.
bool IsDefaultAssignment(const Json& defaults, const std::string& assignment) {
  Json probe = defaults;
  try {
    ApplyAssignment(probe, assignment);
  } catch (const Error&) {
    return false;  // not an option of this build (e.g. results from an older one)
  }
  return probe == defaults;
}

// A run's sweep point with `option`'s assignment replaced, as a lookup key with the sequence.
std::string PairKey(const RunResult& run, const std::string& option, const std::string& assignment) {
  std::string key = run.sequence;
  for (const std::string& a : run.point) key += '\n' + (a.compare(0, option.size() + 1, option + "=") == 0 ? assignment : a);
  return key;
}

}  // namespace

std::string DescribeRevisions(const std::vector<std::string>& revisions) {
  std::set<std::string> distinct;
  bool unrecorded = false;
  for (const std::string& revision : revisions) {
    if (revision.empty()) {
      unrecorded = true;
    } else {
      distinct.insert(revision);
    }
  }
  std::vector<std::string> names(distinct.begin(), distinct.end());
  if (unrecorded || names.empty()) names.push_back("not recorded");
  return Join(names, ", ");
}

std::string DescribeRevisions(const std::vector<RunResult>& results) {
  std::vector<std::string> revisions;
  for (const RunResult& r : results) {
    if (r.status != "failed") revisions.push_back(r.revision);  // a failed run made nothing to name
  }
  if (revisions.empty() && !results.empty()) return "none: every run failed";
  return DescribeRevisions(revisions);
}

std::string RunKey(const RunResult& result) {
  return RunName(result.sequence, result.label);
}


std::string RunStatus(const RunResult& figures) {
  if (figures.init_frame < 0) return "not_initialised";
  const int input_not_tracked = figures.input.frames_dropout + figures.input.frames_unreadable_after_init;
  const bool every_frame = figures.init_frame + figures.frames_tracked + input_not_tracked >= figures.frames_total;
  return every_frame && figures.stop_reason.empty() ? "ok" : "lost";
}

std::string StopText(const RunResult& result) {
  return result.status == "failed" ? "" : DescribeStop(result.init_frame, result.stop_frame, result.stop_reason);
}

std::vector<std::string> RunNotes(const RunResult& result) {
  std::vector<std::string> notes;
  if (std::string stop = StopText(result); !stop.empty()) notes.push_back(std::move(stop));
  for (std::string& note : MapNotes(result.maps_given_up, result.map_depth)) notes.push_back(std::move(note));
  for (std::string& note : result.input.Notes()) notes.push_back(std::move(note));
  return notes;
}

std::string RmseCell(const RunResult& result, double rmse_mm) {
  if (result.evaluated()) return FormatFixed(rmse_mm, 3);
  if (result.frames_tracked == 0) return "-";  // nothing to score
  return result.input.frames_sparse_groundtruth > 0 ? "sparse GT" : "no GT";
}

std::string RecordedRmseCell(const RunResult& result, double rmse_mm) {
  return rmse_mm >= 0 ? RmseCell(result, rmse_mm) : "-";
}

std::string InitFrameCell(const RunResult& result) {
  return result.init_frame >= 0 ? std::to_string(result.init_frame) : "-";
}

double MeanOfRecorded(const std::vector<double>& figures) {
  const bool all = !figures.empty() && std::all_of(figures.begin(), figures.end(), [](double x) { return x >= 0; });
  return all ? Mean(figures) : -1.0;
}

std::string MillimetresCell(double mm) { return mm >= 0 ? FormatFixed(mm, 3) : "-"; }

std::string MegabytesCell(double mb) { return mb >= 0 ? FormatFixed(mb, 0) : "-"; }

std::string CompareCode(const std::vector<std::string>& codes_a, const std::vector<std::string>& codes_b) {
  const auto recorded = [](const std::vector<std::string>& codes) {
    return !codes.empty() && std::none_of(codes.begin(), codes.end(), [](const std::string& c) { return c.empty(); });
  };
  if (!recorded(codes_a) || !recorded(codes_b)) return "";
  std::set<std::string> distinct(codes_a.begin(), codes_a.end());
  distinct.insert(codes_b.begin(), codes_b.end());
  return distinct.size() == 1 ? "the same code" : "other code";
}

std::vector<RunResult> CollectResults(const EvaluationPlan& plan) {
  std::vector<RunResult> results;
  for (const RunJob& run : plan.runs) {
    RunResult result;
    result.sequence = run.sequence;
    result.label = run.label;
    result.point = run.point;
    result.run_folder = run.run_folder.string();
    try {
      if (std::filesystem::exists(run.run_folder / "summary.json")) {
        ReadFigures(ReadJsonFile(run.run_folder / "summary.json"), &result);
        if (std::filesystem::exists(run.run_folder / "config.json")) {
          const Json config = ReadJsonFile(run.run_folder / "config.json");
          result.revision = config.value("nrslam_revision", "");
          result.code = config.value("nrslam_code", "");
        }
        result.status = RunStatus(result);
      } else if (std::filesystem::exists(run.run_folder / "failure.json")) {
        result.error = ReadJsonFile(run.run_folder / "failure.json").value("error", "unknown failure");
      } else {
        result.error = "not run";
      }
    } catch (const Error& e) {
      result.error = e.what();
    }
    results.push_back(result);
  }
  return results;
}

std::string RecordedField(double value) {
  std::ostringstream field;
  if (value >= 0) field << value;
  return field.str();
}

namespace {
// A figure that may not have been recorded (negative, or none) as JSON: null then.
Json RecordedNumber(double value) { return value >= 0 ? Json(value) : Json(); }
Json RecordedNumber(const std::optional<double>& value) { return value ? Json(*value) : Json(); }

std::string RecordedField(const std::optional<double>& value) {
  std::ostringstream field;
  if (value) field << *value;
  return field.str();
}
}  // namespace

Json ToJson(const std::vector<RunResult>& results) {
  Json rows = Json::array();
  for (const RunResult& r : results) {
    Json row{{"sequence", r.sequence}, {"label", r.label}, {"point", r.point}, {"status", r.status},
             {"error", r.error}, {"init_frame", r.init_frame}, {"frames_tracked", r.frames_tracked},
             {"frames_total", r.frames_total}, {"frames_evaluated", r.frames_evaluated}, {"rmse_mm", r.rmse_mm},
             {"rmse_median_mm", r.rmse_median_mm},
             {"rmse_flat_mm", RecordedNumber(r.rmse_flat_mm)},
             {"rmse_map_scale_mm", RecordedNumber(r.rmse_map_scale_mm)},
             {"rmse_median_scale_mm", RecordedNumber(r.rmse_median_scale_mm)},
             {"ate_rmse_mm", RecordedNumber(r.ate_mm)}, {"fps", r.fps},
             {"peak_memory_mb", RecordedNumber(r.peak_memory_mb)},
             {"births_evaluated", r.births_evaluated},
             {"birth_log_error_mean", RecordedNumber(r.birth_log_error_mean)},
             {"birth_log_error_median", RecordedNumber(r.birth_log_error_median)},
             {"maps_given_up", r.maps_given_up},
             {"run_folder", r.run_folder},
             {"revision", r.revision.empty() ? Json() : Json(r.revision)},
             {"code", r.code.empty() ? Json() : Json(r.code)},
             {"stop_frame", r.stop_reason.empty() ? Json() : Json(r.stop_frame)},
             {"stop_reason", r.stop_reason.empty() ? Json() : Json(r.stop_reason)}};
    row.update(Json(r.map_depth));
    row.update(Json(r.input));
    rows.push_back(std::move(row));
  }
  return {{"results", rows}};
}

std::vector<RunResult> ResultsFromJson(const Json& json) {
  std::vector<RunResult> results;
  try {
    for (const Json& row : json.at("results")) {
      RunResult r;
      r.sequence = row.at("sequence");
      r.label = row.value("label", "");
      r.point = row.value("point", std::vector<std::string>{});
      r.status = row.at("status");
      r.error = row.value("error", "");
      ReadFigures(row, &r);
      r.run_folder = row.value("run_folder", "");
      const auto revision = row.find("revision");
      if (revision != row.end() && revision->is_string()) r.revision = revision->get<std::string>();
      const auto code = row.find("code");
      if (code != row.end() && code->is_string()) r.code = code->get<std::string>();
      results.push_back(r);
    }
  } catch (const Json::exception& e) {
    throw Error(std::string("results are malformed: ") + e.what());
  }
  return results;
}

std::vector<RunResult> ReadResults(const std::filesystem::path& folder) {
  if (!std::filesystem::is_directory(folder)) throw Error(folder.string() + " is not a folder");
  if (!std::filesystem::exists(folder / "results.json")) {
    throw Error(folder.string() + " holds no results.json: it is not the output folder (--out) of an evaluation");
  }
  return ResultsFromJson(ReadJsonFile(folder / "results.json"));
}

namespace {

bool Swept(const std::vector<RunResult>& results) {
  return std::any_of(results.begin(), results.end(), [](const RunResult& r) { return !r.label.empty(); });
}

TextTable ResultsTable(const std::vector<RunResult>& results) {
  const bool swept = Swept(results);
  std::vector<std::string> header = {"sequence"};
  if (swept) header.push_back("sweep point");
  for (const char* column : {"status", "init", "tracked", "RMSE mm", "median mm", "flat mm", "1 scale mm", "ATE mm", "fps", "MB"}) {
    header.push_back(column);
  }
  TextTable table(header);
  for (const RunResult& r : results) {
    std::vector<std::string> row = {r.sequence};
    if (swept) row.push_back(r.label);
    if (r.status == "failed") {
      for (const char* cell : {"FAILED", "-", "-", "-", "-", "-", "-", "-", "-", "-"}) row.push_back(cell);
    } else {
      row.insert(row.end(), {r.status, InitFrameCell(r),
                             std::to_string(r.frames_tracked) + "/" + std::to_string(r.frames_total),
                             RmseCell(r, r.rmse_mm), RmseCell(r, r.rmse_median_mm), RecordedRmseCell(r, r.rmse_flat_mm),
                             RecordedRmseCell(r, r.rmse_map_scale_mm), MillimetresCell(r.ate_mm),
                             r.fps > 0 ? FormatFixed(r.fps, 1) : "-",  // an external result has neither
                             MegabytesCell(r.peak_memory_mb)});
    }
    table.AddRow(row);
  }
  return table;
}

// What went wrong or was noted per run, one line each: "FAILED key: error", "key: note".
std::vector<std::string> ResultNoteLines(const std::vector<RunResult>& results) {
  std::vector<std::string> lines;
  for (const RunResult& r : results) {
    if (r.status == "failed") lines.push_back("FAILED " + RunKey(r) + ": " + r.error);
    for (const std::string& note : RunNotes(r)) lines.push_back(RunKey(r) + ": " + note);
  }
  return lines;
}

std::string SweepSummaryTitle(const std::vector<RunResult>& results) {
  int sequences = 0;
  for (const auto& [name, ok] : CompleteSequences(results)) sequences += ok;
  return "Per swept value, over the " + std::to_string(sequences) + " sequence(s) tracked to the end at every point" +
         " (not to end: that value's runs, over all sequences, lost or failed):";
}

TextTable SweepSummaryTable(const std::vector<RunResult>& results) {
  TextTable summary(SweepSummaryHeader());
  for (const SweepValueSummary& v : SummariseSweep(results)) summary.AddRow(SweepSummaryCells(v));
  return summary;
}

// results.md and results.tex in `folder`: the printed tables, to paste into notes and papers.
void WriteResultTables(const std::vector<RunResult>& results, const std::filesystem::path& folder) {
  std::ostringstream markdown, latex;
  const TextTable table = ResultsTable(results);
  table.PrintMarkdown(markdown);
  latex << "% nrslam_eval's results table (needs \\usepackage{booktabs})\n";
  table.PrintLatex(latex);
  const std::vector<std::string> notes = ResultNoteLines(results);
  if (!notes.empty()) markdown << '\n';
  for (const std::string& line : notes) {
    markdown << "- " << line << '\n';
    latex << "% " << line << '\n';
  }
  if (Swept(results)) {
    const std::string title = SweepSummaryTitle(results);
    const TextTable summary = SweepSummaryTable(results);
    markdown << '\n' << title << "\n\n";
    summary.PrintMarkdown(markdown);
    latex << "\n% " << title << '\n';
    summary.PrintLatex(latex);
  }
  WriteTextFile(folder / "results.md", markdown.str());
  WriteTextFile(folder / "results.tex", latex.str());
}

}  // namespace

void PrintResults(const std::vector<RunResult>& results, std::ostream& out) {
  ResultsTable(results).Print(out);
  for (const std::string& line : ResultNoteLines(results)) out << line << '\n';
  if (!Swept(results)) return;
  out << '\n' << SweepSummaryTitle(results) << '\n';
  SweepSummaryTable(results).Print(out);
}

void WriteResults(const std::vector<RunResult>& results, const std::filesystem::path& folder) {
  CreateFolder(folder);
  WriteTextFile(folder / "results.json", ToJson(results).dump(2) + '\n');
  WriteResultTables(results, folder);
  std::ostringstream csv;
  csv << "sequence,sweep_point,status,init_frame,frames_tracked,frames_total,frames_evaluated,"
         "frames_unreadable,frames_unreadable_after_init,frames_groundtruth_unreadable,frames_sparse_groundtruth,"
         "frames_dropout,sudden_occlusions,view_jumps,static_fraction,frames_past_end,rmse_mm,rmse_median_mm,rmse_flat_mm,"
         "rmse_map_scale_mm,rmse_median_scale_mm,ate_rmse_mm,fps,peak_memory_mb,births_evaluated,birth_log_error_mean,"
         "birth_log_error_median,map_depth_change,map_depth_change_beyond_from,maps_given_up,revision,code,error\n";
  for (const RunResult& r : results) {
    csv << CsvField(r.sequence) << ',' << CsvField(r.label) << ',' << r.status << ',' << r.init_frame << ','
        << r.frames_tracked << ',' << r.frames_total << ',' << r.frames_evaluated << ','
        << r.input.frames_unreadable << ',' << r.input.frames_unreadable_after_init << ','
        << r.input.frames_groundtruth_unreadable << ',' << r.input.frames_sparse_groundtruth << ','
        << r.input.frames_dropout << ',' << r.input.sudden_occlusions << ',' << r.input.view_jumps << ','
        << r.input.static_fraction << ',' << r.input.frames_past_end << ','
        << r.rmse_mm << ',' << r.rmse_median_mm << ','
        << RecordedField(r.rmse_flat_mm) << ',' << RecordedField(r.rmse_map_scale_mm) << ','
        << RecordedField(r.rmse_median_scale_mm) << ',' << RecordedField(r.ate_mm) << ',' << r.fps << ','
        << RecordedField(r.peak_memory_mb) << ',' << r.births_evaluated << ',' << RecordedField(r.birth_log_error_mean)
        << ',' << RecordedField(r.birth_log_error_median) << ','
        << RecordedField(r.map_depth.ratio > 0 ? std::optional<double>(r.map_depth.ratio) : std::nullopt) << ','
        << (r.map_depth.beyond_from >= 0 ? std::to_string(r.map_depth.beyond_from) : "") << ',' << r.maps_given_up
        << ',' << r.revision << ',' << r.code << ',' << CsvField(r.error) << '\n';
  }
  WriteTextFile(folder / "results.csv", csv.str());
}

std::vector<std::string> SweepSummaryHeader() {
  return {"option", "value", "mean RMSE mm", "median mm", "mean 1 scale mm", "mean ATE mm", "runs", "not to end",
          "vs default: better / same / worse", "sign test p", "RMSE ratio to default", "its 95 % CI",
          "signed-rank p"};
}

std::vector<std::string> SweepSummaryCells(const SweepValueSummary& v) {
  const bool any = v.runs > 0;
  const std::string paired = v.is_default ? "(default)" : v.paired ? v.against_default.ToString() : "-";
  const auto if_paired = [&v](double figure) { return v.paired ? FormatFixed(figure, 3) : std::string("-"); };
  const std::string interval = v.paired ? v.against_default.GeometricMeanRatioIntervalText() : "";
  return {v.option, v.value, any ? FormatFixed(v.mean_rmse_mm, 3) : "-", any ? FormatFixed(v.median_rmse_mm, 3) : "-",
          any ? MillimetresCell(v.mean_map_scale_mm) : "-", any ? MillimetresCell(v.mean_ate_mm) : "-", std::to_string(v.runs),
          std::to_string(v.short_runs), paired, if_paired(v.against_default.SignTestP()),
          if_paired(v.against_default.GeometricMeanRatio()), interval.empty() ? "-" : interval,
          if_paired(v.against_default.SignedRankP())};
}

std::vector<SweepValueSummary> SummariseSweep(const std::vector<RunResult>& results) {
  const std::map<std::string, bool> complete = CompleteSequences(results);
  const auto value_order = [](const std::string& a, const std::string& b) {
    char *end_a = nullptr, *end_b = nullptr;
    const double x = std::strtod(a.c_str(), &end_a), y = std::strtod(b.c_str(), &end_b);
    return *end_a == '\0' && *end_b == '\0' && x != y ? x < y : a < b;
  };
  struct Cell {
    std::vector<double> rmse, ate, map_scale;
    int short_runs = 0;
  };
  std::map<std::string, std::map<std::string, Cell, decltype(value_order)>> by_value;
  for (const RunResult& r : results) {
    for (const std::string& assignment : r.point) {
      const size_t equals = assignment.find('=');
      Cell& cell = by_value.try_emplace(assignment.substr(0, equals), value_order).first->second[assignment.substr(equals + 1)];
      if (r.status != "ok") ++cell.short_runs;
      if (!complete.at(r.sequence)) continue;
      cell.rmse.push_back(r.rmse_mm);
      cell.ate.push_back(r.ate_mm);
      cell.map_scale.push_back(r.rmse_map_scale_mm);
    }
  }
  const auto has = [](const RunResult& r, const std::string& assignment) {
    return std::find(r.point.begin(), r.point.end(), assignment) != r.point.end();
  };
  const Json defaults = SystemOptions{};
  std::vector<SweepValueSummary> summaries;
  for (const auto& [option, values] : by_value) {
    std::string default_value;
    for (const auto& [value, cell] : values) {
      if (IsDefaultAssignment(defaults, option + "=" + value)) default_value = value;
    }
    const std::string default_assignment = option + "=" + default_value;
    std::map<std::string, double> at_default;  // PairKey → RMSE of the run at the default
    for (const RunResult& r : results) {
      if (complete.at(r.sequence) && has(r, default_assignment)) at_default[PairKey(r, option, default_assignment)] = r.rmse_mm;
    }
    for (const auto& [value, cell] : values) {
      SweepValueSummary summary;
      summary.option = option;
      summary.value = value;
      summary.runs = static_cast<int>(cell.rmse.size());
      summary.short_runs = cell.short_runs;
      if (!cell.rmse.empty()) {
        summary.mean_rmse_mm = Mean(cell.rmse);
        summary.median_rmse_mm = Median(cell.rmse);
        summary.mean_ate_mm = MeanOfRecorded(cell.ate);
        summary.mean_map_scale_mm = MeanOfRecorded(cell.map_scale);
      }
      summary.is_default = value == default_value;
      summary.paired = !default_value.empty() && !summary.is_default;
      const std::string assignment = option + "=" + value;
      for (const RunResult& r : results) {
        if (!summary.paired || !complete.at(r.sequence) || !has(r, assignment)) continue;
        const auto partner = at_default.find(PairKey(r, option, default_assignment));
        if (partner == at_default.end()) continue;
        summary.against_default.Add(partner->second, r.rmse_mm);
      }
      summaries.push_back(summary);
    }
  }
  return summaries;
}

}  // namespace nrslam
