// datasets: rectifying a calibrated stereo pair (two lenses with distortion, one turned against
// the other) into the pair the sequence format stores: two pinhole views side by side whose
// rows match, so that a point's disparity is f·B / depth (datasets/stereo_depth.h).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "nrslam/camera/camera.h"
#include "nrslam/io/camera_file.h"

namespace nrslam {

struct StereoRectificationOptions {
  // Size of the rectified images, px; 0 × 0 = the calibration's size, with the shorter axis
  // stretched to square pixels when fx and fy differ by more than 5 % (an interlaced field of
  // 720×288 becomes about 720×576; the reference stretches Hamlyn's by 1.79).
  int width = 0, height = 0;
  // cv::stereoRectify's free scaling, in [0, 1]: 0 keeps only pixels both views see (no black
  // border, which the tracker would take for corners), 1 keeps every source pixel; -1 is
  // OpenCV's default scaling (the reference's), for the radial-tangential model only.
  double alpha = 0.0;
  void Check() const;
};

class StereoRectifier {
 public:
  // Throws Error when the pair cannot be rectified into side-by-side views: a camera model
  // OpenCV cannot rectify (OCam), two different lens families, cameras above each other, or a
  // "right" camera that is to the left of the "left" one.
  StereoRectifier(const StereoCalibration& calibration, const StereoRectificationOptions& options);

  // The rectified camera of both views (pinhole, no distortion).
  const Camera& camera() const { return camera_; }
  // Distance between the rectified cameras along their x axis, mm.
  double baseline_mm() const { return baseline_mm_; }
  // The rotation from the raw left camera's frame to the rectified one's.
  const Eigen::Matrix3d& rectified_from_left() const { return rectified_from_left_; }

  // A raw image at the calibration's size, rectified (bilinear).
  cv::Mat Left(const cv::Mat& raw) const { return Remapped(raw, left_maps_); }
  cv::Mat Right(const cv::Mat& raw) const { return Remapped(raw, right_maps_); }

 private:
  struct Maps {
    cv::Mat first, second;  // cv::remap's fixed-point maps
  };
  cv::Mat Remapped(const cv::Mat& raw, const Maps& maps) const;

  cv::Size raw_size_;
  Camera camera_;
  double baseline_mm_ = 0.0;
  Eigen::Matrix3d rectified_from_left_ = Eigen::Matrix3d::Identity();
  Maps left_maps_, right_maps_;
};

}  // namespace nrslam
