// tracking: per-frame deformable tracking of the camera and the map (paper §"Deformable
// Tracking"; reference-behaviour §1.2).
//
// Each frame: KLT against the keyframe's reference patches → constant-velocity pose seed →
// rigid pose-only refinement with outlier rounds → (unless rigid) the joint problem of the
// pose and one displacement δ per point, with reprojection, elastic and viscous terms over
// the DDG's best edges → demotion of outliers (‖δ‖ beyond the IQR fence, large reprojection
// error) → graph update and pruning → the optimised motion propagated to lost and demoted
// neighbours → mid-term re-association of lost points by a KLT seeded at their projection.
// Too few points left is the LOST state, a recorded outcome, never an exit; an image on which
// the KLT finds too few of them is first skipped as a dropout, a few frames in a row at most.
#pragma once

#include <opencv2/core.hpp>

#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "nrslam/camera/camera.h"
#include "nrslam/frontend/frontend_options.h"
#include "nrslam/frontend/klt_tracker.h"
#include "nrslam/geometry/rigid3.h"
#include "nrslam/map/map.h"
#include "nrslam/tracking/image_dropouts.h"
#include "nrslam/tracking/tracking_options.h"

namespace nrslam {

enum class TrackingState { kNotInitialised, kTracking, kLost };
const char* ToString(TrackingState state);

struct TrackedPoint {
  PointId id;
  cv::Point2f pixel;          // where the KLT found it this frame
  bool reassociated = false;  // found again this frame by mid-term re-association
};

// A 2D track with no 3D point yet: a candidate for triangulation (mapping).
struct CandidateObservation {
  int track_id;
  cv::Point2f pixel;
};

struct FrameResult {
  int frame = 0;
  TrackingState state = TrackingState::kNotInitialised;
  Rigid3 cam_from_world;
  std::vector<TrackedPoint> points;  // 3D points tracked and kept this frame
  std::vector<CandidateObservation> candidates;  // 2D-only tracks followed this frame
  bool keyframe = false;             // reference patches were refreshed on this frame
  double median_displacement = 0;    // median ‖δ‖ of the optimised points, map units (0 when rigid)
  int klt_tracked = 0;               // tracks the KLT kept
  int outliers = 0;                  // demoted by the optimisation this frame
  int propagated = 0;                // lost or demoted points moved with their neighbours
  int reassociated = 0;              // lost points found again
  double ms_klt = 0, ms_pose = 0, ms_deformation = 0, ms_total = 0;
  // Time spent ahead on this frame's image (grey, pyramid, KLT) during the previous frame's
  // solve, on another thread: not in ms_klt nor ms_total (this frame's own wall-clock).
  double ms_klt_ahead = 0;
  // Inside ms_deformation: Ceres's time in the joint solves (all rounds), and the part of it
  // spent in the linear solver (factorising or CG), which is where deformable tracking's time goes.
  double ms_joint_solve = 0, ms_linear_solve = 0;
  std::string note;                  // why a frame is not tracked, or what was unusual about a tracked one
  // Not tracked, as an image dropout: the tracker kept its map and tracks and will try the next
  // frame (TrackingOptions::max_dropout_frames); state() is still kTracking.
  bool dropout = false;
  // Tracked although most of the map's tracks vanished at once, because those left matched well
  // (ImageDropouts::SuddenOcclusion).
  bool sudden_occlusion = false;
  // Tracked although its tracks moved far more than over the recent frames
  // (TrackingOptions::jump_flow_ratio): frames missing, or a jerk of the scope.
  bool view_jump = false;
};

// `motions` less their mean: the part of the points' motion the camera cannot take over. The
// start of a frame's displacements when `deformation_motion_seed` is on (the camera's
// constant-velocity seed already carries the common part).
std::vector<Eigen::Vector3d> WithoutCommonMotion(std::vector<Eigen::Vector3d> motions);

// The map a tracker starts from: 3D points (world) seen at pixels of the start frame.
struct MapSeed {
  Rigid3 cam_from_world;             // the start frame's camera
  std::vector<cv::Point2f> pixels;
  std::vector<Eigen::Vector3d> points;
  std::vector<int> groups;           // graph groups: edges join points of one group (empty = one group)
  double scale = 1.0;                // Map::scale
  double depth_deviation = 0.0;      // std of the points' depths, map units: σ = sigma_factor · this
};

class Tracker {
 public:
  Tracker(const Camera& camera, const FrontendOptions& frontend, const DeformationModelOptions& deformation,
          const TrackingOptions& tracking);

