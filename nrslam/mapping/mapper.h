// mapping: what runs after tracking on each tracked frame (reference-behaviour §1.3, §1.4).
//
// Every frame leaves a snapshot in a temporal buffer (pose, median deformation, each tracked
// 3D point's pixel and world position, each candidate 2D track's pixel). On a keyframe the
// keyframe is stored and the DBA runs over the window (rigidly when one shape fits it:
// MappingOptions::dba_model_selection); its newest shape and pose go back to tracking. On other frames candidates are triangulated, rigidly and deformably, and the
// paper's model selection keeps one set: the rigid points if there are more than
// model_selection_factor × as many as deformable ones, the deformable points if there are at
// least that many times more, else none. A kept set that leans off the map as a whole (its
// median depth against its points' neighbours: max_batch_depth_bias) is turned away. New
// points join the DDG, connected to every point tracked this frame, and their 2D tracks
// become 3D tracks.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <deque>
#include <future>
#include <optional>
#include <unordered_map>
#include <utility>
#include <vector>

#include "nrslam/camera/camera.h"
#include "nrslam/deformation/deformation_options.h"
#include "nrslam/frontend/frontend_options.h"
#include "nrslam/geometry/two_view.h"
#include "nrslam/mapping/deformable_ba.h"
#include "nrslam/mapping/mapping_options.h"
#include "nrslam/tracking/tracker.h"

namespace nrslam {

struct MappingReport {
  bool dba = false;
  DbaReport dba_report;
  int rigid_candidates = 0, deformable_candidates = 0;  // triangulations that passed their checks
  int new_points = 0;                                   // added this frame (after model selection)
  // The chosen points' median depth over their neighbours' mean depth, in this frame (0: none
  // chosen), and whether mapping.max_batch_depth_bias turned them all away.
  double new_point_depth_bias = 0;
  bool batch_rejected = false;
  double ms_dba = 0, ms_triangulation = 0;
};

class Mapper {
 public:
  // `frontend`: the validity masks and brightness reading of the shading prior.
  Mapper(const Camera& camera, const FrontendOptions& frontend, const DeformationModelOptions& deformation,
         const MappingOptions& options, bool rigid);

  // A new map was started on `start` (the tracker's first frame); `reference`, when given, is
  // the initialisation's other view (its pixels aligned with the map's first points).
  void StartMap(const FrameResult& start, const Tracker& tracker, const std::optional<Keyframe>& reference);
  // After a tracked frame; may change the tracker's map and pose. `mask`: the sequence's mask
  // of the frame (may be empty).
  MappingReport Process(const FrameResult& result, const cv::Mat& bgr, const cv::Mat& mask, Tracker* tracker);

  const std::deque<Keyframe>& keyframes() const { return keyframes_; }
  // The points the DBA window observes (a DBA in flight adjusts the same window).
  std::vector<PointId> WindowPoints() const;

 private:
  struct Snapshot {
    int frame = 0;
    Rigid3 cam_from_world;
    double median_displacement = 0;
    std::unordered_map<PointId, std::pair<cv::Point2f, Eigen::Vector3d>> points;  // pixel, world
    std::unordered_map<int, cv::Point2f> candidates;                                // track id → pixel
  };
  // One candidate track's observations in the buffer, oldest first.
  struct CandidateTrack {
    std::vector<const Snapshot*> frames;
    std::vector<Eigen::Vector2d> pixels;
  };

  Camera camera_;
  FrontendOptions frontend_;
  DeformationModelOptions deformation_;
  MappingOptions options_;
  bool rigid_;
  std::deque<Snapshot> buffer_;
  std::deque<Keyframe> keyframes_;
  int map_keyframes_ = 0;  // keyframes made since the map started
  bool two_view_map_ = false;  // the map came from monocular initialisation (not from depth)
  int start_points_ = 0;       // 3D points the map started with

  // A DBA in flight: the window it adjusts (its own copy) and what the newest keyframe was
  // before, so that tracking's motion since then can be kept when the result is applied.
  struct AdjustedWindow {
    std::deque<Keyframe> keyframes;
    DbaReport report;
  };
  struct PendingDba {
    int keyframe_frame = 0, apply_frame = 0;
    Keyframe newest_before;
    std::future<AdjustedWindow> adjusted;
  };
  std::optional<PendingDba> pending_dba_;

