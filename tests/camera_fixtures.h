// Tests: camera calibrations shared by the camera, cost-functor and simulator tests.
#pragma once

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <vector>

#include "nrslam/camera/camera.h"

namespace nrslam {

// An OCamCalib calibration of a 848x800 fisheye that sees up to 128° off its axis in the corners,
// as its calib_results.txt gives it (centre "row column" 390.949324 423.714757).
inline const std::vector<double> kOcamDirect = {-2.895569e+02, 0.000000e+00, 1.538894e-03, -3.140320e-06, 7.206996e-09};
inline const std::vector<double> kOcamInverse = {434.372025, 226.016722, -31.205890, 43.418508, 11.945692,
                                          -5.582063,  36.541804,  -10.674868, -55.334360, 1.105775,
                                          43.550131,  25.374995,  4.505945};
inline Camera OcamFisheye() {
  return Camera::Ocam(848, 800, 423.714757, 390.949324, 0.999134, -0.000325, -0.000071, kOcamDirect, kOcamInverse);
}

// OpenCV calibrations of a wide laparoscope, 640x480, about 100° across: five coefficients (a
// strong barrel: the corners' rays, 57° off the axis, land 28 % nearer the centre than a pinhole
// would put them), and the rational model's eight.
inline Camera OpenCvLaparoscope() {
  return Camera::OpenCv(640, 480, 360.0, 362.5, 322.4, 236.8, {-0.30, 0.10, 0.0008, -0.0006, -0.01});
}
inline Camera OpenCvRational() {
  return Camera::OpenCv(640, 480, 360.0, 362.5, 322.4, 236.8, {0.2, 0.01, 0.0008, -0.0006, 0.0005, 0.4, 0.02, 0.001});
}

// A Kannala–Brandt camera written in OCamCalib's terms: f·r(θ) expanded about θ = π/2 is an
// exact inverse polynomial, the direct one is fitted, fy / fx is the affine c.
inline Camera OcamFromKannalaBrandt(const Camera& kb) {
  const std::vector<double>& p = kb.params();
  const double radius[10] = {0, p[0], 0, p[0] * p[4], 0, p[0] * p[5], 0, p[0] * p[6], 0, p[0] * p[7]};
  std::vector<double> inverse(10, 0.0);
  for (int n = 1; n < 10; ++n) {
    double binomial = 1;  // C(n, j)
    for (int j = 0; j <= n; ++j) {
      inverse[j] += radius[n] * binomial * std::pow(M_PI / 2, n - j);
      binomial = binomial * (n - j) / (j + 1);
    }
  }
  constexpr int kSamples = 400, kDegree = 7;
  const double widest = std::hypot(std::max(kb.cx(), kb.width() - 1 - kb.cx()), std::max(kb.cy(), kb.height() - 1 - kb.cy()));
  Eigen::MatrixXd basis(kSamples + 1, kDegree + 1);
  Eigen::VectorXd z(kSamples + 1);
  for (int i = 0; i <= kSamples; ++i) {
    const double rho = widest * i / kSamples;
    const Eigen::Vector3d ray = kb.Unproject(Eigen::Vector2d(kb.cx() + rho, kb.cy()));
    const double theta = std::atan2(ray.head<2>().norm(), ray.z());
    z[i] = i == 0 ? -p[0] : -rho / std::tan(theta);
    for (int k = 0; k <= kDegree; ++k) basis(i, k) = std::pow(rho / widest, k);
  }
  const Eigen::VectorXd scaled = basis.colPivHouseholderQr().solve(z);
  std::vector<double> direct(kDegree + 1);
  for (int k = 0; k <= kDegree; ++k) direct[k] = scaled[k] / std::pow(widest, k);
  return Camera::Ocam(kb.width(), kb.height(), kb.cx(), kb.cy(), kb.fy() / kb.fx(), 0, 0, direct, inverse);
}

}  // namespace nrslam