  // Builds the map from a depth map (mm) of this frame: corners in the valid area, lifted to
  // 3D, joined in a complete graph; σ = sigma_factor · std(depth). The frame's pose is the world.
  FrameResult InitialiseFromDepth(int frame, const cv::Mat& bgr, const cv::Mat& depth_mm, const cv::Mat& mask);
  // Starts a new map from `seed` (e.g. a monocular initialisation) on this frame. Seed point
  // i becomes map point i.
  FrameResult InitialiseFromSeed(int frame, const cv::Mat& bgr, const cv::Mat& mask, const MapSeed& seed);
  // Tracks this frame. `next_bgr`, when the caller already has it, is the next frame's image:
  // with `klt_lookahead` its KLT then runs beside this frame's solve, and the next Track uses
  // those results if it is given the same image (compared by content) and the reference
  // patches are still the same; tracks re-associated meanwhile are tracked then. Results never
  // depend on whether it is given.
  FrameResult Track(int frame, const cv::Mat& bgr, const cv::Mat& mask, const cv::Mat& next_bgr = {});

  // With candidates on, each keyframe adds new corners as 2D tracks for mapping to triangulate.
  void EnableCandidates(bool on) { candidates_ = on; }
  // The 2D track `track_id` now observes map point `id` (just triangulated).
  void PromoteCandidate(int track_id, PointId id);
  // Mapping's refined estimate of the current camera (e.g. after DBA).
  void SetPose(const Rigid3& cam_from_world) { cam_from_world_ = cam_from_world; }
  // Retires in the graph every map point that neither this tracker (tracked or lost and
  // looked for) nor the caller (`in_use`, e.g. the DBA window) will read again: none of them
  // can come back, so their edges among themselves can go (DeformationGraph::Retire).
  void RetireDroppedPoints(std::vector<PointId> in_use);

  TrackingState state() const { return state_; }
  const Rigid3& pose() const { return cam_from_world_; }
  const Map& map() const { return *map_; }
  Map& mutable_map() { return *map_; }

 private:
  // Where a track's KLT reference patch was cut: a keyframe and the point's pixel there.
  struct PatchSource {
    std::shared_ptr<const ImagePyramid> keyframe;
    cv::Point2f pixel;
  };
  struct PointTrack {
    PointId id;        // kNoPoint for a candidate (2D only)
    int track_id;
    cv::Point2f pixel;
    bool active;
    PatchSource patch;
  };
  struct LostPoint {
    PatchSource patch;
    int lost_frame;
    cv::Point2f pixel;  // where the KLT last looked for it (or, at a refresh, last found it)
    // Lost where the view was hidden: on a sudden occlusion, together with its neighbours well
    // inside the view (MarkHiddenLosses), or under the validity mask (where the KLT lost it, or
    // at a reference refresh). The tissue under it may go on moving, so the point can come back
    // far from where the map expects it (TrackingOptions::reassociation_consensus_k).
    bool hidden;
  };
  // A lost point the re-association's KLT found: where its map position projects, and where
  // the KLT found it.
  struct FoundAgain {
    PointId id;
    cv::Point2f projection, pixel;
  };
  struct Observation {
    size_t track;   // index into tracks_
    PointId id;
    Eigen::Vector2d pixel;
  };
  // The next frame's KLT, run ahead from the tracks as they were after this frame's KLT.
  struct Lookahead {
    cv::Mat grey;                        // the image it ran on
    std::shared_ptr<const ImagePyramid> pyramid;
    std::vector<KltResult> matches;      // per track index, for the tracks there were then
    int reference_generation = 0;        // the KLT reference it tracked against
    double ms = 0;
  };

