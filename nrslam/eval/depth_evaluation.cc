#include "nrslam/eval/depth_evaluation.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <utility>

#include "nrslam/util/error.h"
#include "nrslam/util/json_options.h"
#include "nrslam/util/median.h"

namespace nrslam {

void EvaluationOptions::Check() const {
  CheckOption(keep_fraction > 0 && keep_fraction <= 1, "evaluation", "keep_fraction must be in (0, 1]");
  CheckOption(iterations >= 1, "evaluation", "iterations must be >= 1");
  CheckOption(min_points >= 1, "evaluation", "min_points must be >= 1");
}

std::optional<double> SampleDepth(const cv::Mat& depth_mm, const cv::Point2d& pixel) {
  if (depth_mm.type() != CV_32F) throw Error("SampleDepth: expected a CV_32F depth map");
  if (!std::isfinite(pixel.x) || !std::isfinite(pixel.y)) return std::nullopt;
  const int x0 = static_cast<int>(std::floor(pixel.x)), y0 = static_cast<int>(std::floor(pixel.y));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= depth_mm.cols || y0 + 1 >= depth_mm.rows) {
    // On the last row or column a sample exactly on the pixel centre is still fine.
    if (x0 >= 0 && y0 >= 0 && x0 < depth_mm.cols && y0 < depth_mm.rows && pixel.x == x0 && pixel.y == y0) {
      const float value = depth_mm.at<float>(y0, x0);
      if (value > 0 && std::isfinite(value)) return value;
    }
    return std::nullopt;
  }
  const double ax = pixel.x - x0, ay = pixel.y - y0;
  const float d00 = depth_mm.at<float>(y0, x0), d01 = depth_mm.at<float>(y0, x0 + 1);
  const float d10 = depth_mm.at<float>(y0 + 1, x0), d11 = depth_mm.at<float>(y0 + 1, x0 + 1);
  for (float d : {d00, d01, d10, d11}) {
    if (!(d > 0) || !std::isfinite(d)) return std::nullopt;  // an edge or a hole: no reliable truth
  }
  return (1 - ay) * ((1 - ax) * d00 + ax * d01) + ay * ((1 - ax) * d10 + ax * d11);
}

namespace {

void CheckPairs(const std::vector<double>& estimated, const std::vector<double>& groundtruth) {
  if (estimated.size() != groundtruth.size()) throw Error("EvaluateDepthPairs: size mismatch");
  for (size_t i = 0; i < estimated.size(); ++i) {
    if (!std::isfinite(estimated[i]) || !std::isfinite(groundtruth[i])) {
      throw Error("EvaluateDepthPairs: non-finite depth at point " + std::to_string(i));
    }
  }
}

size_t KeptCount(size_t count, const EvaluationOptions& options) {
  return std::max<size_t>(1, static_cast<size_t>(std::floor(options.keep_fraction * count)));
}

// Puts the indices of the `keep` smallest squared residuals at `scale` first in `order`
// (`scratch`: space for the squared residuals, reused across the trimming rounds).
void SelectSmallestResiduals(const std::vector<double>& estimated, const std::vector<double>& groundtruth, double scale,
                             size_t keep, std::vector<size_t>* order, std::vector<double>* scratch) {
  std::vector<double>& squared = *scratch;
  squared.resize(estimated.size());
  for (size_t i = 0; i < estimated.size(); ++i) {
    const double residual = groundtruth[i] - scale * estimated[i];
    squared[i] = residual * residual;
  }
  order->resize(estimated.size());
  std::iota(order->begin(), order->end(), 0);
  // Ties broken by index, so the kept set never depends on the sort's whims.
  std::nth_element(order->begin(), order->begin() + (keep - 1), order->end(), [&](size_t a, size_t b) {
    return squared[a] != squared[b] ? squared[a] < squared[b] : a < b;
  });
}

double KeptSquaredError(const std::vector<double>& estimated, const std::vector<double>& groundtruth, double scale,
                        const std::vector<size_t>& order, size_t keep) {
  double sum = 0.0;
  for (size_t k = 0; k < keep; ++k) {
    const double residual = groundtruth[order[k]] - scale * estimated[order[k]];
    sum += residual * residual;
  }
  return sum;
}

void SetScore(double scale, double kept_sum, size_t keep, FrameEvaluation* result) {
  result->evaluated = true;
  result->points_kept = static_cast<int>(keep);
  result->scale = scale;
  result->squared_error_sum = kept_sum;
  result->rmse_mm = std::sqrt(kept_sum / keep);
}

}  // namespace

