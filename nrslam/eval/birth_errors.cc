#include "nrslam/eval/birth_errors.h"

#include <cmath>

#include "nrslam/util/error.h"
#include "nrslam/util/median.h"

namespace nrslam {

void BirthErrors::AddFrame(const std::vector<int64_t>& ids, const std::vector<DepthPoint>& points,
                           const cv::Mat& depth_mm, const FrameEvaluation& evaluation, bool map_start) {
  if (ids.size() != points.size()) throw Error("BirthErrors: ids and points differ in number");
  std::vector<size_t> born;
  for (size_t i = 0; i < ids.size(); ++i) {
    if (seen_.insert(ids[i]).second && !map_start) born.push_back(i);
  }
  if (born.empty() || !evaluation.evaluated) return;
  const double scale = MedianRatioScale(evaluation.estimated, evaluation.groundtruth);
  if (!(scale > 0)) return;
  for (size_t i : born) {
    const std::optional<double> truth = SampleDepth(depth_mm, points[i].pixel);
    const double estimate = scale * points[i].depth;
    if (truth && estimate > 0 && std::isfinite(estimate)) log_errors_.push_back(std::log(estimate / *truth));
  }
}

BirthErrorSummary BirthErrors::Summarise() const {
  BirthErrorSummary summary;
  summary.births_evaluated = static_cast<int>(log_errors_.size());
  if (log_errors_.empty()) return summary;
  summary.mean = Mean(log_errors_);
  summary.median = Median(log_errors_);
  return summary;
}

}  // namespace nrslam
