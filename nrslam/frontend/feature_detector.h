// frontend: Shi–Tomasi corners inside a validity mask.
#pragma once

#include <opencv2/core.hpp>

#include <vector>

#include "nrslam/frontend/frontend_options.h"

namespace nrslam {

// Corners of `grey` whose minimum-eigenvalue score passes the threshold, that are local maxima
// within ±nms_radius, lie where `valid` is non-zero, and are farther than exclusion_radius
// from every point of `existing`. At most max_features, strongest first.
std::vector<cv::Point2f> DetectCorners(const cv::Mat& grey, const cv::Mat& valid,
                                       const std::vector<cv::Point2f>& existing, const FeatureOptions& options);

}  // namespace nrslam
