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
};

// Refines `window` (oldest first) in place; `graph` gives the edges and weights.
DbaReport DeformableBundleAdjustment(const Camera& camera, const DeformationModelOptions& options,
                                     const DeformationGraph& graph, double map_scale, int iterations, bool rigid,
                                     const std::vector<Keyframe*>& window);

}  // namespace nrslam
