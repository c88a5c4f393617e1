#include "nrslam/datasets/stereo_depth.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>

#include "nrslam/util/error.h"

namespace nrslam {

void StereoDepthOptions::Check() const {
  if (!(min_depth_mm > 0) || block_size < 1 || block_size % 2 == 0 || uniqueness_ratio < 0 ||
      !(max_lr_difference_px >= 0) || speckle_window < 0 || speckle_range < 0) {
    throw Error("stereo options: need min_depth_mm > 0, an odd block_size, and non-negative thresholds");
  }
}

namespace {

cv::Mat Grey(const cv::Mat& image) {
  if (image.channels() == 1) return image;
  cv::Mat grey;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  return grey;
}

// Disparities in px (CV_32F, < 0 = none) of `reference` against `other`, both already
// oriented so that matches lie to the left in `other`.
cv::Mat Disparity(const cv::Mat& reference, const cv::Mat& other, int range, const StereoDepthOptions& options) {
  const int area = options.block_size * options.block_size;
  cv::Ptr<cv::StereoSGBM> matcher =
      cv::StereoSGBM::create(0, range, options.block_size, 8 * area, 32 * area, 1, 0, options.uniqueness_ratio,
                             options.speckle_window, options.speckle_range, cv::StereoSGBM::MODE_SGBM);
  // SGBM gives no disparity in the first `range` columns; pad them on so the whole image has one.
  cv::Mat padded_reference, padded_other, fixed;
  cv::copyMakeBorder(reference, padded_reference, 0, 0, range, 0, cv::BORDER_REPLICATE);
  cv::copyMakeBorder(other, padded_other, 0, 0, range, 0, cv::BORDER_REPLICATE);
  matcher->compute(padded_reference, padded_other, fixed);
  cv::Mat disparity;
  fixed.colRange(range, fixed.cols).convertTo(disparity, CV_32F, 1.0 / 16.0);  // SGBM's fixed point is ×16
  return disparity;
}

}  // namespace

cv::Mat StereoDepthMm(const cv::Mat& left, const cv::Mat& right, double focal_px, double baseline_mm,
                      const StereoDepthOptions& options) {
  options.Check();
  if (left.empty() || left.size() != right.size()) throw Error("stereo: the two images must be non-empty and the same size");
  if (!(focal_px > 0) || !(baseline_mm > 0)) throw Error("stereo: focal length and baseline must be positive");
  const double largest = focal_px * baseline_mm / options.min_depth_mm;
  const int range = std::max(16, static_cast<int>(std::ceil(largest / 16.0)) * 16);
  const cv::Mat grey_left = Grey(left), grey_right = Grey(right);
  const cv::Mat left_disparity = Disparity(grey_left, grey_right, range, options);
  // The right image's disparities: mirror both images so the same matcher applies.
  cv::Mat mirrored_left, mirrored_right;
  cv::flip(grey_left, mirrored_left, 1);
  cv::flip(grey_right, mirrored_right, 1);
  cv::Mat right_disparity = Disparity(mirrored_right, mirrored_left, range, options);
  cv::flip(right_disparity, right_disparity, 1);

  cv::Mat depth(left.size(), CV_32F, cv::Scalar(0));
  for (int y = 0; y < depth.rows; ++y) {
    const float* from_left = left_disparity.ptr<float>(y);
    const float* from_right = right_disparity.ptr<float>(y);
    float* out = depth.ptr<float>(y);
    for (int x = 0; x < depth.cols; ++x) {
      const float d = from_left[x];
      if (!(d > 0)) continue;
      const int match = static_cast<int>(std::lround(x - d));
      if (match < 0 || !(from_right[match] > 0)) continue;
      if (std::abs(from_right[match] - d) > options.max_lr_difference_px) continue;  // occluded or mismatched
      out[x] = static_cast<float>(focal_px * baseline_mm / d);
    }
  }
  return depth;
}

}  // namespace nrslam