  void Record(const FrameResult& result, const Tracker& tracker);
  Keyframe MakeKeyframe(const FrameResult& result, const Tracker& tracker) const;
  // Starts the DBA of the window that ends on this keyframe (on another thread when
  // dba_lag_frames > 0), and applies it at once when the lag is 0.
  void StartDba(int frame, Tracker* tracker, MappingReport* report);
  // Waits for the pending DBA and applies it: keyframe poses and shapes, the map, the buffer
  // and the tracker's pose.
  void FinishDba(int frame, Tracker* tracker, MappingReport* report);
  // How a window is adjusted: rigidly (a rigid map, or the warm-up), rigidly if that fits
  // well enough (a gated warm-up: mapping.rigid_warmup_min_inliers), or by model selection.
  enum class WindowModel { kRigid, kRigidIfInliers, kSelected };
  // The DBA proper (rigid trial, model selection, deformable adjustment); reads only its
  // arguments and constant members, so it can run beside tracking.
  // `tracked_deformation`: TrackedDeformation of the window, or -1 for no such test.
  AdjustedWindow AdjustWindow(std::deque<Keyframe> keyframes, const DbaRegularisers& regularisers, double map_scale,
                              WindowModel model, double tracked_deformation) const;
  // Of every (keyframe, point) observation, the fraction reprojecting within max_reprojection_px2.
  double InlierFraction(const std::deque<Keyframe>& keyframes) const;
  // Camera travel from the oldest to the newest keyframe over the newest one's median depth.
  double BaselineRatio(const std::deque<Keyframe>& keyframes) const;
  // How much tracking deformed the map since `since_frame`: the median over the buffered
  // frames from then on of each frame's median ‖δ‖, over `map_scale`; -1 with no such frame.
  double TrackedDeformation(int since_frame, double map_scale) const;
  void Triangulate(const FrameResult& result, const cv::Mat& bgr, const cv::Mat& mask, Tracker* tracker,
                   MappingReport* report);
  // The shading prior on new points (mapping.new_point_shading_weight): `points` (track id,
  // world position) moved along their rays in this frame (the newest snapshot).
  void ApplyShadingPrior(const cv::Mat& bgr, const cv::Mat& mask,
                         const std::unordered_map<int, cv::Point2f>& pixels,
                         std::vector<std::pair<int, Eigen::Vector3d>>* points) const;
  // One candidate's rigid and deformable points (either may be missing); reads only the
  // buffer and the options, so candidates can be triangulated side by side.
  struct CandidatePoints {
    std::optional<Eigen::Vector3d> rigid, deformable;
    double neighbour_depth = 0;  // its neighbours' mean depth in the newest frame
  };
  // A frame's deformable-triangulation gate: over which span (mapping.deformable_gate_span, or
  // the shortest on a starving frame) and whether its two rays must reproject.
  struct DeformableGate {
    bool shortest_span = false;
    bool check_reprojection = true;
    double agreement_ratio = 0;  // this frame's mapping.deformable_agreement_ratio; 0 = no check
    double max_epipolar_ratio = 0;  // this frame's mapping.deformable_max_epipolar_ratio; 0 = no check
  };
  CandidatePoints TriangulateCandidate(const CandidateObservation& candidate, const DeformableGate& gate,
                                       double map_scale) const;
  // Observation i's viewing ray, in the world frame.
  Eigen::Vector3d WorldRay(const CandidateTrack& track, size_t i) const;
  // The rms angle of the track's later rays to their epipolar planes with its oldest ray, over
  // the angle between its oldest and newest rays (infinite without parallax).
  double EpipolarDeviationRatio(const CandidateTrack& track) const;
  // The rays of observations a and b met in the middle, if both lie in front and (when
  // check_reprojection) it reprojects within max_reprojection_px2 in both views. Over the
  // first and last observations: the rigid answer, and the deformable triangulation's
  // reference gate.
  std::optional<Triangulated> TriangulatePair(const CandidateTrack& track, size_t a, size_t b,
                                              bool check_reprojection = true) const;
  // The same over the newest observation and the latest earlier one with
  // deformable_min_parallax_px of parallax (mapping.deformable_gate_span=shortest, and on
  // frames below mapping.shortest_gate_below_fraction of a monocular map's first points).
  std::optional<Triangulated> TriangulateShortestSpan(const CandidateTrack& track, bool check_reprojection) const;
  std::optional<Eigen::Vector3d> TriangulateRigid(const CandidateTrack& track, const std::optional<Triangulated>& ends,
                                                  double map_scale) const;
  std::optional<Eigen::Vector3d> TriangulateDeformable(const CandidateTrack& track,
                                                       const std::optional<Triangulated>& gate,
                                                       const std::vector<PointId>& neighbours, double map_scale) const;
};

}  // namespace nrslam