  Camera camera_;
  FrontendOptions frontend_;
  DeformationModelOptions deformation_;
  TrackingOptions options_;
  std::unique_ptr<Map> map_;
  KltTracker klt_;
  std::vector<PointTrack> tracks_;  // aligned with the KLT's reference points
  std::unordered_map<PointId, LostPoint> lost_;  // moved with their neighbours; may be found again
  std::vector<PointId> lost_now_;  // map points the KLT lost on this frame (re-filled every frame)
  // MarkHiddenLosses's buffers: the map points around (pixel, lost lately) and, for one point,
  // their squared distances to it.
  std::vector<std::pair<cv::Point2f, bool>> around_;
  std::vector<std::pair<float, bool>> nearest_;
  // MovedWithItsNeighbours's buffers, re-filled for every point it is asked about.
  std::vector<std::pair<float, cv::Point2f>> consensus_;
  std::vector<float> offsets_x_, offsets_y_;
  TrackingState state_ = TrackingState::kNotInitialised;
  Rigid3 cam_from_world_;
  Rigid3 motion_;  // last frame-to-frame motion, for the constant-velocity seed
  ImageDropouts dropouts_{options_};
  std::vector<ImageDropouts::LiveTrack> map_tracks_;  // the dropout rule's input, re-filled every frame
  // How far each map track moved this frame (re-filled every frame; NoteViewJump then re-uses it).
  std::vector<double> flows_px_;
  std::deque<double> recent_flows_px_;     // the median of flows_px_ over the last tracked frames
  // By point id: how far the last frame's tracking moved it (with deformation_motion_seed;
  // during the deformation stage, where each point started).
  std::vector<Eigen::Vector3d> point_motion_;
  int frames_since_keyframe_ = 0;
  bool candidates_ = false;
  int next_track_id_ = 0;
  int reference_generation_ = 0;  // counts SetReference calls: a look-ahead from an older one is void
  std::optional<Lookahead> lookahead_;

