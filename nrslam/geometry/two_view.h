// geometry: two-view relations between unit bearing vectors (any camera model, fisheye
// included, since only rays are used): the essential matrix by RANSAC over the 8-point
// algorithm, its decomposition into a relative pose, and inverse-depth weighted mid-point
// triangulation (Lee & Civera 2019, "Triangulation: why optimize?").
#pragma once

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <vector>

#include "nrslam/geometry/rigid3.h"

namespace nrslam {

using Bearings = std::vector<Eigen::Vector3d>;

struct EssentialRansacOptions {
  int iterations = 200;               // minimal samples drawn
  double epipolar_threshold_rad = 0.005;  // inlier: angle between a bearing and its epipolar plane
  uint64_t seed = 4;                  // fixed, so a run is repeatable
};

struct EssentialEstimate {
  Eigen::Matrix3d essential = Eigen::Matrix3d::Zero();  // f_current^T E f_reference = 0
  std::vector<bool> inliers;
  int inlier_count = 0;
};

// E = [t]x R of a relative pose, |t| normalised to 1.
Eigen::Matrix3d EssentialFromPose(const Rigid3& current_from_reference);

// Angle (rad) between `current` and the epipolar plane of `reference` under `essential`.
double EpipolarAngle(const Eigen::Matrix3d& essential, const Eigen::Vector3d& reference, const Eigen::Vector3d& current);

// RANSAC over 8-point samples, then a least-squares refit on all inliers of the best sample
// (re-scored). nullopt with fewer than 8 pairs or no model.
std::optional<EssentialEstimate> EstimateEssential(const Bearings& reference, const Bearings& current,
                                                   const EssentialRansacOptions& options);

struct Triangulated {
  Eigen::Vector3d point;    // world
  double depth0 = 0, depth1 = 0;  // signed distances along the two rays
  double parallax_rad = 0;  // angle between the two rays
};

// Inverse-depth weighted mid-point of the rays centre0 + λ0·ray0 and centre1 + λ1·ray1 (world
// frame, unit rays). nullopt for parallel rays. Depths may be negative: the caller checks.
std::optional<Triangulated> TriangulateMidpoint(const Eigen::Vector3d& centre0, const Eigen::Vector3d& ray0,
                                                const Eigen::Vector3d& centre1, const Eigen::Vector3d& ray1);

// The relative pose current_from_reference (|t| = 1) of the four that E allows which puts
// the most inlier pairs in front of both cameras. Also reports that count.
Rigid3 DecomposeEssential(const Eigen::Matrix3d& essential, const Bearings& reference, const Bearings& current,
                          const std::vector<bool>& inliers, int* in_front = nullptr);

// Signed sine of the angle between the current bearing and the epipolar plane spanned by the
// translation and the rotated reference bearing. Parameters: rotation (angle-axis, rad) and
// translation of current_from_reference, the translation on the unit sphere (the two-view
// scale is free).
struct EpipolarCost {
  EpipolarCost(const Eigen::Vector3d& reference, const Eigen::Vector3d& current)
      : reference_(reference), current_(current) {}

  template <typename T>
  bool operator()(const T* angle_axis, const T* translation, T* residual) const {
    const Eigen::Matrix<T, 3, 1> reference = reference_.cast<T>();
    Eigen::Matrix<T, 3, 1> rotated;
    ceres::AngleAxisRotatePoint(angle_axis, reference.data(), rotated.data());
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t(translation);
    const Eigen::Matrix<T, 3, 1> normal = t.cross(rotated);
    residual[0] = normal.dot(current_.cast<T>()) / (normal.norm() + T(1e-12));
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& reference, const Eigen::Vector3d& current) {
    return new ceres::AutoDiffCostFunction<EpipolarCost, 1, 3, 3>(new EpipolarCost(reference, current));
  }

 private:
  Eigen::Vector3d reference_, current_;
};

// Refines current_from_reference (its translation normalised) by least squares on the
// epipolar angles of the inlier pairs, Cauchy-weighted at `scale_rad`. The linear 8-point fit
// minimises an algebraic error that is biased at low parallax and narrow fields of view,
// where rotation and translation are hard to tell apart. The result is the pose of the refined
// E that puts the most inliers in front (as DecomposeEssential).
Rigid3 RefineRelativePose(const Bearings& reference, const Bearings& current, const std::vector<bool>& inliers,
                          const Rigid3& current_from_reference, double scale_rad);

}  // namespace nrslam