FrameEvaluation EvaluateDepthPairs(const std::vector<double>& estimated, const std::vector<double>& groundtruth,
                                   const EvaluationOptions& options) {
  CheckPairs(estimated, groundtruth);
  FrameEvaluation result;
  result.points_used = static_cast<int>(estimated.size());
  if (result.points_used < options.min_points) return result;
  const size_t keep = KeptCount(estimated.size(), options);
  std::vector<size_t> order;
  std::vector<double> scratch;
  double scale = 1.0;
  double kept_sum = 0.0;
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    SelectSmallestResiduals(estimated, groundtruth, scale, keep, &order, &scratch);
    double cross = 0.0, energy = 0.0;
    for (size_t k = 0; k < keep; ++k) {
      cross += groundtruth[order[k]] * estimated[order[k]];
      energy += estimated[order[k]] * estimated[order[k]];
    }
    if (!(energy > 0)) return result;  // all kept estimates at zero depth: no scale
    scale = cross / energy;
    kept_sum = KeptSquaredError(estimated, groundtruth, scale, order, keep);
  }
  SetScore(scale, kept_sum, keep, &result);
  return result;
}

FrameEvaluation EvaluateDepthPairsAtScale(const std::vector<double>& estimated, const std::vector<double>& groundtruth,
                                          double scale, const EvaluationOptions& options) {
  CheckPairs(estimated, groundtruth);
  FrameEvaluation result;
  result.points_used = static_cast<int>(estimated.size());
  if (result.points_used < options.min_points || !std::isfinite(scale)) return result;
  const size_t keep = KeptCount(estimated.size(), options);
  std::vector<size_t> order;
  std::vector<double> scratch;
  SelectSmallestResiduals(estimated, groundtruth, scale, keep, &order, &scratch);
  SetScore(scale, KeptSquaredError(estimated, groundtruth, scale, order, keep), keep, &result);
  return result;
}

FrameEvaluation EvaluateFrame(const std::vector<DepthPoint>& points, const cv::Mat& depth_mm,
                              const EvaluationOptions& options) {
  std::vector<double> estimated, groundtruth;
  int without = 0;
  for (const DepthPoint& point : points) {
    const auto truth = SampleDepth(depth_mm, point.pixel);
    if (!truth || !std::isfinite(point.depth)) {
      ++without;
      continue;
    }
    estimated.push_back(point.depth);
    groundtruth.push_back(*truth);
  }
  FrameEvaluation result = EvaluateDepthPairs(estimated, groundtruth, options);
  result.points_without_groundtruth = without;
  if (result.evaluated) {
    result.flat_rmse_mm = EvaluateDepthPairs(std::vector<double>(groundtruth.size(), 1.0), groundtruth, options).rmse_mm;
    result.estimated = std::move(estimated);
    result.groundtruth = std::move(groundtruth);
  }
  return result;
}

