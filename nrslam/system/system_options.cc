#include "nrslam/system/system_options.h"

#include <string>
#include <vector>

#include "nrslam/util/json_options.h"

namespace nrslam {

void RunOptions::Check() const {
  CheckOption(init == "depth" || init == "monocular", "run", "init must be depth or monocular, got '" + init + "'");
  CheckOption(first_frame >= 0, "run", "first_frame must be >= 0, got " + std::to_string(first_frame));
  // Only -1 means "to the end": -5 read as "all but the last 5" would run the whole sequence.
  CheckOption(last_frame >= -1, "run",
              "last_frame must be -1 (to the end) or a frame number, got " + std::to_string(last_frame));
  CheckOption(last_frame == -1 || last_frame > first_frame, "run",
              "the frame range [first_frame, last_frame) = [" + std::to_string(first_frame) + ", " +
                  std::to_string(last_frame) + ") is empty (last_frame -1 = to the end)");
  CheckOption(restart_on_depth_change == 0 || restart_on_depth_change > 1, "run",
              "restart_on_depth_change must be 0 (never) or a factor above 1, got " +
                  std::to_string(restart_on_depth_change));
}

SystemOptions SystemOptionsFromFile(const std::filesystem::path& file) {
  const Json given = ReadJsonFile(file);
  if (!given.is_object()) throw Error(file.string() + ": options must be a JSON object");
  // A run folder's config.json also records the sequence, camera and version it ran with.
  const bool run_config = given.contains("options") && given.contains("nrslam_version");
  return OptionsFromJson<SystemOptions>(run_config ? given.at("options") : given, file.string());
}

std::vector<std::string> AssignmentsOverDefaults(const SystemOptions& options) {
  return ChangedAssignments(Json(SystemOptions{}), Json(options));
}

const std::vector<std::string>& RunOptionPaths() {
  static const std::vector<std::string> paths = LeafPaths(Json(SystemOptions{}));
  return paths;
}

std::string ResolveRunOption(const std::string& name) { return ResolveOptionName(name, RunOptionPaths(), "option"); }

std::string ResolveRunAssignment(const std::string& assignment) {
  const size_t equals = assignment.find('=');
  if (equals == std::string::npos) throw Error("--set '" + assignment + "': expected name=value");
  return ResolveRunOption(assignment.substr(0, equals)) + assignment.substr(equals);
}

SystemOptions WithRunAssignments(const SystemOptions& options, const std::vector<std::string>& assignments) {
  std::vector<std::string> resolved;
  for (const std::string& assignment : assignments) resolved.push_back(ResolveRunAssignment(assignment));
  return WithAssignments(options, resolved);
}

}  // namespace nrslam
