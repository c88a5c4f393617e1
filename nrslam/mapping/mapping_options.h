// mapping: options of monocular initialisation, DBA and triangulation (reference values:
// reference-behaviour §3.3, §3.4). Angles given in pixels are multiplied by the camera's
// angular pixel size 1/f, so one setting fits every resolution.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace nrslam {

struct InitialisationOptions {
  int min_tracks = 100;              // fewer tracks from the reference frame: restart from this frame
  // Frames; an older reference is replaced by the current frame. The reference's 30 never let
  // the fisheye lap-lobes initialise (the camera creeps at 66–130 mm depth); 60 does, at frame
  // 58, and changes nothing that initialised within 30 (docs/mapping.md).
  int max_reference_age = 60;
  int ransac_iterations = 200;       // 8-point samples (the reference draws 16 bucketed ones)
  double epipolar_threshold_px = 2.5;  // E inlier: angle to the epipolar plane, in pixel angles (the reference's 0.005 rad at 0.002 rad/px)
  double min_parallax_px = 5;        // a point's rays must differ by this many pixel angles
  double max_reprojection_px2 = 5.991;  // in both views
  int min_points = 100;              // triangulated points needed to accept
  double max_low_parallax_fraction = 0.25;  // of the E inliers; more means the baseline is still too short
  // Once accepted, a point is kept only if its parallax is at least this many times the E
  // inliers' robust epipolar error (1.4826 · median, pixel angles), when at least min_points
  // pass. Deforming tissue moves points off their epipolar planes and along them alike, so
  // that error says how much of a small parallax is deformation. 0 = off (the reference).
  double point_min_parallax_snr = 0;
  double median_depth = 3.0;         // the map is scaled to this median depth, map units
  // Shading prior (frontend/shading.h; not in the paper or the reference): each initial point
  // is moved along its reference ray to log r = w·log r_shading + (1 − w)·log r_two_view, the
  // brightness read in the reference image. Two views a few frames apart of tissue that moves
  // as far as the camera give poor depths; the brightness does not depend on the motion. It
  // suits a tube lit from the tip and hurts where incidence and albedo vary more than distance
  // (lap-lobes) or where two views are already good (a still scene); use it with
  // mapping.rigid_warmup_min_inliers, else the rigid warm-up undoes it (docs/mapping.md).
  // 0 = off (the paper).
  double shading_weight = 0;
  // Initial DDG: "complete" joins every pair of initial points (the reference); "flow_clusters"
  // joins only points whose optical flow since the reference falls in the same DBSCAN cluster.
  std::string initial_graph = "complete";
  double dbscan_epsilon_px = 0.1;    // per flow-vector dimension (the reference's 0.1 × dimension)
  int dbscan_min_points = 10;
  void Check() const;
};
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(InitialisationOptions, min_tracks, max_reference_age, ransac_iterations,
                                                epipolar_threshold_px, min_parallax_px, max_reprojection_px2, min_points,
                                                max_low_parallax_fraction, point_min_parallax_snr, median_depth,
                                                shading_weight, initial_graph,
                                                dbscan_epsilon_px, dbscan_min_points)

