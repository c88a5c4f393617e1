#include "nrslam/batch/seed_groups.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>

#include "nrslam/util/csv.h"
#include "nrslam/util/error.h"
#include "nrslam/util/median.h"
#include "nrslam/util/text_file.h"
#include "nrslam/util/text_table.h"

namespace nrslam {
namespace {

// The render arguments without the seed: {"--preset", "sim-3", "--quiet", "--set", "seed=2"}
// gives {"--preset", "sim-3", "--quiet"}.
std::vector<std::string> WithoutSeed(const std::vector<std::string>& arguments) {
  std::vector<std::string> kept;
  for (size_t i = 0; i < arguments.size(); ++i) {
    if (arguments[i] == "--set" && i + 1 < arguments.size() && IsSeedAssignment(arguments[i + 1])) {
      ++i;
      continue;
    }
    kept.push_back(arguments[i]);
  }
  return kept;
}

std::string SeedOf(const std::vector<std::string>& arguments) {
  for (const std::string& argument : arguments) {
    if (IsSeedAssignment(argument)) return argument.substr(argument.find('=') + 1);
  }
  return "default";
}

// A render's description is its preset; its other settings follow the "--set"s, but for those
// of the sweep point, which its label names.
std::string GroupName(const PrepareJob& render, const RunJob& run) {
  std::set<std::string> swept;
  for (const std::string& assignment : run.point) {
    if (IsSimulatorAssignment(assignment)) swept.insert(SimulatorAssignment(assignment));
  }
  std::string name = render.description;
  const std::vector<std::string> arguments = WithoutSeed(render.arguments);
  for (size_t i = 0; i + 1 < arguments.size(); ++i) {
    if (arguments[i] == "--set" && swept.count(arguments[i + 1]) == 0) name += " " + arguments[i + 1];
  }
  const bool swept_rigidity = std::any_of(run.point.begin(), run.point.end(), [](const std::string& assignment) {
    return assignment.rfind("tracking.rigid=", 0) == 0;
  });
  if (run.options.at("tracking").at("rigid").get<bool>() && !swept_rigidity) name += " rigid";
  if (!run.label.empty()) name += " [" + run.label + "]";
  return name;
}

void Summarise(const std::vector<const RunResult*>& members, SeedGroup* group) {
  std::vector<double> rmse, ate, map_scale;
  for (const RunResult* result : members) {
    if (result->status == "failed" || !result->evaluated()) continue;
    if (result->complete()) ++group->to_end;
    rmse.push_back(result->rmse_mm);
    ate.push_back(result->ate_mm);
    map_scale.push_back(result->rmse_map_scale_mm);
  }
  group->scored = static_cast<int>(rmse.size());
  if (rmse.empty()) return;
  group->mean_rmse_mm = Mean(rmse);
  double squares = 0;
  for (double value : rmse) squares += (value - group->mean_rmse_mm) * (value - group->mean_rmse_mm);
  group->sd_rmse_mm = rmse.size() > 1 ? std::sqrt(squares / (rmse.size() - 1)) : 0.0;
  group->median_rmse_mm = Median(rmse);
  group->min_rmse_mm = *std::min_element(rmse.begin(), rmse.end());
  group->max_rmse_mm = *std::max_element(rmse.begin(), rmse.end());
  group->mean_ate_mm = MeanOfRecorded(ate);
  group->mean_map_scale_mm = MeanOfRecorded(map_scale);
}

}  // namespace

std::vector<SeedGroup> GroupBySeed(const EvaluationPlan& plan, const std::vector<RunResult>& results) {
  if (results.size() != plan.runs.size()) throw Error("seed groups: results do not match the plan's runs");
  std::map<std::string, size_t> index_of_key;
  std::vector<SeedGroup> groups;
  std::vector<std::vector<const RunResult*>> members;
  for (size_t i = 0; i < plan.runs.size(); ++i) {
    const RunJob& run = plan.runs[i];
    if (run.is_external() || run.prepare < 0 || plan.prepares[run.prepare].import) continue;
    const PrepareJob& render = plan.prepares[run.prepare];
    std::string key;
    for (const std::string& argument : WithoutSeed(render.arguments)) key += argument + '\n';
    key += run.options.dump();
    const auto [found, added] = index_of_key.emplace(key, groups.size());
    if (added) {
      groups.push_back({GroupName(render, run), {}, {}});
      members.emplace_back();
    }
    groups[found->second].sequences.push_back(run.sequence);
    groups[found->second].seeds.push_back(SeedOf(render.arguments));
    members[found->second].push_back(&results[i]);
  }
  std::vector<SeedGroup> summarised;
  std::map<std::string, int> name_count;
  for (size_t g = 0; g < groups.size(); ++g) {
    if (groups[g].sequences.size() < 2) continue;
    Summarise(members[g], &groups[g]);
    summarised.push_back(groups[g]);
    ++name_count[groups[g].name];
  }
  // Groups whose options differ per sequence (a manifest's own "set") would share a name.
  for (SeedGroup& group : summarised) {
    if (name_count[group.name] > 1) group.name += " (" + group.sequences.front() + ", ...)";
  }
  return summarised;
}

std::vector<std::string> SeedGroupHeader() {
  return {"preset", "seeds", "scored", "to end", "mean RMSE mm", "sd mm", "median mm", "min mm", "max mm", "mean 1 scale mm", "mean ATE mm"};
}

std::vector<std::string> SeedGroupCells(const SeedGroup& group) {
  const std::string seeds = Join(group.seeds, " ");
  const bool any = group.scored > 0;
  const auto mm = [any](double value) { return any ? FormatFixed(value, 3) : "-"; };
  return {group.name,
          seeds,
          std::to_string(group.scored) + "/" + std::to_string(group.seeds.size()),
          std::to_string(group.to_end),
          mm(group.mean_rmse_mm),
          group.scored > 1 ? FormatFixed(group.sd_rmse_mm, 3) : "-",
          mm(group.median_rmse_mm),
          mm(group.min_rmse_mm),
          mm(group.max_rmse_mm),
          any ? MillimetresCell(group.mean_map_scale_mm) : "-",
          any ? MillimetresCell(group.mean_ate_mm) : "-"};
}

void PrintSeedGroups(const std::vector<SeedGroup>& groups, std::ostream& out) {
  if (groups.empty()) return;
  out << "\nOver scene seeds: runs of one preset that differ only in the simulator's seed, each scored by its own\n"
         "RMSE (\"to end\": how many of those tracked every frame); sd is the sample standard deviation across seeds.\n";
  TextTable table(SeedGroupHeader());
  for (const SeedGroup& group : groups) table.AddRow(SeedGroupCells(group));
  table.Print(out);
}

void WriteSeedGroups(const std::vector<SeedGroup>& groups, const std::filesystem::path& file) {
  std::ostringstream csv;
  csv << "preset,seeds,sequences,runs,scored,to_end,mean_rmse_mm,sd_rmse_mm,median_rmse_mm,min_rmse_mm,max_rmse_mm,"
         "mean_map_scale_mm,mean_ate_mm\n";
  for (const SeedGroup& group : groups) {
    csv << CsvField(group.name) << ',' << Join(group.seeds, " ") << ',' << Join(group.sequences, " ") << ','
        << group.seeds.size() << ',' << group.scored << ',' << group.to_end;
    if (group.scored > 0) {
      csv << ',' << group.mean_rmse_mm << ',';
      if (group.scored > 1) csv << group.sd_rmse_mm;
      csv << ',' << group.median_rmse_mm << ','
          << group.min_rmse_mm << ',' << group.max_rmse_mm << ',' << RecordedField(group.mean_map_scale_mm) << ','
          << RecordedField(group.mean_ate_mm);
    } else {
      csv << ",,,,,,,";
    }
    csv << '\n';
  }
  WriteTextFile(file, csv.str());
}

}  // namespace nrslam
