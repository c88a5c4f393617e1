// system: runs one sequence offline and writes its run folder:
//   config.json     every resolved option, the sequence and the version
//   trajectory.tum  world_from_camera per tracked frame, real timestamps
//   points.csv      frame, point id, u, v, z_est (camera depth, map units), world X Y Z, status
//   depth/NNNNNN.png  estimated depth: points splatted at their pixels, in mm (frame scale),
//                   16-bit in the sequence's depth unit, 0 = none
//   metrics.csv     per frame: state, points, outliers, scale, RMSE, flat-map RMSE, ms per stage
//   summary.json    rmse_mm, rmse_median_mm, rmse_pooled_mm, rmse_flat_mm, frames_tracked, frames_total,
//                   init_frame, fps, ms per stage, maps, map_points and the run's status
//   map.ply         the final map points, coloured
//   run.log         what happened, in words
#pragma once

#include <filesystem>
#include <functional>
#include <string>

#include "nrslam/eval/trajectory_error.h"
#include "nrslam/system/system_options.h"

namespace nrslam {

struct RunSummary {
  double rmse_mm = 0, rmse_median_mm = 0, rmse_pooled_mm = 0;
  double rmse_flat_mm = 0;  // the same points all at one depth (eval/depth_evaluation.h)
  int frames_tracked = 0;  // frames with a pose after initialisation (the paper's "# Fr.")
  int frames_total = 0;
  int frames_lost = 0;
  int init_frame = -1;
  int frames_evaluated = 0;
  double fps = 0;          // frames processed per second of wall time (reading included)
  // Mean milliseconds per processed frame in each stage (the mapping stages run on some frames only).
  double ms_initialisation = 0, ms_tracking = 0, ms_dba = 0, ms_triangulation = 0;
  double ms_tracking_linear_solve = 0;  // of ms_tracking: the joint solves' linear solver
  TrajectoryError trajectory_error;  // camera centres aligned to the ground-truth poses per map
  int maps = 0;            // maps started (a monocular run starts a new one after a loss)
  size_t map_points = 0;   // points in the last map
  // A run that ends without tracking: the first frame of that final stretch and its note (why
  // it was lost); for a run that never initialised, the last frame's note. -1 and "" otherwise.
  int stop_frame = -1;
  std::string stop_reason;
  // "ok", "lost" (the run ends without tracking) or "not_initialised".
  std::string Status() const;
};

// How a run that ends without tracking stopped: "lost from frame 12: only 7 points left after
// outlier rejection" or "never initialised: …"; "" when `reason` is empty (it ends tracking).
std::string DescribeStop(int init_frame, int stop_frame, const std::string& reason);

using RunProgress = std::function<void(int frame, int total, const std::string& line)>;

// Throws Error for a bad sequence or options (before anything is written); a lost track is a
// recorded outcome, not an error.
RunSummary RunSequence(const std::filesystem::path& sequence, const SystemOptions& options,
                       const std::filesystem::path& out, const RunProgress& progress = {});

}  // namespace nrslam
