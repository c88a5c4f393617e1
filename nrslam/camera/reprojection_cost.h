// camera: reprojection residuals as Ceres cost functors, for any camera model.
//
// Residual = (observed − π(T_cw · x)) / σ, in units of σ (so a Huber δ is in "sigmas").
// Pose blocks are 7 numbers [qx qy qz qw tx ty tz] (cam_from_world) with Se3Manifold.
//  - ReprojectionCost (pose, point): rigid pose refinement (point held constant), rigid and
//    deformable triangulation, and DBA, where `point` is that keyframe's own copy x_i^k.
//  - DeformedReprojectionCost (pose, displacement): deformable tracking, projecting
//    x_i^{t-1} + δ_i^t. The previous position x_i^{t-1} is a constant of the functor, not a
//    parameter block: a constant block would still widen every autodiff jet by 3.
#pragma once

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>
#include <algorithm>
#include <limits>
#include <vector>

#include "nrslam/camera/camera.h"
#include "nrslam/geometry/rigid3.h"

namespace nrslam {

template <typename Model>
class ProjectionResidual {
 public:
  ProjectionResidual(const Eigen::Vector2d& observed, const std::vector<double>& camera_params, double sigma_px)
      : observed_(observed), inverse_sigma_(1.0 / sigma_px) {
    std::copy_n(camera_params.begin(), Model::kNumParams, params_);
  }

  template <typename T>
  bool Evaluate(const T* pose, const Eigen::Matrix<T, 3, 1>& world_point, T* residual) const {
    const Eigen::Matrix<T, 3, 1> camera_point = TransformPoint(pose, world_point);
    T pixel[2];
    if (!Model::Project(params_, camera_point.data(), pixel)) return false;  // behind the camera
    residual[0] = (T(observed_.x()) - pixel[0]) * inverse_sigma_;
    residual[1] = (T(observed_.y()) - pixel[1]) * inverse_sigma_;
    return true;
  }

 private:
  Eigen::Vector2d observed_;
  double params_[Model::kNumParams];
  double inverse_sigma_;
};

template <typename Model>
struct ReprojectionCost {
  ProjectionResidual<Model> projection;

  template <typename T>
  bool operator()(const T* pose, const T* point, T* residual) const {
    return projection.Evaluate(pose, Eigen::Matrix<T, 3, 1>(point[0], point[1], point[2]), residual);
  }
  static ceres::CostFunction* Create(const Eigen::Vector2d& observed, const Camera& camera, double sigma_px) {
    return new ceres::AutoDiffCostFunction<ReprojectionCost, 2, kPoseParams, 3>(
        new ReprojectionCost{ProjectionResidual<Model>(observed, camera.params(), sigma_px)});
  }
};

template <typename Model>
struct DeformedReprojectionCost {
  ProjectionResidual<Model> projection;
  Eigen::Vector3d point;  // x_i^{t-1}

  template <typename T>
  bool operator()(const T* pose, const T* displacement, T* residual) const {
    const Eigen::Matrix<T, 3, 1> moved(T(point.x()) + displacement[0], T(point.y()) + displacement[1],
                                       T(point.z()) + displacement[2]);
    return projection.Evaluate(pose, moved, residual);
  }
  static ceres::CostFunction* Create(const Eigen::Vector2d& observed, const Eigen::Vector3d& point,
                                     const Camera& camera, double sigma_px) {
    return new ceres::AutoDiffCostFunction<DeformedReprojectionCost, 2, kPoseParams, 3>(
        new DeformedReprojectionCost{ProjectionResidual<Model>(observed, camera.params(), sigma_px), point});
  }
};

// Squared pixel distance between `observed` and the projection of `world`; infinite when the
// point does not project (behind the camera, off the model's domain).
inline double SquaredReprojectionError(const Camera& camera, const Rigid3& cam_from_world, const Eigen::Vector3d& world,
                                       const Eigen::Vector2d& observed) {
  const auto pixel = camera.Project(cam_from_world * world);
  return pixel ? (*pixel - observed).squaredNorm() : std::numeric_limits<double>::infinity();
}

// The functors above for the camera's model.
inline ceres::CostFunction* CreateReprojectionCost(const Camera& camera, const Eigen::Vector2d& observed,
                                                   double sigma_px) {
  return VisitCameraModel(camera.model(), [&](auto model) {
    return ReprojectionCost<decltype(model)>::Create(observed, camera, sigma_px);
  });
}
inline ceres::CostFunction* CreateDeformedReprojectionCost(const Camera& camera, const Eigen::Vector2d& observed,
                                                           const Eigen::Vector3d& point, double sigma_px) {
  return VisitCameraModel(camera.model(), [&](auto model) {
    return DeformedReprojectionCost<decltype(model)>::Create(observed, point, camera, sigma_px);
  });
}

}  // namespace nrslam
