// sim: renders a whole sequence folder (the format io reads) from simulator options.
#pragma once

#include <filesystem>
#include <functional>
#include <string>

#include "nrslam/sim/sim_options.h"

namespace nrslam {

struct SimulationSummary {
  std::string name;
  int frames = 0;
  int width = 0;
  int height = 0;
  double depth_min_mm = 0.0;   // over valid ground-truth pixels of all frames
  double depth_max_mm = 0.0;
  double render_ms_per_frame = 0.0;  // rendering only, file writing excluded
  double write_ms_per_frame = 0.0;
};

// Called after each frame with (frames done, frames total, mean render ms so far).
using SimulationProgress = std::function<void(int, int, double)>;

// Writes the sequence into `folder` (created; existing frames are overwritten). `name` goes
// into the provenance. Throws Error on invalid options or unwritable output.
SimulationSummary SimulateSequence(const SimOptions& options, const std::string& name,
                                   const std::filesystem::path& folder, const SimulationProgress& progress = {});

}  // namespace nrslam
