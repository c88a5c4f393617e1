// datasets: dense depth ground truth from a rectified stereo pair, for data without it
// (e.g. Hamlyn): OpenCV's semi-global matching in both directions, a left–right consistency
// check that drops occlusions and mismatches, and depth = f·B / disparity.
#pragma once

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

namespace nrslam {

struct StereoDepthOptions {
  double min_depth_mm = 10.0;   // nearest depth searched; sets the disparity range (f·B / this)
  int block_size = 5;           // SGBM matching block, px (odd)
  int uniqueness_ratio = 10;    // SGBM: best match must beat the second by this %
  double max_lr_difference_px = 1.0;  // left and right disparities must agree this well
  int speckle_window = 100;     // SGBM speckle filter: region size, px ...
  int speckle_range = 2;        // ... and disparity variation within it, px
  void Check() const;
};
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(StereoDepthOptions, min_depth_mm, block_size, uniqueness_ratio,
                                                max_lr_difference_px, speckle_window, speckle_range)

// Depth in mm of the left image (CV_32F, 0 = none) from a rectified pair (BGR or grey, same
// size), the focal length in px and the baseline in mm.
cv::Mat StereoDepthMm(const cv::Mat& left, const cv::Mat& right, double focal_px, double baseline_mm,
                      const StereoDepthOptions& options);

}  // namespace nrslam
