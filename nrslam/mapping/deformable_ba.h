// mapping: keyframes and the sliding-window Deformable Bundle Adjustment (paper eq. DBA;
// reference-behaviour §1.4, §2.2).
//
// Variables: each window keyframe's pose and one 3D position per (keyframe, point) — the map
// is a shape per keyframe. Residuals: reprojection of every (keyframe, point) (σ, Huber as in
// tracking); elastic springs within each keyframe between a point and its best D graph
// neighbours seen by that keyframe (no robust kernel, as the reference); viscous dampers on
// the motion of neighbour pairs between consecutive keyframes (Huber). Rigid mode has one
// position per point for the whole window and no regularisers: plain bundle adjustment.
//
// Gauge: the oldest keyframe's pose is held fixed (the reference leaves all 7 gauge
// freedoms to LM damping). Scale needs no anchor: the elastic rest lengths fix it; in rigid
// mode the fixed pose and the previous map set it, and LM's damping keeps it there.
// Solver: CGNR (conjugate gradients on the normal equations, block-Jacobi preconditioned),
// which only multiplies by the sparse Jacobian. Measured per DBA on sim-0 (640x480, 5
// keyframes): 180 ms, against 527 ms for SuiteSparse sparse normal Cholesky and 866 ms for
// Eigen's: the per-keyframe positions make the Cholesky factor fill in.
#pragma once

#include <Eigen/Core>

#include <vector>

#include "nrslam/camera/camera.h"
#include "nrslam/deformation/deformation_graph.h"
#include "nrslam/deformation/deformation_options.h"
#include "nrslam/geometry/rigid3.h"

namespace nrslam {

struct Keyframe {
  int frame = 0;
  Rigid3 cam_from_world;
  std::vector<PointId> ids;              // the 3D points it observes ...
  std::vector<Eigen::Vector2d> pixels;   // ... where ...
  std::vector<Eigen::Vector3d> positions;  // ... and their shape at this keyframe (world)
};

struct DbaReport {
  int keyframes = 0, points = 0, residual_blocks = 0;
  double initial_cost = 0, final_cost = 0;
  // Filled by the mapper: which model adjusted the window, and its model-selection statistics
  // (negative when not measured; mapping.dba_model_selection).
  bool rigid = false;
  double baseline_ratio = -1, rigid_inlier_fraction = -1;
  double tracked_deformation = -1;  // median per-frame median ‖δ‖ / map scale over the window
};

// A regularised pair of one window keyframe: a point and one of its best D graph
// neighbours, both seen by that keyframe (indices into its ids), with the edge's rest length
// and weight b. next_i, next_j index the same two points in the next keyframe when both are
// seen there too (they then also get a viscous term), else −1.
struct DbaPair {
  size_t i = 0, j = 0;
  double rest_length = 0, weight_b = 0;
  int next_i = -1, next_j = -1;
};
using DbaRegularisers = std::vector<std::vector<DbaPair>>;  // per window keyframe

// Reads the graph once for a window, so that the adjustment itself needs no access to the
// live map and can run beside tracking (MappingOptions::dba_lag_frames).
DbaRegularisers WindowRegularisers(const DeformationGraph& graph, const std::vector<Keyframe*>& window);

// Refines `window` (oldest first) in place. `regularisers` (from WindowRegularisers on the
// same window) are used unless `rigid`.
DbaReport DeformableBundleAdjustment(const Camera& camera, const DeformationModelOptions& options,
                                     const DbaRegularisers& regularisers, double map_scale, int iterations, bool rigid,
                                     const std::vector<Keyframe*>& window);

}  // namespace nrslam
