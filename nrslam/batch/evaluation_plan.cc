#include "nrslam/batch/evaluation_plan.h"

#include <algorithm>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>

#include "nrslam/batch/sequence_cache.h"
#include "nrslam/sim/sim_options.h"
#include "nrslam/system/system_options.h"
#include "nrslam/util/error.h"
#include "nrslam/util/json_options.h"

namespace nrslam {
namespace {

// Sweep paths of simulator options start with this; the rest is nrslam_simulate's path.
constexpr std::string_view kSimulatorPrefix = "simulate.";

// `simulate` (a sequence's simulator assignments) with `assignment` ("path=value") in place of
// any it had for that path, sorted, since the render's cache key is made from them in order.
void OverrideAssignment(std::vector<std::string>* simulate, const std::string& assignment) {
  const std::string path = assignment.substr(0, assignment.find('=') + 1);  // "a.b="
  simulate->erase(std::remove_if(simulate->begin(), simulate->end(),
                                 [&](const std::string& a) { return a.compare(0, path.size(), path) == 0; }),
                  simulate->end());
  simulate->push_back(assignment);
  std::sort(simulate->begin(), simulate->end());
}

std::vector<std::string> SplitList(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) items.push_back(item);
  return items;
}

}  // namespace

bool IsSimulatorAssignment(const std::string& assignment) {
  return assignment.compare(0, kSimulatorPrefix.size(), kSimulatorPrefix) == 0;
}

std::string SimulatorAssignment(const std::string& assignment) { return assignment.substr(kSimulatorPrefix.size()); }

Sweep ParseSweep(const std::string& text) {
  const size_t equals = text.find('=');
  if (equals == std::string::npos || equals == 0 || equals + 1 == text.size()) {
    throw Error("--sweep '" + text + "': expected name=value1,value2,...");
  }
  const std::string name = text.substr(0, equals);
  static const std::vector<std::string> simulator_paths = LeafPaths(Json(SimOptions{}));
  std::string path;
  if (IsSimulatorAssignment(name)) {
    const std::string simulator_path =
        ResolveOptionName(SimulatorAssignment(name), simulator_paths, "--sweep: simulator option");
    // Seeds make renderings of the same scene family; they have their own flag and summary.
    if (simulator_path == "seed") throw Error("--sweep: sweep the scene seed with --seeds, e.g. --seeds 1-3");
    path = std::string(kSimulatorPrefix) + simulator_path;
  } else {
    try {
      path = ResolveRunOption(name);
    } catch (const Error&) {
      // A simulator option given without its prefix gets the spelling that sweeps it.
      const std::optional<std::string> simulator = FindOptionName(name, simulator_paths);
      if (!simulator) throw;
      throw Error("--sweep: '" + name + "' is a simulator option; to render the presets anew for each value, sweep " +
                  std::string(kSimulatorPrefix) + *simulator);
    }
  }
  Sweep sweep{path, SplitList(text.substr(equals + 1))};
  for (const std::string& value : sweep.values) {
    if (value.empty()) throw Error("--sweep '" + text + "': empty value");
  }
  return sweep;
}

bool IsSeedAssignment(const std::string& assignment) { return assignment.rfind("seed=", 0) == 0; }

std::vector<uint64_t> ParseSeedList(const std::string& text) {
  const auto number = [&text](const std::string& digits) {
    if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos || digits.size() > 18) {
      throw Error("--seeds '" + text + "': expected seeds and ranges such as 1-3,7");
    }
    return std::stoull(digits);
  };
  std::vector<uint64_t> seeds;
  for (const std::string& item : SplitList(text)) {
    const size_t dash = item.find('-');
    const uint64_t first = number(item.substr(0, dash));
    const uint64_t last = dash == std::string::npos ? first : number(item.substr(dash + 1));
    if (last < first) throw Error("--seeds '" + text + "': range " + item + " runs backwards");
    if (last - first >= 1000) throw Error("--seeds '" + text + "': range " + item + " has more than 1000 seeds");
    for (uint64_t seed = first; seed <= last; ++seed) {
      if (std::find(seeds.begin(), seeds.end(), seed) != seeds.end()) {
        throw Error("--seeds '" + text + "': seed " + std::to_string(seed) + " is given twice");
      }
      seeds.push_back(seed);
    }
  }
  if (seeds.empty()) throw Error("--seeds '" + text + "': no seed given");
  return seeds;
}

