// geometry: the Ceres manifold of a 7-number pose block [qx qy qz qw tx ty tz].
//
// Tangent vector (ρ, φ) ∈ R⁶: the update is applied on the left, in the frame the pose maps
// into, R ← Exp(φ)·R and t ← Exp(φ)·t + ρ. For a cam_from_world pose this perturbs the camera
// in its own frame, which keeps the tangent well scaled for every point in front of it.
// Jacobians come from ceres::AutoDiffManifold, so there is no hand-written derivative.
#pragma once

#include <ceres/autodiff_manifold.h>
#include <ceres/rotation.h>

namespace nrslam {

struct Se3PlusMinus {
  template <typename T>
  bool Plus(const T* x, const T* delta, T* x_plus_delta) const {
    T q_delta_wxyz[4];
    ceres::AngleAxisToQuaternion(delta + 3, q_delta_wxyz);
    const Eigen::Quaternion<T> q_delta(q_delta_wxyz[0], q_delta_wxyz[1], q_delta_wxyz[2], q_delta_wxyz[3]);
    const Eigen::Map<const Eigen::Quaternion<T>> q(x);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t(x + 4);
    Eigen::Map<Eigen::Quaternion<T>> q_out(x_plus_delta);
    Eigen::Map<Eigen::Matrix<T, 3, 1>> t_out(x_plus_delta + 4);
    q_out = q_delta * q;
    t_out = q_delta * t + Eigen::Map<const Eigen::Matrix<T, 3, 1>>(delta);
    return true;
  }

  template <typename T>
  bool Minus(const T* y, const T* x, T* y_minus_x) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_y(y);
    const Eigen::Map<const Eigen::Quaternion<T>> q_x(x);
    Eigen::Quaternion<T> q_delta = q_y * q_x.conjugate();
    // Same rotation either sign; take the short way round so Minus inverts Plus.
    if (q_delta.w() < T(0)) q_delta.coeffs() = -q_delta.coeffs();
    const T q_delta_wxyz[4] = {q_delta.w(), q_delta.x(), q_delta.y(), q_delta.z()};
    ceres::QuaternionToAngleAxis(q_delta_wxyz, y_minus_x + 3);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_y(y + 4);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_x(x + 4);
    Eigen::Map<Eigen::Matrix<T, 3, 1>> translation_difference(y_minus_x);
    translation_difference = t_y - q_delta * t_x;
    return true;
  }
};

using Se3Manifold = ceres::AutoDiffManifold<Se3PlusMinus, 7, 6>;

}  // namespace nrslam
