#include "nrslam/batch/evaluation_plan.h"

#include <fstream>
#include <iomanip>
#include <sstream>

#include "nrslam/system/system_options.h"
#include "nrslam/util/process.h"

namespace nrslam {
namespace {

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

std::string LastName(const std::string& path) { return path.substr(path.rfind('.') + 1); }

std::vector<std::string> SplitList(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) items.push_back(item);
  return items;
}

void WriteFailure(const RunJob& run, const std::string& stage, const std::string& message) {
  std::filesystem::create_directories(run.run_folder);
  std::ofstream(run.run_folder / "failure.json") << Json{{"stage", stage}, {"error", message}}.dump(2) << '\n';
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

Sweep ParseSweep(const std::string& text) {
  const size_t equals = text.find('=');
  if (equals == std::string::npos || equals == 0 || equals + 1 == text.size()) {
    throw Error("--sweep '" + text + "': expected name=value1,value2,...");
  }
  Sweep sweep{ResolveRunOption(text.substr(0, equals)), SplitList(text.substr(equals + 1))};
  for (const std::string& value : sweep.values) {
    if (value.empty()) throw Error("--sweep '" + text + "': empty value");
  }
  return sweep;
}

EvaluationPlan PlanEvaluation(const Manifest& manifest, const std::vector<std::string>& extra,
                              const std::vector<Sweep>& sweeps, const std::filesystem::path& out,
                              const std::filesystem::path& cache) {
  EvaluationPlan plan;
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
    int render = -1;
    std::filesystem::path folder = sequence.path;
    if (!sequence.preset.empty()) {
      std::string key = sequence.preset;
      for (const std::string& assignment : sequence.simulate) key += "\n" + assignment;
      folder = cache_folder / (sequence.preset + "-" + StableHash(key));
      for (size_t i = 0; i < plan.renders.size() && render < 0; ++i) {
        if (plan.renders[i].folder == folder) render = static_cast<int>(i);
      }
      if (render < 0) {
        render = static_cast<int>(plan.renders.size());
        plan.renders.push_back({sequence.preset, sequence.simulate, folder});
      }
    }
    for (const auto& point : points) {
      RunJob run;
      run.sequence = sequence.name;
      run.point = point;
      for (const std::string& assignment : point) {
        run.label += (run.label.empty() ? "" : ",") + LastName(assignment.substr(0, assignment.find('='))) +
                     assignment.substr(assignment.find('='));
      }
      run.sequence_folder = folder;
      run.run_folder = out_folder / "runs" / sequence.name;
      if (!run.label.empty()) run.run_folder /= run.label;
      run.render = render;
      std::vector<std::string> assignments = sequence.assignments;
      assignments.insert(assignments.end(), extra.begin(), extra.end());
      assignments.insert(assignments.end(), point.begin(), point.end());
      SystemOptions options;
      options.tracking.rigid = sequence.rigid;
      try {
        WithAssignments(options, assignments);
      } catch (const Error& e) {
        throw Error("sequence '" + sequence.name + "'" + (run.label.empty() ? "" : " at " + run.label) + ": " +
                    e.what());
      }
      run.arguments = {folder.string(), "--out", run.run_folder.string(), "--quiet"};
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

std::string RenderShellLine(const RenderJob& render, const Programs& programs) {
  std::vector<std::string> argv = {programs.simulate.string(), "--preset", render.preset, "--quiet"};
  for (const std::string& assignment : render.simulate) {
    argv.push_back("--set");
    argv.push_back(assignment);
  }
  const std::string folder = ShellLine({render.folder.string()});
  const std::string partial = ShellLine({render.folder.string() + ".partial.XXXXXX"});
  // Render into a private folder and move it into place: a concurrent render of the same
  // preset on another machine loses the race harmlessly, an interrupted one leaves no trace.
  return "{ [ -d " + folder + " ] || { mkdir -p " + ShellLine({render.folder.parent_path().string()}) +
         " && T=$(mktemp -d " + partial + ") && " + ShellLine(argv) + " --out \"$T/sequence\"; mv -T \"$T/sequence\" " +
         folder + " 2>/dev/null; rm -rf \"$T\"; [ -d " + folder + " ]; }; }";
}

std::string RunShellLine(const EvaluationPlan& plan, const RunJob& run, const Programs& programs) {
  std::vector<std::string> argv = {programs.run.string()};
  argv.insert(argv.end(), run.arguments.begin(), run.arguments.end());
  const std::string command = ShellLine(argv);
  if (run.render < 0) return command;
  return RenderShellLine(plan.renders[run.render], programs) + " && " + command;
}

bool RunIsFinished(const RunJob& run) { return std::filesystem::exists(run.run_folder / "summary.json"); }

void ExecutePlan(const EvaluationPlan& plan, const Programs& programs, int jobs,
                 const std::function<void(const std::string&)>& progress) {
  // Renders first: several runs may share one.
  std::vector<Command> renders;
  std::vector<size_t> render_index;
  for (size_t i = 0; i < plan.renders.size(); ++i) {
    const RenderJob& render = plan.renders[i];
    if (std::filesystem::exists(render.folder)) continue;
    std::filesystem::create_directories(render.folder.parent_path());
    std::filesystem::remove_all(render.folder.string() + ".partial");
    Command command{{programs.simulate.string(), "--preset", render.preset, "--out", render.folder.string() + ".partial",
                     "--quiet"},
                    render.folder.string() + ".log"};
    for (const std::string& assignment : render.simulate) {
      command.argv.push_back("--set");
      command.argv.push_back(assignment);
    }
    renders.push_back(command);
    render_index.push_back(i);
  }
  std::vector<std::string> render_errors(plan.renders.size());
  RunCommands(renders, jobs, [&](size_t k, const ProcessOutcome& outcome) {
    const RenderJob& render = plan.renders[render_index[k]];
    if (outcome.ok()) {
      std::filesystem::rename(render.folder.string() + ".partial", render.folder);
      progress("rendered " + render.folder.filename().string());
    } else {
      const std::string why = LastLine(renders[k].log);
      render_errors[render_index[k]] = "rendering " + render.preset + " failed (" + outcome.Describe() + ")" +
                                       (why.empty() ? "" : ": " + why);
      progress(render_errors[render_index[k]]);
    }
  });

  std::vector<Command> runs;
  std::vector<size_t> run_index;
  size_t skipped = 0;
  for (size_t i = 0; i < plan.runs.size(); ++i) {
    const RunJob& run = plan.runs[i];
    if (RunIsFinished(run)) {
      ++skipped;
      continue;
    }
    std::filesystem::remove(run.run_folder / "failure.json");
    if (run.render >= 0 && !render_errors[run.render].empty()) {
      WriteFailure(run, "render", render_errors[run.render]);
      continue;
    }
    std::filesystem::create_directories(run.run_folder.parent_path());
    Command command{{programs.run.string()}, run.run_folder.string() + ".log"};
    command.argv.insert(command.argv.end(), run.arguments.begin(), run.arguments.end());
    runs.push_back(command);
    run_index.push_back(i);
  }
  if (skipped > 0) progress(std::to_string(skipped) + " run(s) already finished, not run again");
  size_t finished = 0;
  RunCommands(runs, jobs, [&](size_t k, const ProcessOutcome& outcome) {
    const RunJob& run = plan.runs[run_index[k]];
    const std::string name = run.sequence + (run.label.empty() ? "" : " [" + run.label + "]");
    const std::string counter = "[" + std::to_string(++finished) + "/" + std::to_string(runs.size()) + "] ";
    if (outcome.ok() && RunIsFinished(run)) {
      progress(counter + name + " done");
      return;
    }
    const std::string why = LastLine(runs[k].log);
    WriteFailure(run, "run", outcome.Describe() + (why.empty() ? "" : ": " + why));
    progress(counter + name + " FAILED (" + outcome.Describe() + ")" + (why.empty() ? "" : ": " + why));
  });
}

}  // namespace nrslam
