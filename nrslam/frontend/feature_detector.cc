#include "nrslam/frontend/feature_detector.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>

#include "nrslam/util/error.h"

namespace nrslam {

std::vector<cv::Point2f> DetectCorners(const cv::Mat& grey, const cv::Mat& valid,
                                       const std::vector<cv::Point2f>& existing, const FeatureOptions& options) {
  if (grey.type() != CV_8UC1) throw Error("DetectCorners: expected an 8-bit grey image");
  cv::Mat score;
  cv::cornerMinEigenVal(grey, score, 3, 3);
  cv::Mat local_max;
  const int side = 2 * options.nms_radius_px + 1;
  cv::dilate(score, local_max, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(side, side)));

  cv::Mat allowed = valid.empty() ? cv::Mat(grey.size(), CV_8UC1, cv::Scalar(255)) : valid.clone();
  for (const cv::Point2f& point : existing) {
    cv::circle(allowed, cv::Point(cvRound(point.x), cvRound(point.y)), options.exclusion_radius_px, cv::Scalar(0), -1);
  }

  struct Candidate {
    float score;
    int x, y;
  };
  std::vector<Candidate> candidates;
  for (int y = 0; y < grey.rows; ++y) {
    const float* s = score.ptr<float>(y);
    const float* m = local_max.ptr<float>(y);
    const uint8_t* a = allowed.ptr<uint8_t>(y);
    for (int x = 0; x < grey.cols; ++x) {
      if (a[x] && s[x] >= options.min_eigenvalue && s[x] >= m[x]) candidates.push_back({s[x], x, y});
    }
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return a.score != b.score ? a.score > b.score : (a.y != b.y ? a.y < b.y : a.x < b.x);
  });
  // Plateaus of equal score pass the local-maximum test together; keep one per neighbourhood.
  cv::Mat taken = cv::Mat::zeros(grey.size(), CV_8UC1);
  std::vector<cv::Point2f> corners;
  for (const Candidate& candidate : candidates) {
    if (static_cast<int>(corners.size()) >= options.max_features) break;
    if (taken.at<uint8_t>(candidate.y, candidate.x)) continue;
    corners.emplace_back(static_cast<float>(candidate.x), static_cast<float>(candidate.y));
    cv::circle(taken, cv::Point(candidate.x, candidate.y), options.nms_radius_px, cv::Scalar(255), -1);
  }
  return corners;
}

}  // namespace nrslam
