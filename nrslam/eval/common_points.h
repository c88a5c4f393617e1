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
  // Ids both runs report that name different points, so are never common: the two runs first
  // reported them in different frames or at pixels more than kSameTrackPixels apart (two
  // monocular runs number their new points in the order each made them).
  int mismatched_ids = 0;
  double mean_points_a = 0, mean_points_b = 0, mean_common_points = 0;  // per frame
  SequenceMetrics a_own, b_own;        // each run on its own points, over those frames
  SequenceMetrics a_common, b_common;  // each run on the points both report
};

// How far apart (pixels) two runs may first report an id for it to be the same point.
constexpr double kSameTrackPixels = 0.5;

// `depth_mm(frame)` gives a frame's ground truth (CV_32F, 0 = none; an empty matrix leaves the
// frame out). A point is common when both runs report its id and first reported that id in the
// same frame at the same pixel: the same track, as when one initial map (from depth, or the same
// two-view map) is tracked in two modes. Ids that fail the check are counted, not compared.
CommonPointsComparison CompareOnCommonPoints(const RunPoints& a, const RunPoints& b,
                                             const std::function<cv::Mat(int frame)>& depth_mm,
                                             const EvaluationOptions& options);

}  // namespace nrslam
