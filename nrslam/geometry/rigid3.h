// geometry: rigid transforms in 3D.
//
// Naming: `Rigid3 a_from_b` maps coordinates in frame b to frame a, x_a = R x_b + t.
// Camera poses are stored as `cam_from_world` (T_cw) in the optimisers and written as
// `world_from_cam` (T_wc) in TUM files, as every trajectory tool expects.
//
// Ceres sees a pose as one 7-number parameter block [qx qy qz qw tx ty tz] (Eigen's
// quaternion coefficient order) with Se3Manifold (se3_manifold.h).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cmath>

namespace nrslam {

constexpr int kPoseParams = 7;
using PoseParams = std::array<double, kPoseParams>;

struct Rigid3 {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Rigid3() = default;
  Rigid3(const Eigen::Quaterniond& q, const Eigen::Vector3d& t) : rotation(q.normalized()), translation(t) {}

  static Rigid3 FromParams(const double* params) {
    return Rigid3(Eigen::Quaterniond(params[3], params[0], params[1], params[2]),
                  Eigen::Vector3d(params[4], params[5], params[6]));
  }
  PoseParams ToParams() const {
    return {rotation.x(), rotation.y(), rotation.z(), rotation.w(),
            translation.x(), translation.y(), translation.z()};
  }

  Eigen::Vector3d operator*(const Eigen::Vector3d& x) const { return rotation * x + translation; }
  Rigid3 operator*(const Rigid3& other) const {
    return Rigid3(rotation * other.rotation, rotation * other.translation + translation);
  }
  Rigid3 Inverse() const {
    const Eigen::Quaterniond inverse = rotation.conjugate();
    return Rigid3(inverse, -(inverse * translation));
  }
  Eigen::Matrix4d Matrix() const {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.topLeftCorner<3, 3>() = rotation.toRotationMatrix();
    m.topRightCorner<3, 1>() = translation;
    return m;
  }
};

// Whether a matrix read from a file is a rotation (orthonormal, not a reflection), to the
// precision calibration and pose files are written with.
inline bool IsRotation(const Eigen::Matrix3d& matrix, double tolerance = 1e-3) {
  return (matrix.transpose() * matrix - Eigen::Matrix3d::Identity()).norm() <= tolerance && matrix.determinant() > 0;
}

// Whether a quaternion read from a file is a rotation: of unit length to within what a text
// file's digits lose; a zero, far-off or non-finite one is not normalised into a pose.
inline bool IsUnitQuaternion(const Eigen::Quaterniond& q, double tolerance = 1e-3) {
  return std::abs(q.norm() - 1.0) <= tolerance;
}

// x_a = T_ab * x_b for a pose parameter block; templated for Ceres Jets.
template <typename T>
inline Eigen::Matrix<T, 3, 1> TransformPoint(const T* pose_params, const Eigen::Matrix<T, 3, 1>& x) {
  const Eigen::Map<const Eigen::Quaternion<T>> rotation(pose_params);
  const Eigen::Map<const Eigen::Matrix<T, 3, 1>> translation(pose_params + 4);
  return rotation * x + translation;
}

}  // namespace nrslam
