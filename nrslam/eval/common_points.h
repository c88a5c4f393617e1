// eval: two runs of one sequence compared on the points both of them report.
//
// Each run's own RMSE covers the points it kept: a rigid baseline that flags most of a
// deforming scene as outliers is scored on the few points that still fit it, while a
// deformable run keeps the hard ones. Scored on the same points in the same frames, the two
// numbers compare like with like.
#pragma once

#include <opencv2/core.hpp>

#include <cstdint>
#include <functional>
#include <map>

#include "nrslam/eval/depth_evaluation.h"

namespace nrslam {

// One run's reported points in one frame, by point id.
using FramePoints = std::map<int64_t, DepthPoint>;
// Per frame index.
using RunPoints = std::map<int, FramePoints>;

struct CommonPointsComparison {
  // Frames both runs report on which all four evaluations below have an RMSE.
  int frames = 0;
  double mean_points_a = 0, mean_points_b = 0, mean_common_points = 0;  // per frame
  SequenceMetrics a_own, b_own;        // each run on its own points, over those frames
  SequenceMetrics a_common, b_common;  // each run on the points both report
};

// `depth_mm(frame)` gives a frame's ground truth (CV_32F, 0 = none). Point ids must mean the
// same point in both runs: the same map, as when one initial map from depth is tracked in two
// modes (nrslam_run --init depth).
CommonPointsComparison CompareOnCommonPoints(const RunPoints& a, const RunPoints& b,
                                             const std::function<cv::Mat(int frame)>& depth_mm,
                                             const EvaluationOptions& options);

}  // namespace nrslam
