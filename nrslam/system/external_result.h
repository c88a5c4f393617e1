// system: another system's output on a sequence, scored exactly as a run of ours is.
//
// Baselines (ORB-SLAM3, DefSLAM, a monocular depth network, ...) write their estimates in their
// own ways. Given as per-frame points or per-frame depth images, they get the same per-frame
// trimmed least-squares scale and depth RMSE as nrslam_run (design §5), the same trajectory
// error when a TUM trajectory comes with them, and the same run folder: config.json (the
// sequence and what was scored), points.csv, metrics.csv, depth/, trajectory.tum and
// summary.json, so every tool that reads run folders reads these too.
//
// Estimates, either:
//   - a CSV file with a header naming at least `frame`, `u`, `v` and `z`, and optionally
//     `point_id`; other columns are ignored. A `z_est` column is taken for the depth before
//     `z`, so a run's own points.csv scores to its own summary. Pixel coordinates are the
//     image's (0,0 the centre of the top-left pixel); those outside it are left out and
//     counted, but more than a tenth outside, or all within two pixels (normalised
//     coordinates), is refused. z is any camera depth along the optical axis, in any unit:
//     each frame's scale is fitted;
//   - a folder of single-channel depth images readable by OpenCV (16-bit PNG, float TIFF or
//     EXR), one per frame, the frame number the last number in the file name. They are sampled
//     every `depth_stride_px` pixels; 0, negative and non-finite values are "no estimate".
//     Files that are not images OpenCV reads (notes, a calibration) are skipped.
// A frame with neither points nor a pose counts as not tracked. config.json says whether the
// ids name points (`ids_name_points`: only a CSV's own point_id column does), which
// `nrslam_eval compare` requires.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

#include "nrslam/eval/depth_evaluation.h"
#include "nrslam/system/run_files.h"

namespace nrslam {

struct ExternalResult {
  std::filesystem::path estimates;   // CSV file or depth-image folder
  std::filesystem::path trajectory;  // optional: world_from_camera, TUM, timestamps = frame / fps
  int depth_stride_px = 8;           // sampling step of depth images, px
  std::string name;                  // what produced it (e.g. "DefSLAM"), recorded in config.json
  void Check() const;
};
// What config.json records under "external": the fields, with absolute paths, and the
// files' sizes and modification times (an output exported again is scored again).
nlohmann::json ToJson(const ExternalResult& result);

// Throws Error for a bad sequence or bad estimates (a missing column, a row that is not
// numbers, a frame outside the sequence, pixels that cannot be the image's, an image of the
// wrong size), naming the file and row.
RunSummary ScoreExternalResult(const std::filesystem::path& sequence, const ExternalResult& result,
                               const EvaluationOptions& evaluation, const std::filesystem::path& out);

}  // namespace nrslam
