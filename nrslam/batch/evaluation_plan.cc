#include "nrslam/batch/evaluation_plan.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <fstream>
#include <iomanip>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>

#include "nrslam/io/sequence_info.h"
#include "nrslam/sim/sim_options.h"
#include "nrslam/system/system_options.h"
#include "nrslam/util/error.h"
#include "nrslam/util/folder.h"
#include "nrslam/util/json_options.h"
#include "nrslam/util/process.h"
#include "nrslam/util/source_revision.h"
#include "nrslam/util/text_file.h"
#include "nrslam/util/text_table.h"

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

// FNV-1a: a cache key that is the same on every machine and build.
std::string StableHash(const std::string& text) {
  uint64_t hash = 1469598103934665603ull;
  for (unsigned char c : text) {
    hash ^= c;
    hash *= 1099511628211ull;
  }
  std::ostringstream hex;
  hex << std::hex << std::setw(16) << std::setfill('0') << hash;
  return hex.str().substr(0, 12);
}

std::vector<std::string> SplitList(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) items.push_back(item);
  return items;
}

void WriteFailure(const RunJob& run, const std::string& stage, const std::string& message) {
  CreateFolder(run.run_folder);
  WriteTextFile(run.run_folder / "failure.json", Json{{"stage", stage}, {"error", message}}.dump(2) + '\n');
}

