#include "nrslam/eval/common_points.h"

#include <set>
#include <vector>

namespace nrslam {
namespace {

std::vector<DepthPoint> Values(const FramePoints& points) {
  std::vector<DepthPoint> values;
  for (const auto& entry : points) values.push_back(entry.second);
  return values;
}

struct FirstReport {
  int frame;
  cv::Point2d pixel;
};

std::map<int64_t, FirstReport> FirstReports(const RunPoints& run) {
  std::map<int64_t, FirstReport> first;
  for (const auto& [frame, points] : run) {  // frames in order: emplace keeps the earliest
    for (const auto& [id, point] : points) first.emplace(id, FirstReport{frame, point.pixel});
  }
  return first;
}

// The ids both runs report for the same track.
std::set<int64_t> SharedTracks(const RunPoints& a, const RunPoints& b, int* mismatched) {
  const std::map<int64_t, FirstReport> first_b = FirstReports(b);
  std::set<int64_t> shared;
  *mismatched = 0;
  for (const auto& [id, report] : FirstReports(a)) {
    const auto other = first_b.find(id);
    if (other == first_b.end()) continue;
    if (other->second.frame == report.frame && cv::norm(other->second.pixel - report.pixel) <= kSameTrackPixels) {
      shared.insert(id);
    } else {
      ++*mismatched;
    }
  }
  return shared;
}

}  // namespace

CommonPointsComparison CompareOnCommonPoints(const RunPoints& a, const RunPoints& b,
                                             const std::function<cv::Mat(int frame)>& depth_mm,
                                             const EvaluationOptions& options) {
  CommonPointsComparison comparison;
  const std::set<int64_t> shared = SharedTracks(a, b, &comparison.mismatched_ids);
  std::vector<FrameEvaluation> a_own, b_own, a_common, b_common;
  double points_a = 0, points_b = 0, common = 0;
  for (const auto& [frame, points] : a) {
    const auto other = b.find(frame);
    if (other == b.end()) continue;
    std::vector<DepthPoint> common_a, common_b;
    for (const auto& [id, point] : points) {
      const auto match = other->second.find(id);
      if (match == other->second.end() || shared.count(id) == 0) continue;
      common_a.push_back(point);
      common_b.push_back(match->second);
    }
    const cv::Mat depth = depth_mm(frame);
    if (depth.empty()) continue;
    const FrameEvaluation evaluations[] = {EvaluateFrame(Values(points), depth, options),
                                           EvaluateFrame(Values(other->second), depth, options),
                                           EvaluateFrame(common_a, depth, options),
                                           EvaluateFrame(common_b, depth, options)};
    bool all = true;
    for (const FrameEvaluation& evaluation : evaluations) all = all && evaluation.evaluated;
    if (!all) continue;
    a_own.push_back(evaluations[0]);
    b_own.push_back(evaluations[1]);
    a_common.push_back(evaluations[2]);
    b_common.push_back(evaluations[3]);
    points_a += static_cast<double>(points.size());
    points_b += static_cast<double>(other->second.size());
    common += static_cast<double>(common_a.size());
  }
  comparison.frames = static_cast<int>(a_own.size());
  if (comparison.frames == 0) return comparison;
  comparison.mean_points_a = points_a / comparison.frames;
  comparison.mean_points_b = points_b / comparison.frames;
  comparison.mean_common_points = common / comparison.frames;
  comparison.a_own = AggregateFrames(a_own);
  comparison.b_own = AggregateFrames(b_own);
  comparison.a_common = AggregateFrames(a_common);
  comparison.b_common = AggregateFrames(b_common);
  return comparison;
}

}  // namespace nrslam
