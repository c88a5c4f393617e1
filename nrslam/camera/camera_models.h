// camera: the projection models, as stateless structs templated on the scalar of the point
// (the intrinsics are constants: no residual optimises them, so they stay plain doubles).
//
// Pixel convention: (0, 0) is the centre of the top-left pixel (OpenCV's), u to the right,
// v down; camera frame x right, y down, z forward. Unproject returns a unit bearing, for
// every model, so consumers never need to know which model produced a ray.
#pragma once

#include <ceres/jet.h>

#include <Eigen/Core>
#include <Eigen/LU>

#include <cmath>

namespace nrslam {

enum class CameraModelId { kPinhole, kKannalaBrandt, kOcam, kOpenCv };

// params = [fx, fy, cx, cy]
struct PinholeModel {
  static constexpr CameraModelId kId = CameraModelId::kPinhole;
  static constexpr int kNumParams = 4;
  static constexpr const char* kName = "pinhole";

  // False for points at or behind the image plane.
  template <typename T>
  static bool Project(const double* params, const T* point, T* pixel) {
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
  static T Distort(const double* params, const T& theta) {
    const T theta2 = theta * theta;
    return theta * (T(1) + theta2 * (params[4] + theta2 * (params[5] + theta2 * (params[6] + theta2 * params[7]))));
  }

  // Defined for every direction but the backward axis; whether θ is inside the lens's
  // field of view is the Camera's business (Camera::max_theta()).
  template <typename T>
  static bool Project(const double* params, const T* point, T* pixel) {
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

// OpenCV's pinhole model with radial-tangential (Brown–Conrady) distortion, as
// cv::calibrateCamera returns it: the model of most laparoscope and endoscope calibrations.
// params = [fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6] (OpenCV's distCoeffs order; a
// calibration with 4 or 5 coefficients leaves the rest 0, the rational model uses k4…k6).
// With (x, y) = (X/Z, Y/Z) and r² = x² + y²:
//   x' = x·R + 2p1·xy + p2(r² + 2x²),  y' = y·R + p1(r² + 2y²) + 2p2·xy,
//   R = (1 + k1r² + k2r⁴ + k3r⁶) / (1 + k4r² + k5r⁴ + k6r⁶),   u = fx·x' + cx, v = fy·y' + cy.
struct OpenCvModel {
  static constexpr CameraModelId kId = CameraModelId::kOpenCv;
  static constexpr int kNumParams = 12;
  static constexpr int kDistortionOffset = 4;
  static constexpr const char* kName = "opencv";

  // (x', y') of the undistorted normalised point (x, y).
  template <typename T>
  static void Distort(const double* params, const T& x, const T& y, T* distorted) {
    const double k1 = params[4], k2 = params[5], p1 = params[6], p2 = params[7];
    const double k3 = params[8], k4 = params[9], k5 = params[10], k6 = params[11];
    const T r2 = x * x + y * y;
    const T radial = (T(1) + r2 * (k1 + r2 * (k2 + r2 * k3))) / (T(1) + r2 * (k4 + r2 * (k5 + r2 * k6)));
    const T xy = x * y;
    distorted[0] = x * radial + T(2 * p1) * xy + p2 * (r2 + T(2) * x * x);
    distorted[1] = y * radial + p1 * (r2 + T(2) * y * y) + T(2 * p2) * xy;
  }

  // Distance from the axis, in the normalised image, of a point r from it without distortion
  // (the radial part alone): where it stops growing, two rays share a pixel.
  static double RadialDistort(const double* params, double r) {
    const double r2 = r * r;
    return r * (1 + r2 * (params[4] + r2 * (params[5] + r2 * params[8]))) /
           (1 + r2 * (params[9] + r2 * (params[10] + r2 * params[11])));
  }

  // False for points at or behind the image plane; whether the point is inside the field of
  // view the distortion is defined over is the Camera's business (Camera::max_theta()).
  template <typename T>
  static bool Project(const double* params, const T* point, T* pixel) {
    if (!(point[2] > T(0))) return false;
    const T inverse_z = T(1) / point[2];
    T distorted[2];
    Distort(params, point[0] * inverse_z, point[1] * inverse_z, distorted);
    pixel[0] = params[0] * distorted[0] + params[2];
    pixel[1] = params[1] * distorted[1] + params[3];
    return true;
  }

  // Newton's method on the distortion, from the distorted point itself. Pixels the distortion
  // does not reach (beyond its fold) give whatever the iteration ends at; Camera::Unproject
  // catches them.
  static Eigen::Vector3d Unproject(const double* params, double u, double v) {
    using Jet = ceres::Jet<double, 2>;
    const Eigen::Vector2d target((u - params[2]) / params[0], (v - params[3]) / params[1]);
    Eigen::Vector2d undistorted = target;
    for (int iteration = 0; iteration < 30; ++iteration) {
      Jet distorted[2];
      Distort(params, Jet(undistorted.x(), 0), Jet(undistorted.y(), 1), distorted);
      Eigen::Matrix2d jacobian;
      jacobian << distorted[0].v.transpose(), distorted[1].v.transpose();
      const Eigen::Vector2d step =
          jacobian.inverse() * (Eigen::Vector2d(distorted[0].a, distorted[1].a) - target);
      if (!step.allFinite()) break;
      undistorted -= step;
      if (step.norm() < 1e-15 * (1 + undistorted.norm())) break;
    }
    return Eigen::Vector3d(undistorted.x(), undistorted.y(), 1.0).normalized();
  }
};

// Scaramuzza's omnidirectional model as OCamCalib calibrates it (the model of C3VD and of many
// endoscope calibrations). OCamCalib's own frame has x down the rows, y along the columns and z
// out of the lens; here the usual frame is kept and the axes swapped inside.
// params = [f, f·c, cx, cy, c, d, e, ss[kMaxDirect], invpol[kMaxInverse]]:
//  - (cx, cy): the centre's column and row (OCamCalib writes "row column");
//  - c, d, e: the affine part, [row; col] offsets = [c d; e 1] · (a, b), where (a, b) are the
//    offsets along OCamCalib's x and y before it;
//  - ss: the direct polynomial: a pixel at distance ρ from the centre (after the affine part)
//    looks along (a, b, ss(ρ)) in OCamCalib's frame; unused trailing terms are 0;
//  - invpol: the inverse polynomial ρ(t), t = φ − π/2, φ the angle from the optical axis. Its
//    value on the axis (calibrations leave it at ~1e-3 px) is subtracted, so the axis maps to
//    the centre exactly;
//  - f, f·c: ρ'(0) in pixels per radian along the columns and the rows, derived; what the
//    other models call fx, fy, used for pixel-angle scales.
// Projection uses invpol (what the residuals differentiate); Unproject inverts exactly that
// projection by Newton's method, starting from the direct polynomial's ray.
struct OcamModel {
  static constexpr CameraModelId kId = CameraModelId::kOcam;
  static constexpr int kMaxDirect = 8;
  static constexpr int kMaxInverse = 32;
  static constexpr int kDirectOffset = 7;
  static constexpr int kInverseOffset = kDirectOffset + kMaxDirect;
  static constexpr int kNumParams = kInverseOffset + kMaxInverse;
  static constexpr const char* kName = "ocam";

  // invpol(t) and its derivative, by Horner.
  template <typename T>
  static T Inverse(const double* params, const T& t) {
    T value(0);
    for (int i = kMaxInverse - 1; i >= 0; --i) value = value * t + params[kInverseOffset + i];
    return value;
  }
  template <typename T>
  static T InverseDerivative(const double* params, const T& t) {
    T value(0);
    for (int i = kMaxInverse - 1; i >= 1; --i) value = value * t + i * params[kInverseOffset + i];
    return value;
  }
  // Pixel distance from the centre (before the affine part) of a ray φ off the axis.
  template <typename T>
  static T Radius(const double* params, const T& phi) {
    constexpr double kAxis = -M_PI / 2;
    return Inverse(params, phi + kAxis) - Inverse(params, kAxis);
  }

  template <typename T>
  static bool Project(const double* params, const T* point, T* pixel) {
    using std::atan2;
    using std::sqrt;
    const T& along_rows = point[1];
    const T& along_columns = point[0];
    const T norm2 = along_rows * along_rows + along_columns * along_columns;
    T scale;  // ρ / ‖(x, y)‖
    if (norm2 < T(1e-20) * point[2] * point[2]) {
      if (!(point[2] > T(0))) return false;
      scale = InverseDerivative(params, -M_PI / 2) / point[2];
    } else {
      const T norm = sqrt(norm2);
      scale = Radius(params, atan2(norm, point[2])) / norm;
    }
    const T a = scale * along_rows, b = scale * along_columns;
    pixel[1] = params[4] * a + params[5] * b + params[3];
    pixel[0] = params[6] * a + b + params[2];
    return true;
  }

  // Offsets (a along the rows, b along the columns) of a pixel before the affine part.
  static Eigen::Vector2d Unaffine(const double* params, double u, double v) {
    const double row = v - params[3], column = u - params[2];
    const double c = params[4], d = params[5], e = params[6];
    const double det = c - d * e;
    return Eigen::Vector2d((row - d * column) / det, (c * column - e * row) / det);
  }

  // ss(ρ): OCamCalib's z of the ray ρ px from the centre (after the affine part), by Horner.
  static double Direct(const double* params, double rho) {
    double z = 0.0;
    for (int i = kMaxDirect - 1; i >= 0; --i) z = z * rho + params[kDirectOffset + i];
    return z;
  }

  // The ray OCamCalib's direct polynomial gives a pixel (unit bearing, usual frame).
  static Eigen::Vector3d DirectRay(const double* params, double u, double v) {
    const Eigen::Vector2d ab = Unaffine(params, u, v);
    return Eigen::Vector3d(ab.y(), ab.x(), -Direct(params, ab.norm())).normalized();
  }

  static Eigen::Vector3d Unproject(const double* params, double u, double v) {
    const Eigen::Vector2d ab = Unaffine(params, u, v);
    const double rho = ab.norm();
    if (rho < 1e-12) return Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d start = DirectRay(params, u, v);
    double phi = std::atan2(start.head<2>().norm(), start.z());
    for (int iteration = 0; iteration < 30; ++iteration) {
      const double step =
          (Radius(params, phi) - rho) / InverseDerivative(params, phi - M_PI / 2);
      phi -= step;
      if (std::abs(step) < 1e-13) break;
    }
    const double s = std::sin(phi) / rho;
    return Eigen::Vector3d(s * ab.y(), s * ab.x(), std::cos(phi));
  }
};

// Calls f(Model{}) with the model type for `id`, so templated code is written once.
template <typename Function>
decltype(auto) VisitCameraModel(CameraModelId id, Function&& f) {
  switch (id) {
    case CameraModelId::kKannalaBrandt:
      return f(KannalaBrandtModel{});
    case CameraModelId::kOcam:
      return f(OcamModel{});
    case CameraModelId::kOpenCv:
      return f(OpenCvModel{});
    case CameraModelId::kPinhole:
    default:
      return f(PinholeModel{});
  }
}

}  // namespace nrslam