// The last non-empty line of a log, where the programs put their error message.
std::string LastLine(const std::filesystem::path& log) {
  std::ifstream stream(log);
  std::string line, last;
  while (std::getline(stream, line)) {
    const size_t carriage = line.rfind('\r');  // progress lines overwrite themselves
    if (carriage != std::string::npos) line = line.substr(carriage + 1);
    if (line.find_first_not_of(" \t") != std::string::npos) last = line;
  }
  return last;
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
  // The code that makes sequences is part of the key: a render or import by other code (an
  // importer since mended, a simulator since changed) is made again, not silently reused.
  std::string key = std::string("code ") + SequenceCodeFingerprint() + "\n";
  for (const std::string& argument : job.arguments) key += argument + "\n";
  const std::string stem = job.import ? sequence.name : sequence.preset;
  job.folder = cache_folder / (stem + "-" + StableHash(key));
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

namespace {

std::string HostName() {
  char host[256] = {};
  ::gethostname(host, sizeof(host) - 1);
  return host;
}

// Where a sequence is prepared before it is moved into place: <folder>.partial.<host>-<pid>-<n>.
// Evaluations that share a cache may prepare the same sequence at once; each writes only into a
// folder of its own.
std::filesystem::path PartialFolder(const std::filesystem::path& folder) {
  static std::atomic<int> count{0};
  return folder.string() + ".partial." + HostName() + "-" + std::to_string(::getpid()) + "-" +
         std::to_string(count++);
}

// Removes the partial folders (and their logs) in `cache` that interrupted evaluations on this
// machine left behind: those whose process is gone. A cache shared between machines keeps the
// others'.
void RemoveAbandonedPartials(const std::filesystem::path& cache) {
  const std::string marker = ".partial." + HostName() + "-";
  std::error_code unreadable;
  for (const auto& entry : std::filesystem::directory_iterator(cache, unreadable)) {
    const std::string name = entry.path().filename().string();
    const size_t at = name.find(marker);
    if (at == std::string::npos) continue;
    const std::string pid = name.substr(at + marker.size(), name.find('-', at + marker.size()) - at - marker.size());
    if (pid.empty() || pid.size() > 9 || pid.find_first_not_of("0123456789") != std::string::npos) continue;
    if (!ProcessIsRunning(std::stoi(pid))) {
      std::error_code ignored;
      std::filesystem::remove_all(entry.path(), ignored);
    }
  }
}

const std::filesystem::path& ProgramOf(const RunJob& run, const Programs& programs) {
  return run.is_external() ? programs.eval : programs.run;
}

std::vector<std::string> PrepareCommand(const PrepareJob& prepare, const Programs& programs) {
  std::vector<std::string> argv = {(prepare.import ? programs.import : programs.simulate).string()};
  argv.insert(argv.end(), prepare.arguments.begin(), prepare.arguments.end());
  return argv;
}

}  // namespace

std::string PrepareShellLine(const PrepareJob& prepare, const Programs& programs) {
  const std::string folder = ShellLine({prepare.folder.string()});
  const std::string partial = ShellLine({prepare.folder.string() + ".partial.XXXXXX"});
  // Make it in a private folder and move that into place: a concurrent job on another
  // machine loses the race harmlessly, an interrupted one leaves no trace.
  return "{ [ -d " + folder + " ] || { mkdir -p " + ShellLine({prepare.folder.parent_path().string()}) +
         " && T=$(mktemp -d " + partial + ") && " + ShellLine(PrepareCommand(prepare, programs)) +
         " --out \"$T/sequence\"; mv -T \"$T/sequence\" " + folder + " 2>/dev/null; rm -rf \"$T\"; [ -d " + folder +
         " ]; }; }";
}

std::string RunShellLine(const EvaluationPlan& plan, const RunJob& run, const Programs& programs) {
  std::vector<std::string> argv = {ProgramOf(run, programs).string()};
  argv.insert(argv.end(), run.arguments.begin(), run.arguments.end());
  const std::string command = ShellLine(argv);
  if (run.prepare < 0) return command;
  return PrepareShellLine(plan.prepares[run.prepare], programs) + " && " + command;
}

bool RunIsFinished(const RunJob& run) {
  if (!std::filesystem::exists(run.run_folder / "summary.json")) return false;
  try {
    const Json config = ReadJsonFile(run.run_folder / "config.json");
    // The same folder holding another description (a calibration corrected, frames added) is
    // another sequence.
    const bool same_sequence =
        config.at("sequence").get<std::string>() == std::filesystem::absolute(run.sequence_folder).string() &&
        config.value("sequence_info", Json()) ==
            Json(ReadJsonFile(run.sequence_folder / "sequence.json").get<SequenceInfo>());
    if (run.is_external()) return config.value("external", Json()) == run.external && same_sequence;
    // Parsed back through the options struct, so that a config written before an option
    // existed compares as that option's default.
    const Json options = OptionsFromJson<SystemOptions>(config.at("options"), "config.json");
    // By the code's fingerprint, not its commit: a commit of documentation alone keeps the runs.
    const bool same_code = config.value("nrslam_code", "") == CodeFingerprint();
    return options == run.options && same_sequence && same_code;
  } catch (const std::exception&) {
    return false;  // unreadable, or from a version with options this one lacks: run it again
  }
}

std::string DescribePlan(const EvaluationPlan& plan) {
  std::ostringstream details;
  int to_prepare = 0, finished = 0;
  for (const PrepareJob& prepare : plan.prepares) {
    const bool cached = std::filesystem::exists(prepare.folder);
    to_prepare += !cached;
    details << (cached ? "  in the cache  " : prepare.import ? "  to import     " : "  to render     ")
            << prepare.description;
    for (size_t i = 0; i + 1 < prepare.arguments.size(); ++i) {
      if (prepare.arguments[i] == "--set") details << ' ' << prepare.arguments[i + 1];  // what sets renders apart
    }
    details << "  " << prepare.folder.string() << '\n';
  }
  for (const RunJob& run : plan.runs) {
    const bool done = RunIsFinished(run);
    finished += done;
    details << (done ? "  finished      " : "  to run        ") << RunName(run.sequence, run.label) << '\n';
  }
  std::ostringstream text;
  text << to_prepare << " sequence(s) to render or import, " << plan.prepares.size() - to_prepare
       << " already in the cache; " << plan.runs.size() - finished << " run(s) to run, " << finished
       << " finished before (kept)\n"
       << details.str();
  return text.str();
}

void CheckRunProgramCode(const std::filesystem::path& run_program) {
  const std::optional<std::string> version = CommandOutput({run_program.string(), "--version"}, 5);
  if (!version) return;
  const std::string marker = "code ";
  const size_t start = version->rfind(marker);
  const size_t end = start == std::string::npos ? start : version->find(')', start);
  if (end == std::string::npos) return;
  const std::string code = version->substr(start + marker.size(), end - start - marker.size());
  if (code != CodeFingerprint()) {
    throw Error(run_program.string() + " is built from other code (" + code + ") than this nrslam_eval (" +
                CodeFingerprint() + "); its runs would never count as finished. Rebuild every tool (e.g. make -C build)");
  }
}

void ExecutePlan(const EvaluationPlan& plan, const Programs& programs, int jobs,
                 const std::function<void(const std::string&)>& progress, double run_timeout_seconds,
                 const std::atomic<bool>* stop) {
  const auto stopped = [stop] { return stop && *stop; };
  // Each run's config.json is read once, here.
  std::vector<bool> finished_before(plan.runs.size());
  bool runs_ours = false;
  for (size_t i = 0; i < plan.runs.size(); ++i) {
    finished_before[i] = RunIsFinished(plan.runs[i]);
    runs_ours = runs_ours || (!finished_before[i] && !plan.runs[i].is_external());
  }
  if (runs_ours) CheckRunProgramCode(programs.run);  // before anything is rendered or removed
  // Sequences first: several runs may share one.
  std::vector<Command> prepares;
  std::vector<size_t> prepare_index;
  std::vector<std::filesystem::path> partials;
  std::set<std::filesystem::path> caches;
  for (const PrepareJob& prepare : plan.prepares) caches.insert(prepare.folder.parent_path());
  for (const std::filesystem::path& cache : caches) RemoveAbandonedPartials(cache);
  for (size_t i = 0; i < plan.prepares.size(); ++i) {
    const PrepareJob& prepare = plan.prepares[i];
    if (std::filesystem::exists(prepare.folder)) continue;
    CreateFolder(prepare.folder.parent_path());
    const std::filesystem::path partial = PartialFolder(prepare.folder);
    Command command{PrepareCommand(prepare, programs), partial.string() + ".log"};
    command.argv.insert(command.argv.end(), {"--out", partial.string()});
    prepares.push_back(command);
    prepare_index.push_back(i);
    partials.push_back(partial);
  }
  std::vector<std::string> prepare_errors(plan.prepares.size());
  RunCommands(prepares, jobs, [&](size_t k, const ProcessOutcome& outcome) {
    const PrepareJob& prepare = plan.prepares[prepare_index[k]];
    const std::filesystem::path& partial = partials[k];
    const std::string why = LastLine(prepares[k].log);
    std::error_code not_moved;
    if (outcome.ok()) std::filesystem::rename(partial, prepare.folder, not_moved);
    // Another evaluation that prepared the same sequence first made the same files.
    const bool ready = outcome.ok() && (!not_moved || std::filesystem::exists(prepare.folder));
    std::error_code ignored;
    std::filesystem::rename(prepares[k].log, prepare.folder.string() + ".log", ignored);
    std::filesystem::remove_all(partial, ignored);
    if (outcome.interrupted) return;
    const std::string verb = prepare.import ? "imported " : "rendered ";
    if (ready) {
      progress(verb + prepare.folder.filename().string());
    } else {
      const std::string how = outcome.ok() ? "its folder could not be moved into place: " + not_moved.message()
                                           : outcome.Describe();
      prepare_errors[prepare_index[k]] = (prepare.import ? "importing " : "rendering ") + prepare.description +
                                         " failed (" + how + ")" + (why.empty() ? "" : ": " + why);
      progress(prepare_errors[prepare_index[k]]);
    }
  }, stop);

  std::vector<Command> runs;
  std::vector<size_t> run_index;
  size_t skipped = 0, superseded = 0;
  for (size_t i = 0; i < plan.runs.size(); ++i) {
    const RunJob& run = plan.runs[i];
    if (finished_before[i]) {
      ++skipped;
      continue;
    }
    if (std::filesystem::exists(run.run_folder / "summary.json")) {
      ++superseded;  // a finished run of other options: none of its files may outlive it
      std::filesystem::remove_all(run.run_folder);
    }
    std::filesystem::remove(run.run_folder / "failure.json");
    if (run.prepare >= 0 && !prepare_errors[run.prepare].empty()) {
      WriteFailure(run, "prepare", prepare_errors[run.prepare]);
      continue;
    }
    CreateFolder(run.run_folder.parent_path());
    Command command{{ProgramOf(run, programs).string()}, run.run_folder.string() + ".log", run_timeout_seconds};
    command.argv.insert(command.argv.end(), run.arguments.begin(), run.arguments.end());
    runs.push_back(command);
    run_index.push_back(i);
  }
  if (skipped > 0) progress(std::to_string(skipped) + " run(s) already finished, not run again");
  if (superseded > 0) {
    progress(std::to_string(superseded) +
             " run(s) in the output folder had other options, another or changed sequence, changed estimates or "
             "other code: run again");
  }
  size_t finished = 0, interrupted = 0;
  double run_seconds = 0;
  RunCommands(runs, jobs, [&](size_t k, const ProcessOutcome& outcome) {
    const RunJob& run = plan.runs[run_index[k]];
    const std::string name = RunName(run.sequence, run.label);
    const std::string counter = "[" + std::to_string(++finished) + "/" + std::to_string(runs.size()) + "] ";
    run_seconds += outcome.wall_seconds;
    if (outcome.ok() && RunIsFinished(run)) {
      // The runs left at the mean time of those finished, `jobs` at a time: a sweep of hours
      // says when it will end.
      const size_t left = runs.size() - finished;
      const double estimate = run_seconds / finished * left / std::min<size_t>(left, std::max(1, jobs));
      progress(counter + name + " done in " + FormatDuration(outcome.wall_seconds) +
               (left == 0 ? "" : "; about " + FormatDuration(estimate) + " left"));
      return;
    }
    if (outcome.interrupted || stopped()) {
      ++interrupted;  // not a failure of the run: it is left unfinished, for the next evaluation
      return;
    }
    const std::string why = LastLine(runs[k].log);
    const std::string how = outcome.ok() ? "exited with 0 but left no finished run" : outcome.Describe();
    WriteFailure(run, "run", how + (why.empty() ? "" : ": " + why));
    progress(counter + name + " FAILED (" + how + ")" + (why.empty() ? "" : ": " + why));
  }, stop);
  if (interrupted > 0) {
    progress(std::to_string(interrupted) +
             " run(s) interrupted and left unfinished: the next evaluation into this folder runs them");
  }
}

}  // namespace nrslam
