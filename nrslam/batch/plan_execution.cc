#include "nrslam/batch/plan_execution.h"

#include <algorithm>
#include <atomic>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <vector>

#include "nrslam/batch/sequence_cache.h"
#include "nrslam/io/sequence_info.h"
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

void WriteFailure(const RunJob& run, const std::string& stage, const std::string& message) {
  CreateFolder(run.run_folder);
  WriteTextFile(run.run_folder / "failure.json", Json{{"stage", stage}, {"error", message}}.dump(2) + '\n');
}

// The message a program ended its log with, where the programs put their error: its last
// line that is not indented, with the indented list under it (a sequence's bad files, say) on
// one line. A long list gives its first items and says where the rest is: its last line alone
// would be "25 more bad files in rgb/", which names neither the sequence nor the fault.
std::string ClosingMessage(const std::filesystem::path& log, const std::filesystem::path& kept_as) {
  constexpr size_t kItemsShown = 3;
  std::ifstream stream(log);
  std::string line, heading;
  std::vector<std::string> items;
  while (std::getline(stream, line)) {
    const size_t carriage = line.rfind('\r');  // progress lines overwrite themselves
    if (carriage != std::string::npos) line = line.substr(carriage + 1);
    const size_t start = line.find_first_not_of(" \t");
    if (start == std::string::npos) continue;
    if (start == 0 || heading.empty()) {
      heading = line.substr(start);
      items.clear();
    } else {
      items.push_back(line.substr(line.compare(start, 2, "- ") == 0 ? start + 2 : start));
    }
  }
  std::string message = heading;
  for (size_t i = 0; i < std::min(items.size(), kItemsShown); ++i) {
    message += (i == 0 && !message.empty() && message.back() == ':' ? " " : "; ") + items[i];
  }
  if (items.size() > kItemsShown) {
    message += "; " + std::to_string(items.size() - kItemsShown) + " more line(s) in " + kept_as.string();
  }
  return message;
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
    Command command{PrepareCommand(prepare, programs), CacheLog(partial)};
    command.argv.insert(command.argv.end(), {"--out", partial.string()});
    prepares.push_back(command);
    prepare_index.push_back(i);
    partials.push_back(partial);
  }
  std::vector<std::string> prepare_errors(plan.prepares.size());
  RunCommands(prepares, jobs, [&](size_t k, const ProcessOutcome& outcome) {
    const PrepareJob& prepare = plan.prepares[prepare_index[k]];
    const std::filesystem::path& partial = partials[k];
    const std::string why = ClosingMessage(prepares[k].log, CacheLog(prepare.folder));
    std::error_code not_moved;
    if (outcome.ok()) std::filesystem::rename(partial, prepare.folder, not_moved);
    // Another evaluation that prepared the same sequence first made the same files.
    const bool ready = outcome.ok() && (!not_moved || std::filesystem::exists(prepare.folder));
    std::error_code ignored;
    std::filesystem::rename(prepares[k].log, CacheLog(prepare.folder), ignored);
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
    const std::string why = ClosingMessage(runs[k].log, runs[k].log);
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
