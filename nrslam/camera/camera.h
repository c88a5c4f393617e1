// camera: a camera model with its intrinsics and image size.
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

#include "nrslam/camera/camera_models.h"

namespace nrslam {

class Camera {
 public:
  Camera() = default;  // an invalid camera; Check() throws
  static Camera Pinhole(int width, int height, double fx, double fy, double cx, double cy);
  static Camera KannalaBrandt(int width, int height, double fx, double fy, double cx, double cy,
                              const Eigen::Vector4d& k);
  // OpenCV's radial-tangential model (camera_models.h) with OpenCV's distCoeffs: 4 (k1 k2 p1 p2),
  // 5 (… k3) or 8 (… k4 k5 k6, the rational model) of them; other counts throw Error.
  static Camera OpenCv(int width, int height, double fx, double fy, double cx, double cy,
                       const std::vector<double>& distortion);
  // OCamCalib's model (camera_models.h): centre at column cx, row cy; `direct` is ss and
  // `inverse` is invpol, lowest order first, at most OcamModel::kMaxDirect / kMaxInverse terms.
  // An empty `inverse` is fitted to `direct` over the image (calibrations that give only ss).
  static Camera Ocam(int width, int height, double cx, double cy, double c, double d, double e,
                     const std::vector<double>& direct, const std::vector<double>& inverse);

  // The same lens for its images resized to width × height, as cv::resize maps pixels (centres
  // scale about the image's corner: u' = (u + 0.5)·width'/width − 0.5). Throws Error on a size ≤ 0.
  Camera Resized(int width, int height) const;

  CameraModelId model() const { return model_; }
  std::string model_name() const;
  int width() const { return width_; }
  int height() const { return height_; }
  const std::vector<double>& params() const { return params_; }
  double fx() const { return params_[0]; }
  double fy() const { return params_[1]; }
  double cx() const { return params_[2]; }
  double cy() const { return params_[3]; }

  // Largest angle from the optical axis the model maps one-to-one (rad): π/2 for pinhole,
  // the end of the monotonic part of r(θ) for Kannala–Brandt (at most π) and of the radial
  // distortion for OpenCV's model (at most π/2), the widest ray of the image's border for OCam
  // (its polynomials are fitted over the image only).
  double max_theta() const { return max_theta_; }

  // Pixel of a point in camera coordinates; nullopt when the point is behind the camera
  // or outside the model's field of view. The pixel may still lie outside the image.
  std::optional<Eigen::Vector2d> Project(const Eigen::Vector3d& point) const;
  // Unit bearing of a pixel; beyond what the distortion reaches (a fisheye's image circle), the
  // bearing at max_theta().
  Eigen::Vector3d Unproject(const Eigen::Vector2d& pixel) const;
  // d pixel / d point at `point` (camera coordinates).
  Eigen::Matrix<double, 2, 3> ProjectionJacobian(const Eigen::Vector3d& point) const;

  bool InImage(const Eigen::Vector2d& pixel, double margin = 0.0) const {
    return pixel.x() >= margin && pixel.y() >= margin && pixel.x() <= width_ - 1 - margin &&
           pixel.y() <= height_ - 1 - margin;
  }
  // Mean focal length (px); its inverse is the angular size of a pixel at the centre.
  double MeanFocal() const { return 0.5 * (fx() + fy()); }

  // Throws Error naming the first thing wrong (non-positive size, negative focal length, ...).
  void Check() const;

 private:
  CameraModelId model_ = CameraModelId::kPinhole;
  int width_ = 0;
  int height_ = 0;
  std::vector<double> params_;
  double max_theta_ = 0.0;
  void ComputeMaxTheta();
  void CheckOcam() const;
  void CheckOpenCv() const;
  void CheckFieldOfView() const;
  // The ray of a pixel at normalised offset (mx, my) inside the Kannala–Brandt image circle.
  Eigen::Vector3d KannalaBrandtRay(double mx, double my, const Eigen::Vector3d& newton_ray) const;
};

// The model's name in sequence.json ("kannala_brandt").
std::string CameraModelName(CameraModelId model);
// The model here that a calibration tool's name for a lens model means: ROS's plumb_bob and
// rational_polynomial and Kalibr's radtan are opencv; equidistant and fisheye (Kalibr, ROS,
// OpenCV's fisheye module) are kannala_brandt. Nothing for any other name.
std::optional<CameraModelId> CameraModelOfToolName(const std::string& name);

void to_json(nlohmann::json& j, const Camera& camera);
// Validates (Check()) and throws Error on unknown model or missing fields.
void from_json(const nlohmann::json& j, Camera& camera);

}  // namespace nrslam