SequenceMetrics AggregateFrames(const std::vector<FrameEvaluation>& frames) {
  SequenceMetrics metrics;
  std::vector<double> rmses, flat_rmses;
  double squared = 0.0;
  long kept = 0;
  for (const FrameEvaluation& frame : frames) {
    if (!frame.evaluated) continue;
    rmses.push_back(frame.rmse_mm);
    flat_rmses.push_back(frame.flat_rmse_mm);
    squared += frame.squared_error_sum;
    kept += frame.points_kept;
  }
  metrics.frames_evaluated = static_cast<int>(rmses.size());
  if (rmses.empty()) return metrics;
  metrics.rmse_mm = Mean(rmses);
  metrics.rmse_flat_mm = Mean(flat_rmses);
  std::sort(rmses.begin(), rmses.end());
  const size_t n = rmses.size();
  metrics.rmse_median_mm = n % 2 ? rmses[n / 2] : 0.5 * (rmses[n / 2 - 1] + rmses[n / 2]);
  metrics.rmse_pooled_mm = std::sqrt(squared / kept);
  return metrics;
}

double MedianRatioScale(const std::vector<double>& estimated, const std::vector<double>& groundtruth) {
  std::vector<double> ratios;
  for (size_t i = 0; i < estimated.size(); ++i) {
    if (estimated[i] > 0) ratios.push_back(groundtruth[i] / estimated[i]);
  }
  return ratios.empty() ? 0.0 : Median(ratios);
}

double DepthCorrelation(const std::vector<double>& estimated, const std::vector<double>& groundtruth) {
  if (estimated.size() != groundtruth.size()) throw Error("DepthCorrelation: as many estimates as true depths needed");
  if (estimated.empty()) return 0.0;
  const double mean_estimated = Mean(estimated), mean_true = Mean(groundtruth);
  double covariance = 0, variance_estimated = 0, variance_true = 0;
  for (size_t i = 0; i < estimated.size(); ++i) {
    const double a = estimated[i] - mean_estimated, b = groundtruth[i] - mean_true;
    covariance += a * b;
    variance_estimated += a * a;
    variance_true += b * b;
  }
  if (variance_estimated <= 0 || variance_true <= 0) return 0.0;
  return covariance / std::sqrt(variance_estimated * variance_true);
}

OtherAlignments EvaluateOtherAlignments(const std::vector<FrameEvaluation>& frames, const EvaluationOptions& options) {
  std::map<int, std::pair<std::vector<double>, std::vector<double>>> pooled;  // per map: estimates, truths
  for (const FrameEvaluation& frame : frames) {
    if (!frame.evaluated) continue;
    auto& [estimated, groundtruth] = pooled[frame.map];
    estimated.insert(estimated.end(), frame.estimated.begin(), frame.estimated.end());
    groundtruth.insert(groundtruth.end(), frame.groundtruth.begin(), frame.groundtruth.end());
  }
  std::map<int, double> map_scale;
  for (const auto& [map, pairs] : pooled) map_scale[map] = EvaluateDepthPairs(pairs.first, pairs.second, options).scale;

  std::vector<double> at_map_scale, at_median_scale;
  for (const FrameEvaluation& frame : frames) {
    if (!frame.evaluated) continue;
    if (frame.estimated.empty()) throw Error("EvaluateOtherAlignments: a frame evaluated without its pairs");
    // With no estimate in front of the camera there is no ratio; scale 0 scores every estimate
    // as depth 0, so the frame gets the RMSE of its true depths.
    const double median_scale = MedianRatioScale(frame.estimated, frame.groundtruth);
    at_map_scale.push_back(
        EvaluateDepthPairsAtScale(frame.estimated, frame.groundtruth, map_scale.at(frame.map), options).rmse_mm);
    at_median_scale.push_back(EvaluateDepthPairsAtScale(frame.estimated, frame.groundtruth, median_scale, options).rmse_mm);
  }
  OtherAlignments result;
  result.frames_evaluated = static_cast<int>(at_map_scale.size());
  if (at_map_scale.empty()) return result;
  result.rmse_map_scale_mm = Mean(at_map_scale);
  result.rmse_median_scale_mm = Mean(at_median_scale);
  return result;
}

}  // namespace nrslam
