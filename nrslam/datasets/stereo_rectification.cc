#include "nrslam/datasets/stereo_rectification.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "nrslam/util/error.h"

namespace nrslam {
namespace {

cv::Matx33d CameraMatrix(const Camera& camera) {
  return {camera.fx(), 0.0, camera.cx(), 0.0, camera.fy(), camera.cy(), 0.0, 0.0, 1.0};
}

// OpenCV's distortion vector of a camera: none for a pinhole, k1 k2 p1 p2 k3 k4 k5 k6 for the
// radial-tangential model, k1 … k4 for the fisheye one.
cv::Mat DistortionCoefficients(const Camera& camera) {
  const std::vector<double>& p = camera.params();
  switch (camera.model()) {
    case CameraModelId::kPinhole:
      return cv::Mat::zeros(1, 5, CV_64F);
    case CameraModelId::kOpenCv:
      return cv::Mat(std::vector<double>(p.begin() + 4, p.begin() + 12), true).reshape(1, 1);
    case CameraModelId::kKannalaBrandt:
      return cv::Mat(std::vector<double>(p.begin() + 4, p.begin() + 8), true).reshape(1, 1);
    case CameraModelId::kOcam:
      break;
  }
  throw Error("stereo rectification: OpenCV cannot rectify the " + camera.model_name() +
              " model; calibrate the pair with OpenCV's radial-tangential or fisheye model");
}

bool IsFisheye(const Camera& camera) { return camera.model() == CameraModelId::kKannalaBrandt; }

// The calibration's size with the shorter pixel axis stretched to square pixels, when the
// pixels are clearly not square (interlaced video).
cv::Size SquarePixelSize(const Camera& camera) {
  const double aspect = camera.fx() / camera.fy();
  if (std::abs(aspect - 1.0) <= 0.05) return {camera.width(), camera.height()};
  if (aspect > 1.0) return {camera.width(), static_cast<int>(std::lround(camera.height() * aspect))};
  return {static_cast<int>(std::lround(camera.width() / aspect)), camera.height()};
}

}  // namespace

void StereoRectificationOptions::Check() const {
  if (width < 0 || height < 0 || (width == 0) != (height == 0)) {
    throw Error("stereo rectification: the rectified size needs both a width and a height > 0 (or neither)");
  }
  if (!((alpha >= 0.0 && alpha <= 1.0) || alpha == -1.0)) {
    throw Error("stereo rectification: alpha must be in [0, 1] or -1 (OpenCV's default), got " + std::to_string(alpha));
  }
}

StereoRectifier::StereoRectifier(const StereoCalibration& calibration, const StereoRectificationOptions& options)
    : raw_size_(calibration.left.width(), calibration.left.height()) {
  options.Check();
  const Camera& left = calibration.left;
  const Camera& right = calibration.right;
  if (right.width() != left.width() || right.height() != left.height()) {
    throw Error("stereo rectification: the two cameras were calibrated at different image sizes");
  }
  const cv::Mat left_distortion = DistortionCoefficients(left), right_distortion = DistortionCoefficients(right);
  const bool fisheye = IsFisheye(left);
  if (fisheye != IsFisheye(right)) {
    throw Error("stereo rectification: one camera is a fisheye (equidistant) lens and the other is not");
  }
  if (fisheye && options.alpha < 0.0) {
    throw Error("stereo rectification: alpha -1 (OpenCV's default) exists for the radial-tangential model only");
  }
  const cv::Size size = options.width > 0 ? cv::Size(options.width, options.height) : SquarePixelSize(left);
  const Eigen::Matrix3d rotation = calibration.right_from_left.rotation.toRotationMatrix();
  const Eigen::Vector3d& translation = calibration.right_from_left.translation;
  const cv::Matx33d r(rotation(0, 0), rotation(0, 1), rotation(0, 2), rotation(1, 0), rotation(1, 1), rotation(1, 2),
                      rotation(2, 0), rotation(2, 1), rotation(2, 2));
  const cv::Vec3d t(translation.x(), translation.y(), translation.z());
  if (!(translation.norm() > 0)) throw Error("stereo rectification: T is zero (the two cameras are in one place)");
  cv::Mat r1, r2, p1, p2, q;
  const cv::Matx33d k1 = CameraMatrix(left), k2 = CameraMatrix(right);
  if (fisheye) {
    cv::fisheye::stereoRectify(k1, left_distortion, k2, right_distortion, raw_size_, r, t, r1, r2, p1, p2, q,
                               cv::CALIB_ZERO_DISPARITY, size, options.alpha);
  } else {
    cv::stereoRectify(k1, left_distortion, k2, right_distortion, raw_size_, r, t, r1, r2, p1, p2, q,
                      cv::CALIB_ZERO_DISPARITY, options.alpha, size);
  }
  // OpenCV rectifies a rig whose cameras are mostly above each other into rows that match
  // vertically (the offset is in P2's second row); the sequence format stores side-by-side views.
  const double horizontal = p2.at<double>(0, 3), vertical = p2.at<double>(1, 3);
  if (std::abs(vertical) > std::abs(horizontal)) {
    throw Error("stereo rectification: the second camera is above or below the first (T = " + std::to_string(t[0]) +
                ", " + std::to_string(t[1]) + ", " + std::to_string(t[2]) +
                "), and the sequence format stores a side-by-side pair");
  }
  if (horizontal > 0.0) {
    throw Error("stereo rectification: the second (\"right\") camera is to the left of the first (T's x is " +
                std::to_string(t[0]) + " > 0): swap the two cameras");
  }
  const double f = p1.at<double>(0, 0);
  camera_ = Camera::Pinhole(size.width, size.height, f, p1.at<double>(1, 1), p1.at<double>(0, 2), p1.at<double>(1, 2));
  camera_.Check();
  baseline_mm_ = -horizontal / p2.at<double>(0, 0);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) rectified_from_left_(i, j) = r1.at<double>(i, j);
  }
  if (fisheye) {
    cv::fisheye::initUndistortRectifyMap(k1, left_distortion, r1, p1, size, CV_16SC2, left_maps_.first,
                                         left_maps_.second);
    cv::fisheye::initUndistortRectifyMap(k2, right_distortion, r2, p2, size, CV_16SC2, right_maps_.first,
                                         right_maps_.second);
  } else {
    cv::initUndistortRectifyMap(k1, left_distortion, r1, p1, size, CV_16SC2, left_maps_.first, left_maps_.second);
    cv::initUndistortRectifyMap(k2, right_distortion, r2, p2, size, CV_16SC2, right_maps_.first, right_maps_.second);
  }
}

cv::Mat StereoRectifier::Remapped(const cv::Mat& raw, const Maps& maps) const {
  if (raw.size() != raw_size_) {
    throw Error("stereo rectification: an image is " + std::to_string(raw.cols) + "x" + std::to_string(raw.rows) +
                " but the calibration is " + std::to_string(raw_size_.width) + "x" + std::to_string(raw_size_.height));
  }
  cv::Mat rectified;
  cv::remap(raw, rectified, maps.first, maps.second, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  return rectified;
}

}  // namespace nrslam
