// tracking: per-frame deformable tracking of the camera and the map (paper §"Deformable
// Tracking"; reference-behaviour §1.2).
//
// Each frame: KLT against the keyframe's reference patches → constant-velocity pose seed →
// rigid pose-only refinement with outlier rounds → (unless rigid) the joint problem of the
// pose and one displacement δ per point, with reprojection, elastic and viscous terms over
// the DDG's best edges → demotion of outliers (‖δ‖ beyond the IQR fence, large reprojection
// error) → graph update and pruning. Too few points left is the LOST state, a recorded
// outcome, never an exit.
#pragma once

#include <opencv2/core.hpp>

#include <memory>
#include <string>
#include <vector>

#include "nrslam/camera/camera.h"
#include "nrslam/frontend/frontend_options.h"
#include "nrslam/frontend/klt_tracker.h"
#include "nrslam/geometry/rigid3.h"
#include "nrslam/map/map.h"
#include "nrslam/tracking/tracking_options.h"

namespace nrslam {

enum class TrackingState { kNotInitialised, kTracking, kLost };
const char* ToString(TrackingState state);

struct TrackedPoint {
  PointId id;
  cv::Point2f pixel;  // where the KLT found it this frame
};

struct FrameResult {
  int frame = 0;
  TrackingState state = TrackingState::kNotInitialised;
  Rigid3 cam_from_world;
  std::vector<TrackedPoint> points;  // 3D points tracked and kept this frame
  int klt_tracked = 0;               // tracks the KLT kept
  int outliers = 0;                  // demoted by the optimisation this frame
  double ms_klt = 0, ms_pose = 0, ms_deformation = 0, ms_total = 0;
  std::string note;                  // why a frame is not tracked
};

class Tracker {
 public:
  Tracker(const Camera& camera, const FrontendOptions& frontend, const DeformationModelOptions& deformation,
          const TrackingOptions& tracking);

  // Builds the map from a depth map (mm) of this frame: corners in the valid area, lifted to
  // 3D, joined in a complete graph; σ = sigma_factor · std(depth). The frame's pose is the world.
  FrameResult InitialiseFromDepth(int frame, const cv::Mat& bgr, const cv::Mat& depth_mm, const cv::Mat& mask);
  FrameResult Track(int frame, const cv::Mat& bgr, const cv::Mat& mask);

  TrackingState state() const { return state_; }
  const Map& map() const { return *map_; }

 private:
  struct PointTrack {
    PointId id;
    cv::Point2f pixel;
    bool active;
  };
  struct Observation {
    size_t track;   // index into tracks_
    PointId id;
    Eigen::Vector2d pixel;
  };

  Camera camera_;
  FrontendOptions frontend_;
  DeformationModelOptions deformation_;
  TrackingOptions options_;
  std::unique_ptr<Map> map_;
  KltTracker klt_;
  std::vector<PointTrack> tracks_;  // aligned with the KLT's reference points
  TrackingState state_ = TrackingState::kNotInitialised;
  Rigid3 cam_from_world_;
  Rigid3 motion_;  // last frame-to-frame motion, for the constant-velocity seed
  int frames_since_keyframe_ = 0;

  void RefreshReference(const cv::Mat& grey, const cv::Mat& mask);
  // Rigid pose-only refinement; returns the per-observation inlier flags of the last round.
  std::vector<bool> RefinePose(const std::vector<Observation>& observations, Rigid3* pose) const;
  // The joint pose + displacement problem; fills displacements and inlier flags.
  void SolveDeformation(const std::vector<Observation>& observations, Rigid3* pose,
                        std::vector<Eigen::Vector3d>* displacements, std::vector<bool>* inliers) const;
  FrameResult Lost(FrameResult result, const std::string& why);
};

}  // namespace nrslam
