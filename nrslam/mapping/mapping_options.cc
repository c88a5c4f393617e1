#include "nrslam/mapping/mapping_options.h"

#include "nrslam/util/json_options.h"

namespace nrslam {

void InitialisationOptions::Check() const {
  CheckOption(min_tracks >= 8 && min_points >= 8, "initialisation", "min_tracks and min_points must be >= 8");
  CheckOption(max_reference_age >= 1 && ransac_iterations >= 1, "initialisation",
              "max_reference_age and ransac_iterations must be >= 1");
  CheckOption(epipolar_threshold_px > 0 && min_parallax_px >= 0 && max_reprojection_px2 > 0 && median_depth > 0,
              "initialisation", "thresholds and median_depth must be positive");
  CheckOption(max_low_parallax_fraction >= 0 && max_low_parallax_fraction <= 1, "initialisation",
              "max_low_parallax_fraction must be in [0, 1]");
  CheckOption(point_min_parallax_snr >= 0, "initialisation", "point_min_parallax_snr must be >= 0");
  CheckOption(shading_weight >= 0 && shading_weight <= 1, "initialisation", "shading_weight must be in [0, 1]");
  CheckOption(initial_graph == "complete" || initial_graph == "flow_clusters", "initialisation",
              "initial_graph must be complete or flow_clusters, got '" + initial_graph + "'");
  CheckOption(dbscan_epsilon_px > 0 && dbscan_min_points >= 1, "initialisation", "DBSCAN parameters must be positive");
}

void MappingOptions::Check() const {
  CheckOption(dba_window >= 2 && dba_min_keyframes >= 2 && dba_min_keyframes <= dba_window && dba_iterations >= 1,
              "mapping", "need 2 <= dba_min_keyframes <= dba_window and dba_iterations >= 1");
  CheckOption(dba_lag_frames >= 0, "mapping", "dba_lag_frames must be >= 0");
  CheckOption(temporal_window >= 2 && neighbours >= 1 && deformable_min_track >= 2 && deformable_iterations >= 1,
              "mapping", "temporal_window, neighbours, deformable_min_track and iterations out of range");
  CheckOption(crowding_radius_px >= 0 && neighbour_radius_px > crowding_radius_px, "mapping",
              "need 0 <= crowding_radius_px < neighbour_radius_px");
  CheckOption(rigid_min_parallax_px >= 0 && rigid_max_parallax_px > rigid_min_parallax_px, "mapping",
              "need 0 <= rigid_min_parallax_px < rigid_max_parallax_px");
  CheckOption(rigidity_threshold >= 0 && max_reprojection_px2 > 0 && flow_sigma > 0 && flow_outlier_chi2 > 0 &&
                  reprojection_outlier_chi2 > 0 && deformable_min_parallax_px >= 0,
              "mapping", "thresholds must be positive");
  CheckOption(rigid_warmup_keyframes >= 0, "mapping", "rigid_warmup_keyframes must be >= 0");
  CheckOption(rigid_warmup_min_inliers >= 0 && rigid_warmup_min_inliers <= 1, "mapping",
              "rigid_warmup_min_inliers must be in [0, 1]");
  CheckOption(new_point_shading_weight >= 0 && new_point_shading_weight <= 1, "mapping",
              "new_point_shading_weight must be in [0, 1]");
  CheckOption(rigid_dba_min_inliers >= 0 && rigid_dba_min_inliers <= 1 && rigid_dba_min_baseline >= 0 &&
                  rigid_dba_max_deformation >= 0,
              "mapping", "need rigid_dba_min_inliers in [0, 1], rigid_dba_min_baseline >= 0 and rigid_dba_max_deformation >= 0");
  CheckOption(max_depth_ratio >= 1, "mapping", "max_depth_ratio must be >= 1");
  CheckOption(max_batch_depth_bias == 0 || max_batch_depth_bias >= 1, "mapping",
              "max_batch_depth_bias must be 0 (off) or >= 1");
  CheckOption(batch_check_min_points >= 1, "mapping", "batch_check_min_points must be >= 1");
  CheckOption(deformable_agreement_ratio == 0 || deformable_agreement_ratio >= 1, "mapping",
              "deformable_agreement_ratio must be 0 (off) or >= 1");
  CheckOption(deformable_max_epipolar_ratio >= 0 && starving_max_epipolar_ratio >= 0, "mapping",
              "deformable_max_epipolar_ratio and starving_max_epipolar_ratio must be >= 0 (0 = off)");
  CheckOption(deformable_gate_span == "oldest" || deformable_gate_span == "shortest", "mapping",
              "deformable_gate_span must be oldest or shortest, got '" + deformable_gate_span + "'");
  CheckOption(shortest_gate_below_fraction >= 0 && shortest_gate_below_fraction <= 1, "mapping",
              "shortest_gate_below_fraction must be in [0, 1]");
  CheckOption(model_selection_factor >= 1, "mapping", "model_selection_factor must be >= 1");
  CheckOption(deformable_function_tolerance > 0 && deformable_function_tolerance < 1, "mapping",
              "deformable_function_tolerance must be in (0, 1)");
}

}  // namespace nrslam