Manifest WithSceneSeeds(const Manifest& manifest, const std::vector<uint64_t>& seeds) {
  Manifest seeded = manifest;
  seeded.sequences.clear();
  std::set<std::string> names;
  const auto add = [&](const ManifestSequence& sequence) {
    if (!names.insert(sequence.name).second) {
      throw Error("--seeds: two sequences would be named '" + sequence.name + "'; rename one in the manifest");
    }
    seeded.sequences.push_back(sequence);
  };
  for (const ManifestSequence& sequence : manifest.sequences) {
    if (sequence.preset.empty() || sequence.is_external()) {
      add(sequence);
      continue;
    }
    for (const uint64_t seed : seeds) {
      ManifestSequence copy = sequence;
      copy.name += "-seed" + std::to_string(seed);
      OverrideAssignment(&copy.simulate, Assignment("seed", Json(seed)));
      add(copy);
    }
  }
  return seeded;
}

namespace {

// The render or import that makes `sequence`'s folder, added to the plan once however many
// runs read it: its index in plan->prepares, or -1 for a sequence already on disk.
int AddPrepare(const ManifestSequence& sequence, const std::filesystem::path& cache_folder, EvaluationPlan* plan) {
  if (sequence.preset.empty() && sequence.import.empty()) return -1;
  PrepareJob job;
  job.import = !sequence.import.empty();
  if (job.import) {
    job.arguments = sequence.import;
    for (size_t i = 0; i + 1 < job.arguments.size(); i += 2) {
      if (job.arguments[i] == "--format" || job.arguments[i] == "--in") {
        job.description += (job.description.empty() ? "" : " ") + job.arguments[i + 1];
      }
    }
  } else {
    job.arguments = {"--preset", sequence.preset, "--quiet"};
    for (const std::string& assignment : sequence.simulate) {
      job.arguments.push_back("--set");
      job.arguments.push_back(assignment);
    }
    job.description = sequence.preset;
  }
  job.folder = CachedSequenceFolder(cache_folder, job.import ? sequence.name : sequence.preset, job.arguments);
  for (size_t i = 0; i < plan->prepares.size(); ++i) {
    if (plan->prepares[i].folder == job.folder) return static_cast<int>(i);
  }
  plan->prepares.push_back(job);
  return static_cast<int>(plan->prepares.size()) - 1;
}

// `sequence` rendered with a sweep point's simulator assignments over its own.
ManifestSequence WithSimulatorPoint(ManifestSequence sequence, const std::vector<std::string>& point) {
  for (const std::string& assignment : point) {
    if (IsSimulatorAssignment(assignment)) OverrideAssignment(&sequence.simulate, SimulatorAssignment(assignment));
  }
  WithAssignments(SimPreset(sequence.preset), sequence.simulate);  // throws on a value out of range
  return sequence;
}

// The folder a sweep point's runs go to, named by its label. A value can be a path
// (`--sweep simulate.camera.calibration=/data/lens.yml`): '/' is percent-encoded (and '%', so
// that two labels never share a folder), so a value neither nests folders nor climbs out of --out.
std::string LabelFolderName(const std::string& label) {
  std::string name;
  for (char c : label) name += c == '/' ? "%2F" : c == '%' ? "%25" : std::string(1, c);
  return name;
}

}  // namespace

void RejectSetAndSwept(const std::vector<std::string>& set_assignments, const std::vector<Sweep>& sweeps) {
  for (const std::string& assignment : set_assignments) {
    const std::string path = assignment.substr(0, assignment.find('='));
    for (const Sweep& sweep : sweeps) {
      if (sweep.path == path) {
        throw Error("--set " + assignment + " and --sweep " + path + ": the sweep would set it in every run; give one of them");
      }
    }
  }
}

std::string RunName(const std::string& sequence, const std::string& label) {
  return label.empty() ? sequence : sequence + " [" + label + "]";
}

