// eval: depth RMSE against ground truth, exactly as the paper computes it.
//
// Per frame, for every point tracked with 3D: its camera-frame depth z_est and the ground
// truth z_gt, sampled bilinearly at the point's sub-pixel position (points whose four
// neighbouring ground-truth pixels are not all valid are excluded and counted). The scale s
// comes from trimmed least squares: s = 1, then 10 times: keep the 95 % smallest squared
// residuals (z_gt − s·z_est)², s ← Σ z_gt·z_est / Σ z_est² over them, RMSE ← √(mean kept
// squared residual) with the new s. The RMSE is in ground-truth units (mm).
//
// Beside it, the flat-map RMSE: the same points and the same rule with every estimate at one
// depth, which is what a map without any structure scores. A depth estimate carries
// information only where its RMSE is below that; in a tube most of the RMSE can be the spread
// of the true depths.
//
// Beside the headline, two stricter alignments (design §5's extra columns): one scale per map,
// which a per-frame scale hides the drift of, and the per-frame median ratio that monocular
// depth benchmarks use.
#pragma once

#include <opencv2/core.hpp>
#include <nlohmann/json.hpp>

#include <optional>
#include <vector>

namespace nrslam {

struct EvaluationOptions {
  double keep_fraction = 0.95;  // fraction of the smallest residuals kept by the trimming
  int iterations = 10;          // trimmed least-squares rounds
  int min_points = 5;           // fewer evaluable points: the frame has no RMSE
  void Check() const;
};
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(EvaluationOptions, keep_fraction, iterations, min_points)

struct DepthPoint {
  cv::Point2d pixel;  // sub-pixel image position
  double depth;       // estimated camera-frame depth z_est, map units
};

struct FrameEvaluation {
  bool evaluated = false;  // false when fewer than min_points had ground truth
  int points_used = 0;     // points with valid ground truth
  int points_kept = 0;     // after trimming
  int points_without_groundtruth = 0;
  double scale = 0.0;      // s: map units → mm
  double rmse_mm = 0.0;
  double squared_error_sum = 0.0;  // over the kept points, for pooled aggregates
  double flat_rmse_mm = 0.0;       // the same points all at one depth (EvaluateFrame only)
  // The evaluable pairs themselves (EvaluateFrame only), for the alignments that look past one
  // frame, and the map whose scale the estimates share (a monocular run that re-initialises
  // starts a map of another scale); the caller sets `map`.
  std::vector<double> estimated, groundtruth;
  int map = 0;
};

// Bilinear sample of a depth map (CV_32F, 0 = none); nullopt unless all four taps are valid.
std::optional<double> SampleDepth(const cv::Mat& depth_mm, const cv::Point2d& pixel);

// The trimmed least-squares scale and RMSE of (z_est, z_gt) pairs.
FrameEvaluation EvaluateDepthPairs(const std::vector<double>& estimated, const std::vector<double>& groundtruth,
                                   const EvaluationOptions& options);

// The RMSE of the pairs at a scale given, not fitted: over the smallest `keep_fraction` of
// the squared residuals at that scale, as EvaluateDepthPairs trims.
FrameEvaluation EvaluateDepthPairsAtScale(const std::vector<double>& estimated, const std::vector<double>& groundtruth,
                                          double scale, const EvaluationOptions& options);

// Samples the ground truth at every point, then EvaluateDepthPairs, of the estimates and of
// the flat map.
FrameEvaluation EvaluateFrame(const std::vector<DepthPoint>& points, const cv::Mat& depth_mm,
                              const EvaluationOptions& options);

// Sequence figures with the key names of summary.json.
struct SequenceMetrics {
  double rmse_mm = 0.0;         // mean of frame RMSEs (the paper's headline)
  double rmse_median_mm = 0.0;
  double rmse_pooled_mm = 0.0;  // √(Σ kept squared errors / Σ kept points) over all frames
  double rmse_flat_mm = 0.0;    // mean of frame flat-map RMSEs, over the same frames as rmse_mm
  int frames_evaluated = 0;
};
SequenceMetrics AggregateFrames(const std::vector<FrameEvaluation>& frames);

// median(z_gt / z_est) over the pairs whose estimate is in front of the camera; 0 without one.
double MedianRatioScale(const std::vector<double>& estimated, const std::vector<double>& groundtruth);

// Pearson's correlation of the estimates with the true depths: near 1 for depth at any scale,
// strongly negative for inverse depth or disparity taken for depth; 0 when either is constant.
double DepthCorrelation(const std::vector<double>& estimated, const std::vector<double>& groundtruth);

// The evaluated frames (with their pairs) scored at other scales than their own, each frame's
// RMSE trimmed as EvaluateDepthPairs trims, and averaged over the frames like rmse_mm:
//   map scale:    one scale per map, fitted as a frame's is (trimmed least squares) to all of
//                 that map's pairs pooled, so a map whose scale drifts pays for the drift;
//   median scale: per frame s = median(z_gt / z_est) over the estimates in front of the camera.
struct OtherAlignments {
  double rmse_map_scale_mm = 0.0;
  double rmse_median_scale_mm = 0.0;
  int frames_evaluated = 0;
};
OtherAlignments EvaluateOtherAlignments(const std::vector<FrameEvaluation>& frames, const EvaluationOptions& options);

}  // namespace nrslam
