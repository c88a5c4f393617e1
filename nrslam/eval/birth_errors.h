// eval: how far from the rest of the map new points are born.
//
// A point's birth is the first frame it is reported in, unless that frame started its map
// (an initial map is scored by the headline RMSE from its first frame). Its birth error is
// log(s·z_est / z_gt), z_gt sampled as the evaluator samples it and s the frame's median of
// z_gt / z_est over its points (the scale that centres the frame's log errors; the RMSE's
// least-squares scale leans towards far points): 0 for a point born where the frame's other
// points put the map, negative for one born too near. Tracking keeps a point's ratio to the
// truth, so a mean below zero compounds as points turn over and the map shrinks (top-level
// docs/mapping.md, "Long runs").
#pragma once

#include <opencv2/core.hpp>

#include <cstdint>
#include <optional>
#include <unordered_set>
#include <vector>

#include "nrslam/eval/depth_evaluation.h"

namespace nrslam {

struct BirthErrorSummary {
  int births_evaluated = 0;            // births scored
  std::optional<double> mean, median;  // of their log errors; none without one
};

class BirthErrors {
 public:
  // One frame's points, frames in order; `ids` parallel to `points`; `evaluation` the frame's
  // EvaluateFrame of the same points (default: the frame has no ground truth), whose pairs give
  // the scale. A frame that was not evaluated (no ground truth, fewer than min_points points
  // with it) still sees its new points born, unscored. `map_start`: the frame started a map.
  // Throws Error when `ids` and `points` differ in number.
  void AddFrame(const std::vector<int64_t>& ids, const std::vector<DepthPoint>& points, const cv::Mat& depth_mm,
                const FrameEvaluation& evaluation, bool map_start);
  const std::vector<double>& log_errors() const { return log_errors_; }  // one per scored birth
  BirthErrorSummary Summarise() const;

 private:
  std::unordered_set<int64_t> seen_;
  std::vector<double> log_errors_;
};

}  // namespace nrslam
