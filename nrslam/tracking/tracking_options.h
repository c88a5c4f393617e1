// tracking: options of per-frame tracking (reference values: reference-behaviour §1.2, §3.2).
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace nrslam {

struct TrackingOptions {
  bool rigid = false;                 // rigid baseline: no displacement variables
  int max_points = 600;               // map points created at initialisation (strongest corners)
  int keyframe_period = 6;            // KLT reference patches are refreshed every this many frames
  int min_points = 10;                // fewer tracked 3D points: the frame is LOST
  // An image on which the KLT finds fewer than min_points of the map's tracks (the light off,
  // the lens against the tissue, a flush or a flash) is skipped with the map kept, up to this
  // many frames in a row: the next image is tracked from where the last tracked one left the
  // tracks, with the same constant-velocity seed. One more such frame is LOST. 0: lost at
  // once, as in the reference.
  int max_dropout_frames = 5;
  // ... and so is one on which it finds fewer than this fraction of them (0–1): a frame of
  // noise or garbled data, where a quarter of the tracks can lock onto chance patterns that
  // no pose fits. A tracked frame of the simulated suites keeps ≥ 89 % of them. 0: only
  // min_points decides.
  double min_tracked_fraction = 0.5;
  // A frame under that share is still used when the tracks found match well: their median
  // SSIM (after the KLT's light correction) above this, and their median gain α inside the
  // KLT's bounds. Then the view is partly hidden (an instrument, a mask) and the tracks left are
  // right; on noise the chance matches scored a median SSIM of 0.79–0.82 with α at a bound,
  // on a view 60 % hidden 0.92–0.99 (docs/data.md, "Sequence format"). 1: every such frame skipped.
  double dropout_min_match_ssim = 0.88;
  // A tracked frame whose map tracks moved more than this many times as far as over the recent
  // frames (median px, against the median of the last 10 tracked frames' medians, taken as at
  // least 1 px) is noted as a jump of the view: frames missing from the recording, or a jerk of
  // the scope. The tissue then moved as far as over several frames, more than the per-frame
  // regularisers allow, and the error rises (sim-3 from depth with 10 frames cut out: 0.65 →
  // 3.8 mm, and it stays). On the suites' renderings the ratio stays under 2.2 (from their
  // points.csv); frames cut out of sim-3 give 4.9 (5 frames) and 6.1 (10). A note only: 0 = none.
  double jump_flow_ratio = 4;
  int pose_rounds = 3;                // rigid pose-only refinement: outlier rounds ...
  int pose_iterations = 10;           // ... of this many LM iterations each
  double pose_sigma_px = 1.0;         // σ of the rigid refinement's reprojection residuals
  int deformation_rounds = 2;         // joint pose + displacement problem: outlier rounds ...
  int deformation_iterations = 10;    // ... of this many LM iterations each
  // Linear solver of that problem: "sparse_cholesky" (Eigen's simplicial LDLT, exact steps)
  // or "cgnr" (conjugate gradients, block-Jacobi preconditioned: the deformation stage ~1.35×
  // faster, but less accurate with mapping, and from depth on sim-6; docs/tracking.md).
  std::string joint_linear_solver = "sparse_cholesky";
  // Trust-region strategy of that problem: "levenberg_marquardt" (the reference) or "dogleg",
  // which re-uses a step's linear solve when the region shrinks instead of factorising again:
  // tracking 0–14 % faster, accuracy mixed over the seed renderings (docs/tracking.md).
  std::string joint_trust_region = "levenberg_marquardt";
  // At most this many points take part in the joint solve, spread over the image (one point
  // of each cell of a grid, a different one each frame); the others move with their solved
  // neighbours, as demoted points do, and stay reported while they reproject within
  // outlier_chi2. The solve's cost grows faster than its point count, and a map that keeps its
  // points in view (lap-lobes: ~460) pays most. 0: every point (the reference).
  int joint_solve_max_points = 0;
  double outlier_chi2 = 5.99;         // reprojection χ² (2 DoF, 95 %) beyond which a point is an outlier
  double displacement_iqr_factor = 1.5;  // ‖δ‖ ≥ Q3 + factor·IQR demotes a point
  // σ of a zero-mean prior on each point's displacement δ, in map-scale units (0: none, the
  // reference). Moving the camera and every δ by the same amount changes no other residual,
  // so without a prior nothing but LM damping decides how much of a common motion is the camera's.
  double displacement_prior_sigma = 0.0;
  // Start each frame's pose refinement and joint solve from the points moved by their motion of
  // the previous frame, less the mean motion of the tracked points (which the camera's
  // constant-velocity seed already carries, and which no residual can tell from it).
  // Only where the solves start changes, not what they minimise (not in the reference).
  // Measured better when tracking a map from depth (`--no-mapping`), worse with mapping,
  // where δ also carries corrections to the map (docs/tracking.md).
  bool deformation_motion_seed = false;
  // Mid-term re-association: a lost map point is looked for again by a KLT seeded at its
  // projection, with the patch of the keyframe it was last tracked from.
  bool reassociation = true;
  int reassociation_levels = 2;            // pyramid levels of that KLT (the seed is close)
  double reassociation_gate_px2 = 5.99;    // squared px between the found position and the projection
  // With k > 0, a point lost where the view was hidden (on a sudden occlusion, or under the
  // validity mask at a reference refresh) and not found within that gate is looked for again
  // over the KLT's full pyramid, and taken when its offset from its projection is within the
  // gate of the median offset of the k points found nearest it this frame. Tissue an instrument
  // hid for a few frames went on moving, as its neighbours did, and comes back tens of px from
  // where its points were left. Tracking a map from depth, it keeps sim-3 with an instrument
  // over 60 % of the view for 10 frames tracked to the end (93 of 120 frames without). Points
  // lost otherwise are not searched so: their offset more often says the map position is stale
  // (docs/tracking.md, "Tracking and the runner"). 0: the gate alone.
  int reassociation_consensus_k = 4;
  // A map point the KLT loses at least hidden_min_edge_fraction of the image's shorter side
  // inside it is taken as hidden (for the consensus above) when at least half of the k map
  // points nearest it were lost too within the last hidden_recent_frames frames: an instrument
  // sliding over the view, which no single frame shows as a sudden occlusion. Nearer the edge,
  // points are lost as the view moves on: in the unoccluded sim-3, 397 of its 401 losses over 60
  // frames were within 40 px of it (640×480), and at 42 px a colon rendering still had such
  // clusters (docs/tracking.md, "Tracking and the runner").
  int hidden_recent_frames = 5;            // frames; 0: only sudden occlusions and masks hide points
  double hidden_min_edge_fraction = 0.17;  // of the shorter side (82 px at 640×480)
  int lost_max_age_frames = 90;   // a point lost longer ago is neither moved nor looked for (bounds work)
  // When the caller hands Track the next frame's image, that frame's KLT runs on a second
  // thread while this frame's pose and deformation are solved (deformable mode only). The
  // results are the same to the last bit either way (a point's KLT depends only on its patch,
  // its guess and the image); off, tracking uses one core but for the KLT's own threads.
  bool klt_lookahead = true;
  void Check() const;
};
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(TrackingOptions, rigid, max_points, keyframe_period, min_points,
                                                max_dropout_frames, min_tracked_fraction, dropout_min_match_ssim,
                                                jump_flow_ratio,
                                                pose_rounds, pose_iterations, pose_sigma_px, deformation_rounds,
                                                deformation_iterations, joint_linear_solver, joint_trust_region,
                                                joint_solve_max_points,
                                                outlier_chi2, displacement_iqr_factor, displacement_prior_sigma,
                                                deformation_motion_seed, reassociation, reassociation_levels,
                                                reassociation_gate_px2, reassociation_consensus_k, hidden_recent_frames,
                                                hidden_min_edge_fraction, lost_max_age_frames,
                                                klt_lookahead)

}  // namespace nrslam
