#include "nrslam/tracking/tracking_options.h"

#include "nrslam/util/json_options.h"

namespace nrslam {

void TrackingOptions::Check() const {
  CheckOption(max_points >= 10, "tracking", "max_points must be >= 10");
  CheckOption(keyframe_period >= 1, "tracking", "keyframe_period must be >= 1");
  CheckOption(min_points >= 3, "tracking", "min_points must be >= 3");
  CheckOption(jump_flow_ratio == 0 || jump_flow_ratio >= 1, "tracking", "jump_flow_ratio must be 0 (no note) or >= 1");
  CheckOption(max_dropout_frames >= 0, "tracking", "max_dropout_frames must be >= 0 (0: a dropout is lost at once)");
  CheckOption(min_tracked_fraction >= 0 && min_tracked_fraction <= 1, "tracking",
              "min_tracked_fraction must be in [0, 1]");
  CheckOption(dropout_min_match_ssim >= 0 && dropout_min_match_ssim <= 1, "tracking",
              "dropout_min_match_ssim must be in [0, 1] (1: every frame under min_tracked_fraction is a dropout)");
  CheckOption(pose_rounds >= 1 && pose_iterations >= 1 && deformation_rounds >= 1 && deformation_iterations >= 1,
              "tracking", "rounds and iterations must be >= 1");
  CheckOption(joint_linear_solver == "sparse_cholesky" || joint_linear_solver == "cgnr", "tracking",
              "joint_linear_solver must be sparse_cholesky or cgnr, got '" + joint_linear_solver + "'");
  CheckOption(joint_trust_region == "levenberg_marquardt" || joint_trust_region == "dogleg", "tracking",
              "joint_trust_region must be levenberg_marquardt or dogleg, got '" + joint_trust_region + "'");
  CheckOption(joint_solve_max_points == 0 || joint_solve_max_points >= min_points, "tracking",
              "joint_solve_max_points must be 0 (every point) or >= min_points");
  CheckOption(pose_sigma_px > 0 && outlier_chi2 > 0 && displacement_iqr_factor > 0, "tracking",
              "sigma, chi2 and IQR factor must be > 0");
  CheckOption(displacement_prior_sigma >= 0, "tracking", "displacement_prior_sigma must be >= 0 (0: no prior)");
  CheckOption(reassociation_consensus_k >= 0, "tracking", "reassociation_consensus_k must be >= 0 (0: the gate alone)");
  CheckOption(hidden_recent_frames >= 0 && hidden_min_edge_fraction >= 0 && hidden_min_edge_fraction < 0.5, "tracking",
              "hidden_recent_frames must be >= 0 and hidden_min_edge_fraction in [0, 0.5)");
  CheckOption(reassociation_levels >= 1 && reassociation_gate_px2 > 0 && lost_max_age_frames >= 1,
              "tracking", "reassociation_levels, reassociation_gate_px2 and lost_max_age_frames must be positive");
}

}  // namespace nrslam
