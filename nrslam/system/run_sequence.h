// system: runs one sequence offline and writes its run folder:
//   config.json     every resolved option, the sequence and the version
//   trajectory.tum  world_from_camera per tracked frame, real timestamps
//   points.csv      frame, point id, u, v, z_est (camera depth, map units), world X Y Z, status
//   depth/NNNNNN.png  estimated depth: points splatted at their pixels, in mm (frame scale),
//                   16-bit in the sequence's depth unit, 0 = none
//   metrics.csv     per frame: state, points, outliers, scale, RMSE, flat-map RMSE, ms per stage
//   summary.json    rmse_mm, rmse_median_mm, rmse_pooled_mm, rmse_flat_mm, rmse_map_scale_mm,
//                   rmse_median_scale_mm, frames_tracked, frames_total, init_frame, fps, peak_memory_mb,
//                   ms per stage, maps, map_points, how far from the map's scale new points
//                   were born (births_evaluated, birth_log_error_mean / _median), the share of
//                   the image left out as static (static_fraction) and the status
//   map.ply         the final map points, coloured
//   static_mask.png where the run found the image never changing and left it out (255), if anywhere
//   run.log         what happened, in words
#pragma once

#include <filesystem>
#include <functional>
#include <string>

#include "nrslam/system/run_files.h"
#include "nrslam/system/system_options.h"

namespace nrslam {

using RunProgress = std::function<void(int frame, int total, const std::string& line)>;

// Throws Error for a bad sequence or options (before anything is written); a lost track is a
// recorded outcome, not an error.
RunSummary RunSequence(const std::filesystem::path& sequence, const SystemOptions& options,
                       const std::filesystem::path& out, const RunProgress& progress = {});

}  // namespace nrslam