struct MappingOptions {
  // Deformable Bundle Adjustment over the last keyframes (a keyframe every
  // tracking.keyframe_period frames). Gauge: the oldest keyframe's pose is held fixed; the
  // elastic rest lengths fix the scale.
  bool dba = true;
  int dba_window = 5;                // keyframes in the window (paper's N_k)
  int dba_min_keyframes = 3;         // fewer: no DBA
  int dba_iterations = 5;            // LM iterations
  // Frames the DBA of a keyframe may run beside tracking before its result is applied (on
  // the keyframe + this many frames, or on the next keyframe if sooner). 0: at once, on the
  // keyframe, as the reference. The result is always applied on that same frame, whatever
  // the timing, so runs stay repeatable; tracking's motion since the keyframe is kept.
  int dba_lag_frames = 0;
  // The first keyframes of a two-view map are adjusted rigidly and their shape becomes the
  // DDG's rest shape: the map's depths get corrected by the growing baseline before the
  // per-keyframe shapes can absorb their error (counting the initial two). A map from depth
  // is left alone (warming it up made depth-initialised runs worse). 0 = off (the
  // reference); 4 measured best of 0, 4, 6, 8, 12 on the suite (docs/mapping.md).
  int rigid_warmup_keyframes = 4;
  // The warm-up's rigid result is kept only when at least this fraction of the window's
  // observations reprojects within max_reprojection_px2; otherwise the window gets the
  // deformable DBA. With the shading prior (initialisation.shading_weight) the two-view depths
  // are no longer the map's, and an unconditional warm-up would bring them back; 0.99 keeps it
  // in still scenes (fractions ≥ 0.999 measured) and not in deforming ones (0.30–0.986).
  // 0 = always kept (as without the prior).
  double rigid_warmup_min_inliers = 0;
  // Model selection for the DBA (not in the reference; the paper selects models only for new
  // points): after the warm-up, a window is first adjusted rigidly, and that result is kept
  // (and becomes the DDG's rest shape) when the camera travelled far enough over the window
  // and nearly every observation reprojects within max_reprojection_px2. Otherwise the
  // window gets the deformable DBA. Without it a still scene drifts: the per-keyframe shapes
  // absorb the noise that a rigid adjustment averages out.
  bool dba_model_selection = true;
  double rigid_dba_min_inliers = 0.95;  // fraction of the window's observations
  double rigid_dba_min_baseline = 0.2;  // camera travel over the window / median depth
  // ... and, on a map from depth, when tracking saw the window's frames as still: the median
  // over the buffered frames since the window's oldest keyframe of each frame's median ‖δ‖,
  // at most this × map scale (rigidity_threshold's units). The inlier test is in pixels, so a
  // deformation of a given size passes it the more easily the coarser the image; δ is
  // measured in 3D. At 320×240 without it, rigid windows took deforming sim-1 and sim-3 maps
  // from 0.9 / 1.6 to 4.9 / 5.6 mm. Not for two-view maps: there δ also carry corrections of
  // the map's depths (a still scene's reached 0.0030, against at most 0.0015 from depth), and
  // over 42 monocular renderings the test was better on 3 and worse on 5 (docs/mapping.md).
  // 0 = no such test.
  double rigid_dba_max_deformation = 0.004;
  // New points from 2D tracks (corners detected at keyframes) over the last frames.
  int temporal_window = 20;          // frames of track history kept
  double crowding_radius_px = 20;    // no new point this close to a tracked 3D point
  double neighbour_radius_px = 500;  // its neighbours: tracked 3D points within this radius ...
  int neighbours = 10;               // ... at most this many, nearest first
  double max_depth_ratio = 1.25;     // a new point's depth within [nearest/r, r·farthest] of its neighbours'
  // Not in the reference: a frame's new points (the set model selection chose), when there
  // are at least batch_check_min_points of them, are all turned away when the median of their
  // depth over their neighbours' mean depth, in that frame, is outside [1/b, b]; 0 = no such
  // check. The per-point bound above lets a whole batch lean to one side of the map; a median
  // of fewer points is their own noise more than a shared lean. Measured (docs/mapping.md,
  // "Batch depth check"): monocular lap-lobes with its focal length 5 % off 10.15 → 4.51 mm.
  double max_batch_depth_bias = 1.25;
  int batch_check_min_points = 10;
  double rigidity_threshold = 0.004; // rigid triangulation needs median ‖δ‖ ≤ this × map scale in every spanned frame
  double rigid_min_parallax_px = 10; // rigid triangulation: parallax window, in pixel angles
  double rigid_max_parallax_px = 20;
  double max_reprojection_px2 = 5.991;  // rigid (both views) and deformable gate
  // Deformable triangulation and the paper's model selection between it and rigid
  // triangulation. Without it a deforming scene gets almost no new points (the rigidity
  // gate) and is lost once the camera leaves the initial map; with it the map keeps growing,
  // at a cost in accuracy over short runs (docs/mapping.md).
  bool deformable_triangulation = true;
  // Deformable triangulation's plausibility gate: the rigid two-ray midpoint must reproject
  // within max_reprojection_px2 in both views, with deformable_min_parallax_px between them.
  // "oldest": the track's oldest and newest observations (the reference); "shortest": the
  // newest and the latest earlier one that gives that parallax. Over the oldest span (up to
  // temporal_window frames) a deforming surface moves enough for the rays to miss: in the
  // 300-frame sim-3 run's point dip, 330 of ~400 candidates per frame failed the gate there.
  std::string deformable_gate_span = "oldest";
  // ... except on frames that track fewer than this fraction of the points a monocular map
  // started with, where the shortest span is used whatever deformable_gate_span says (0:
  // never). A starving map needs new points more than it needs the stricter gate. A fraction
  // rather than a count, so that it holds at any image size. Not for maps from depth: they
  // start accurate, and the looser gate's points cost them more than they add (measured in
  // docs/mapping.md).
  double shortest_gate_below_fraction = 0.35;
  // On those frames, whether the gate's two rays must also reproject within
  // max_reprojection_px2. Even over the shortest span the tissue moves about as far as the
  // camera, so in the 300-frame sim-3 run's dip 100-290 candidates per frame still failed it
  // and 5 late frames tracked fewer than 100 points. false (default): parallax and positive
  // depths only; the deformable fit's own outlier checks and max_depth_ratio remain.
  bool starving_two_ray_check = false;
  int deformable_min_track = 5;      // deformable triangulation needs this many observations
  // A deformable point is kept only if its depth in the newest frame is within this ratio of
  // the gate's two-ray depth: two estimates from different models that agree. Where they do
  // not, the fit's depth along a low-parallax ray is mostly its seed, the neighbours' depth.
  // Not on starving frames (shortest_gate_below_fraction): there the map needs points more.
  // 0 = off (the reference). 1.25 measured better than off on 18 of 21 colon renderings and
  // 5 of 6 lap-lobes renderings (docs/mapping.md).
  double deformable_agreement_ratio = 1.25;
  // A deformable candidate is fitted only if its track's rays stay near their epipolar planes
  // with its oldest ray: their rms angle to those planes, over the oldest-to-newest parallax,
  // at most this. A rigid point's rays lie on those planes; what the tissue moves a track
  // across them it also moves it along them, and that false parallax puts the point too near
  // (down the lumen of monocular sim-3, 2-4x too near). 0 = off (the reference). 0.15
  // measured better than off on 16 of 21 colon renderings and 6 of 6 lap-lobes renderings.
  double deformable_max_epipolar_ratio = 0.15;
  // The same on starving frames (shortest_gate_below_fraction), looser because the map needs
  // points there: at 0 (no check) the points those frames made undid most of the gain; at the
  // main ratio (0.1 or 0.15) or 0.2 the 300-frame sim-3 run had 6-99 frames under 100 tracked
  // points after frame 30, at 0.3 none (docs/mapping.md).
  double starving_max_epipolar_ratio = 0.3;
  double deformable_min_parallax_px = 5;
  double flow_sigma = 0.1;           // σ of the neighbour-flow residual, × map scale
  int deformable_iterations = 10;
  // The fit stops when an iteration lowers its cost by less than this fraction (Ceres's
  // function_tolerance; 1e-6 is its default). Along a ray with little parallax the cost is
  // nearly flat, so the fit stops a few steps from its seed: at 1e-14 the new points' depths
  // follow their tracks more, but 14 of the 21 colon renderings came out worse and a
  // 1000-frame run from depth lost its track (docs/mapping.md, "Long runs").
  double deformable_function_tolerance = 1e-6;
  double flow_outlier_chi2 = 7.815;  // reject if more than half the flow residuals exceed it ...
  double reprojection_outlier_chi2 = 59.9;  // ... or more than half the reprojections exceed this
  double model_selection_factor = 1.5;  // keep a model's points only if it found this many times more
  // Shading prior for new points (frontend/shading.h; not in the paper or the reference): the
  // points of deformable triangulation, whose depth along a short-baseline ray is weak, are moved
  // along their ray to log r = w·log r_shading + (1 − w)·log r, the brightness calibrated on the
  // frame's tracked points. Rigid triangulation passed its rigidity and parallax gates and is
  // left alone. At 1 it holds a deforming colon's map scale over 1000 frames, where without it
  // the scale collapses; it costs the still scene and lap-lobes (docs/mapping.md, "Long runs").
  // 0 = off (the paper).
  double new_point_shading_weight = 0;
  void Check() const;
};
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(MappingOptions, dba, dba_window, dba_min_keyframes, dba_iterations,
                                                dba_lag_frames,
                                                rigid_warmup_keyframes, rigid_warmup_min_inliers, dba_model_selection, rigid_dba_min_inliers, rigid_dba_min_baseline,
                                                rigid_dba_max_deformation,
                                                temporal_window, crowding_radius_px, neighbour_radius_px, neighbours,
                                                max_depth_ratio, max_batch_depth_bias, batch_check_min_points, rigidity_threshold, rigid_min_parallax_px, rigid_max_parallax_px,
                                                max_reprojection_px2, deformable_triangulation, deformable_gate_span,
                                                shortest_gate_below_fraction, starving_two_ray_check, deformable_min_track,
                                                deformable_agreement_ratio, deformable_max_epipolar_ratio, starving_max_epipolar_ratio, deformable_min_parallax_px,
                                                flow_sigma, deformable_iterations, deformable_function_tolerance, flow_outlier_chi2,
                                                reprojection_outlier_chi2, model_selection_factor, new_point_shading_weight)

}  // namespace nrslam
