// benchmarks: the options a benchmark times, from its --set list (as nrslam_run's).
#pragma once

#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "nrslam/system/system_options.h"
#include "nrslam/util/error.h"

// The defaults with `assignments` applied. The options that differ from the defaults are
// printed first, so that a table says what it timed; a bad assignment is printed as an error
// and gives nullopt.
inline std::optional<nrslam::SystemOptions> BenchmarkOptions(const std::vector<std::string>& assignments) {
  try {
    const nrslam::SystemOptions options = nrslam::WithRunAssignments(nrslam::SystemOptions{}, assignments);
    for (const std::string& changed : nrslam::AssignmentsOverDefaults(options)) std::printf("set %s\n", changed.c_str());
    return options;
  } catch (const nrslam::Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return std::nullopt;
  }
}