  // Cuts new reference patches in `keyframe`; `valid` is its validity mask. With candidates
  // on and a grey image given, new corners away from every track join as candidates.
  void RefreshReference(int frame, std::shared_ptr<const ImagePyramid> keyframe, const cv::Mat& valid,
                        const cv::Mat& grey = {});
  // Where the KLT starts each track in the next image: its last pixel, NaN when inactive.
  std::vector<cv::Point2f> KltGuesses() const;
  // The short-term KLT of every track into `pyramid` from `guesses`, re-using the results of
  // a look-ahead (run against the current reference) for the tracks it ran.
  void MatchTracks(const ImagePyramid& pyramid, const std::vector<cv::Point2f>& guesses, const Lookahead* ahead,
                   std::vector<KltResult>* matches) const;
  // What the pose and deformation stage leaves for the rest of the frame.
  struct FrameSolution {
    Rigid3 pose;
    std::vector<bool> inliers, demoted;  // per observation
  };
  // Constant-velocity seed and rigid refinement of the pose, then (unless rigid) the joint
  // solve, demotion of outliers, graph update and propagation to lost and demoted points.
  // Drops the observations the seed puts behind the camera; returns why the frame is lost.
  std::optional<std::string> SolvePoseAndDeformation(std::vector<Observation>* observations_in_view,
                                                     FrameSolution* solution, FrameResult* result);
  // The next frame's KLT from the tracks as they are now (run beside this frame's solve).
  Lookahead RunAhead(const cv::Mat& next_bgr, const std::vector<cv::Point2f>& guesses, int reference_generation) const;
  // Stops tracking a point; unless the graph has cut it loose (or it is a candidate) it is kept
  // among the lost points, which may be found again later: whether it was.
  bool LoseTrack(PointTrack* track, int frame, bool hidden);
  // How far from the image's edge a pixel must be for a whole KLT window around it to fit.
  double WindowMargin() const { return frontend_.klt.window_px / 2 + 1; }
  // Whether `pixel`, far enough inside the image for a KLT window (not in its border), is
  // invalid in `valid`: under the sequence's mask or a highlight.
  bool UnderMask(const cv::Mat& valid, const cv::Point2f& pixel) const;
  // Marks as hidden each map point the KLT lost on this frame well inside the image
  // (hidden_min_edge_fraction) when at least half of the reassociation_consensus_k map points
  // nearest it were lost too within the last hidden_recent_frames frames: something came over
  // that part of the view (an instrument sliding in). A point lost alone, or at the image's
  // edge as the view moves on, is not marked.
  void MarkHiddenLosses(int frame);
  // The inlier test of every solve: `world` reprojects within outlier_chi2 of `observed`, its
  // residual whitened by `sigma_px` (infinite, so not, when it does not project).
  bool ReprojectsWithinChi2(const Rigid3& cam_from_world, const Eigen::Vector3d& world,
                            const Eigen::Vector2d& observed, double sigma_px) const;
  // Rigid pose-only refinement; returns the per-observation inlier flags of the last round.
  // Each point is moved by its `start` δ (one per observation) before the fit.
  std::vector<bool> RefinePose(const std::vector<Observation>& observations, const std::vector<Eigen::Vector3d>& start,
                               Rigid3* pose) const;
  // Ceres's time in the joint solves of one frame, all rounds.
  struct JointSolveTimes {
    double ms_total = 0, ms_linear = 0;
  };
  // The joint pose + displacement problem; fills displacements and inlier flags. Every round
  // starts from the given pose and `start` (one δ per observation).
  JointSolveTimes SolveDeformation(const std::vector<Observation>& observations,
                                   const std::vector<Eigen::Vector3d>& start, Rigid3* pose,
                                   std::vector<Eigen::Vector3d>* displacements, std::vector<bool>* inliers) const;
  // The observations that take part in the joint solve (indices, ascending): all of them, or
  // with joint_solve_max_points a subset spread over the image, one point of each cell of a
  // grid, taken in turn over the frames between keyframes.
  std::vector<size_t> JointSolveSubset(const std::vector<Observation>& observations) const;
  // Moves each lost point and each of `demoted` (demoted, or left out of the joint solve) by the
  // weighted mean displacement (weights b²) of its best optimised neighbours: the minimiser of
  // its viscous terms with the neighbours held fixed. `optimised` is indexed by point id
  // (nullopt: not optimised this frame).
  int PropagateMotion(const std::vector<std::optional<Eigen::Vector3d>>& optimised,
                      const std::vector<PointId>& demoted);
  // Drops lost points that are too old or that the graph has cut loose.
  void ForgetLostPoints(int frame);
  // Looks for lost points near their projection; found ones become tracks again.
  void Reassociate(const ImagePyramid& pyramid, const cv::Mat& valid, FrameResult* result);
  // Whether `point` (one of `far`, found beyond the gate of its projection) is within the gate
  // of the median offset of the reassociation_consensus_k others found nearest it this frame,
  // within the gate (`near`) or beyond it (`far`).
  bool MovedWithItsNeighbours(const FoundAgain& point, const std::vector<FoundAgain>& near,
                              const std::vector<FoundAgain>& far);
  // Notes on `result` a frame whose map tracks moved far more than over the recent frames
  // (flows_px_, TrackingOptions::jump_flow_ratio), and adds its median flow to the recent ones.
  void NoteViewJump(FrameResult* result);
  FrameResult Lost(FrameResult result, const std::string& why);
};

}  // namespace nrslam
