// camera: the projection models, as stateless structs templated on the scalar.
//
// Pixel convention: (0, 0) is the centre of the top-left pixel (OpenCV's), u to the right,
// v down; camera frame x right, y down, z forward. Unproject returns a unit bearing, for
// every model, so consumers never need to know which model produced a ray.
#pragma once

#include <Eigen/Core>

#include <cmath>

namespace nrslam {

enum class CameraModelId { kPinhole, kKannalaBrandt };

// params = [fx, fy, cx, cy]
struct PinholeModel {
  static constexpr CameraModelId kId = CameraModelId::kPinhole;
  static constexpr int kNumParams = 4;
  static constexpr const char* kName = "pinhole";

  // False for points at or behind the image plane.
  template <typename T>
  static bool Project(const T* params, const T* point, T* pixel) {
    if (!(point[2] > T(0))) return false;
    const T inverse_z = T(1) / point[2];
    pixel[0] = params[0] * point[0] * inverse_z + params[2];
    pixel[1] = params[1] * point[1] * inverse_z + params[3];
    return true;
  }

  static Eigen::Vector3d Unproject(const double* params, double u, double v) {
    return Eigen::Vector3d((u - params[2]) / params[0], (v - params[3]) / params[1], 1.0).normalized();
  }
};

// Kannala–Brandt with four coefficients (the common "KB8" / OpenCV fisheye form):
// params = [fx, fy, cx, cy, k0, k1, k2, k3], r(θ) = θ + k0 θ³ + k1 θ⁵ + k2 θ⁷ + k3 θ⁹,
// where θ is the angle between the ray and the optical axis.
struct KannalaBrandtModel {
  static constexpr CameraModelId kId = CameraModelId::kKannalaBrandt;
  static constexpr int kNumParams = 8;
  static constexpr const char* kName = "kannala_brandt";

  template <typename T>
  static T Distort(const T* params, const T& theta) {
    const T theta2 = theta * theta;
    return theta * (T(1) + theta2 * (params[4] + theta2 * (params[5] + theta2 * (params[6] + theta2 * params[7]))));
  }

  // Defined for every direction but the backward axis; whether θ is inside the lens's
  // field of view is the Camera's business (Camera::max_theta()).
  template <typename T>
  static bool Project(const T* params, const T* point, T* pixel) {
    using std::atan2;
    using std::sqrt;
    const T rho2 = point[0] * point[0] + point[1] * point[1];
    T scale;  // r(θ) / ρ, the factor that maps (x, y) to the normalised image plane
    if (rho2 < T(1e-20) * point[2] * point[2]) {
      // On the axis θ/ρ → 1/z; the series keeps Jets finite where sqrt(ρ²) would not be.
      if (!(point[2] > T(0))) return false;
      scale = T(1) / point[2];
    } else {
      const T rho = sqrt(rho2);
      scale = Distort(params, atan2(rho, point[2])) / rho;
    }
    pixel[0] = params[0] * scale * point[0] + params[2];
    pixel[1] = params[1] * scale * point[1] + params[3];
    return true;
  }

  static Eigen::Vector3d Unproject(const double* params, double u, double v) {
    const double mx = (u - params[2]) / params[0];
    const double my = (v - params[3]) / params[1];
    const double theta_d = std::sqrt(mx * mx + my * my);
    if (theta_d < 1e-12) return Eigen::Vector3d::UnitZ();
    // Newton on r(θ) = θ_d, starting from the undistorted angle.
    double theta = theta_d;
    for (int iteration = 0; iteration < 20; ++iteration) {
      const double t2 = theta * theta;
      const double r = Distort(params, theta);
      const double dr = 1 + t2 * (3 * params[4] + t2 * (5 * params[5] + t2 * (7 * params[6] + t2 * 9 * params[7])));
      const double step = (r - theta_d) / dr;
      theta -= step;
      if (std::abs(step) < 1e-13) break;
    }
    const double s = std::sin(theta) / theta_d;
    return Eigen::Vector3d(s * mx, s * my, std::cos(theta));
  }
};

// Calls f(Model{}) with the model type for `id`, so templated code is written once.
template <typename Function>
decltype(auto) VisitCameraModel(CameraModelId id, Function&& f) {
  switch (id) {
    case CameraModelId::kKannalaBrandt:
      return f(KannalaBrandtModel{});
    case CameraModelId::kPinhole:
    default:
      return f(PinholeModel{});
  }
}

}  // namespace nrslam
