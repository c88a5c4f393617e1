// deformation: the elastic (spring) and viscous (damper) regularisers as Ceres cost functions.
//
// Both residuals are linear in what they penalise, times a multiplier that carries the
// weighting (deformation_options.h), so that the squared residual is the energy:
//   elastic  r = c_e · (d − d0),  d = ‖x_i − x_j‖;
//     paper:     c_e = √(k/d0)          → r² = k (d − d0)²/d0
//     reference: c_e = k / (d0 · σ_e)   → r² = k² (d − d0)²/(d0² σ_e²)
//   viscous  r = c_v · (δ_i − δ_j);
//     paper:     c_v = √b               → r² = b ‖δ_i − δ_j‖²
//     reference: c_v = b / (σ_v · s)    → r² = b² ‖δ_i − δ_j‖²/(σ_v s)²   (s = map scale)
#pragma once

#include <ceres/autodiff_cost_function.h>
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <cmath>

#include "nrslam/deformation/deformation_options.h"

namespace nrslam {

double ElasticMultiplier(const DeformationModelOptions& options, double rest_length);
double ViscousMultiplier(const DeformationModelOptions& options, double edge_weight_b, double map_scale);

// Spring between two points whose positions are base + parameter: in tracking the bases are
// the previous positions and the parameters the displacements δ; in DBA the bases are zero
// and the parameters a keyframe's positions x^k. Analytic Jacobians: tracking evaluates
// thousands of these per iteration (bench_tracking: the deformation stage 1–7 % faster).
class ElasticCost final : public ceres::SizedCostFunction<1, 3, 3> {
 public:
  ElasticCost(const Eigen::Vector3d& base_i, const Eigen::Vector3d& base_j, double rest_length, double multiplier)
      : base_difference_(base_i - base_j), rest_length_(rest_length), multiplier_(multiplier) {}

  bool Evaluate(double const* const* parameters, double* residual, double** jacobians) const override {
    const Eigen::Map<const Eigen::Vector3d> p_i(parameters[0]), p_j(parameters[1]);
    const Eigen::Vector3d difference = base_difference_ + p_i - p_j;
    // The epsilon keeps the derivative finite for coincident points (never met in practice).
    const double length = std::sqrt(difference.squaredNorm() + 1e-24);
    residual[0] = multiplier_ * (length - rest_length_);
    if (jacobians == nullptr) return true;  // Ceres asks for residuals alone when it tries a step
    const Eigen::Vector3d gradient = (multiplier_ / length) * difference;  // ∂r/∂p_i = −∂r/∂p_j
    if (jacobians[0] != nullptr) Eigen::Map<Eigen::Vector3d>{jacobians[0]} = gradient;
    if (jacobians[1] != nullptr) Eigen::Map<Eigen::Vector3d>{jacobians[1]} = -gradient;
    return true;
  }
  static ceres::CostFunction* Create(const Eigen::Vector3d& base_i, const Eigen::Vector3d& base_j,
                                     double rest_length, double multiplier) {
    return new ElasticCost(base_i, base_j, rest_length, multiplier);
  }

 private:
  Eigen::Vector3d base_difference_;  // base_i − base_j
  double rest_length_;               // d0, map units
  double multiplier_;                // c_e
};

// Damper on the difference of two points' motions over one frame (tracking): δ_i − δ_j.
// Linear, so its Jacobians are the constants ±c_v·I (analytic for the reason above).
class ViscousCost final : public ceres::SizedCostFunction<3, 3, 3> {
 public:
  explicit ViscousCost(double multiplier) : multiplier_(multiplier) {}

  bool Evaluate(double const* const* parameters, double* residual, double** jacobians) const override {
    for (int a = 0; a < 3; ++a) residual[a] = multiplier_ * (parameters[0][a] - parameters[1][a]);
    if (jacobians == nullptr) return true;
    for (int block = 0; block < 2; ++block) {
      if (jacobians[block] == nullptr) continue;
      // Row-major 3×3, as Ceres lays out a block's Jacobian.
      Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>{jacobians[block]} =
          (block == 0 ? multiplier_ : -multiplier_) * Eigen::Matrix3d::Identity();
    }
    return true;
  }
  static ceres::CostFunction* Create(double multiplier) { return new ViscousCost(multiplier); }

 private:
  double multiplier_;  // c_v
};

// The same damper between consecutive keyframes k, k+1 of the DBA window, where the motions
// are differences of per-keyframe positions: (x_i^{k+1} − x_i^k) − (x_j^{k+1} − x_j^k).
struct ViscousKeyframeCost {
  double multiplier;

  template <typename T>
  bool operator()(const T* x_i_k, const T* x_i_next, const T* x_j_k, const T* x_j_next, T* residual) const {
    for (int a = 0; a < 3; ++a) {
      residual[a] = T(multiplier) * ((x_i_next[a] - x_i_k[a]) - (x_j_next[a] - x_j_k[a]));
    }
    return true;
  }
  static ceres::CostFunction* Create(double multiplier) {
    return new ceres::AutoDiffCostFunction<ViscousKeyframeCost, 3, 3, 3, 3, 3>(new ViscousKeyframeCost{multiplier});
  }
};

// Deformable triangulation (mapping): a new point's world positions X_a, X_b in two frames
// must move like its neighbours did between them: r = c · ((X_b − X_a) − flow), with flow
// the neighbours' mean motion and c = √N / σ, so r² equals the sum over the N neighbours of
// ‖(X_b − X_a) − flow_n‖²/σ² up to a constant.
struct NeighbourFlowCost {
  Eigen::Vector3d flow;
  double multiplier;

  template <typename T>
  bool operator()(const T* x_a, const T* x_b, T* residual) const {
    for (int a = 0; a < 3; ++a) residual[a] = T(multiplier) * ((x_b[a] - x_a[a]) - T(flow[a]));
    return true;
  }
  static ceres::CostFunction* Create(const Eigen::Vector3d& flow, double multiplier) {
    return new ceres::AutoDiffCostFunction<NeighbourFlowCost, 3, 3, 3>(new NeighbourFlowCost{flow, multiplier});
  }
};

}  // namespace nrslam