EvaluationPlan PlanEvaluation(const Manifest& manifest, const std::vector<std::string>& extra,
                              const std::vector<Sweep>& sweeps, const std::filesystem::path& out,
                              const std::filesystem::path& cache) {
  EvaluationPlan plan;
  // A point given twice would be two runs writing into one folder at once; an option swept
  // twice would leave one of its sweeps without effect; two options with one last name would
  // label their runs alike.
  std::set<std::string> swept, labels;
  bool simulator_sweep = false;
  for (const Sweep& sweep : sweeps) {
    if (!swept.insert(sweep.path).second) throw Error("--sweep: " + sweep.path + " is swept twice");
    if (!labels.insert(LastName(sweep.path)).second) {
      throw Error("--sweep: two swept options are named '" + LastName(sweep.path) +
                  "', and a run folder is labelled by that name");
    }
    simulator_sweep |= IsSimulatorAssignment(sweep.path);
    std::set<std::string> values;
    for (const std::string& value : sweep.values) {
      if (!values.insert(value).second) throw Error("--sweep " + sweep.path + ": value " + value + " is given twice");
    }
  }
  // The grid of sweep points, each a list of "path=value".
  std::vector<std::vector<std::string>> points = {{}};
  for (const Sweep& sweep : sweeps) {
    std::vector<std::vector<std::string>> grown;
    for (const auto& point : points) {
      for (const std::string& value : sweep.values) {
        grown.push_back(point);
        grown.back().push_back(sweep.path + "=" + value);
      }
    }
    points = grown;
  }
  const std::filesystem::path cache_folder = std::filesystem::absolute(cache);
  const std::filesystem::path out_folder = std::filesystem::absolute(out);
  for (const ManifestSequence& sequence : manifest.sequences) {
    if (sequence.is_external()) {
      const int prepare = AddPrepare(sequence, cache_folder, &plan);
      const std::filesystem::path folder = prepare < 0 ? sequence.path : plan.prepares[prepare].folder;
      RunJob run;
      run.sequence = sequence.name;
      run.sequence_folder = folder;
      run.run_folder = out_folder / "runs" / sequence.name;
      run.prepare = prepare;
      run.external = ToJson(sequence.external);
      run.arguments = {"score", folder.string(), sequence.external.estimates.string(), "--out", run.run_folder.string(),
                       "--stride", std::to_string(sequence.external.depth_stride_px)};
      if (!sequence.external.trajectory.empty()) {
        run.arguments.insert(run.arguments.end(), {"--trajectory", sequence.external.trajectory.string()});
      }
      if (!sequence.external.name.empty()) run.arguments.insert(run.arguments.end(), {"--name", sequence.external.name});
      plan.runs.push_back(std::move(run));
      continue;
    }
    if (simulator_sweep && sequence.preset.empty()) {
      throw Error("--sweep of a simulator option: sequence '" + sequence.name +
                  "' is not rendered from a preset, so it cannot be rendered anew; leave it out with --only");
    }
    for (const auto& point : points) {
      RunJob run;
      run.sequence = sequence.name;
      run.point = point;
      for (const std::string& assignment : point) {
        run.label += (run.label.empty() ? "" : ",") + LastName(assignment.substr(0, assignment.find('='))) +
                     assignment.substr(assignment.find('='));
      }
      const std::string where = "sequence '" + sequence.name + "'" + (run.label.empty() ? "" : " at " + run.label);
      ManifestSequence rendered = sequence;
      if (simulator_sweep) {
        try {
          rendered = WithSimulatorPoint(sequence, point);
        } catch (const Error& e) {
          throw Error(where + ": simulate: " + e.what());
        }
      }
      run.prepare = AddPrepare(rendered, cache_folder, &plan);
      run.sequence_folder = run.prepare < 0 ? sequence.path : plan.prepares[run.prepare].folder;
      run.run_folder = out_folder / "runs" / sequence.name;
      if (!run.label.empty()) run.run_folder /= LabelFolderName(run.label);
      std::vector<std::string> assignments = sequence.assignments;
      assignments.insert(assignments.end(), extra.begin(), extra.end());
      for (const std::string& assignment : point) {
        if (!IsSimulatorAssignment(assignment)) assignments.push_back(assignment);
      }
      SystemOptions options;
      options.tracking.rigid = sequence.rigid;
      try {
        run.options = WithAssignments(options, assignments);
      } catch (const Error& e) {
        throw Error(where + ": " + e.what());
      }
      run.arguments = {run.sequence_folder.string(), "--out", run.run_folder.string(), "--quiet"};
      if (sequence.rigid) run.arguments.push_back("--rigid");
      for (const std::string& assignment : assignments) {
        run.arguments.push_back("--set");
        run.arguments.push_back(assignment);
      }
      plan.runs.push_back(std::move(run));
    }
  }
  return plan;
}

}  // namespace nrslam
