// mapping: monocular map initialisation (paper §"Monocular Map Initialization";
// reference-behaviour §1.5, with its bugs fixed).
//
// Corners of a reference frame are tracked by KLT into each new frame. Each frame the
// essential matrix between the reference and the current bearings is estimated (RANSAC over
// 8-point samples on unit rays, so fisheye works) and decomposed (all four solutions tested
// for cheirality, not the reference's small-rotation guess). Its inliers are triangulated by
// inverse-depth weighted mid-point; the map is accepted once enough points pass the
// parallax, depth and reprojection gates and few inliers still lack parallax. The map is then
// scaled to the target median depth. The reference restarts when its tracks run out or it ages.
// An image dropout (a frame on which the KLT finds under tracking.min_tracked_fraction of the
// live tracks: blank, noise) is skipped as tracking skips one, up to max_dropout_frames in a row,
// rather than cutting the tracks or becoming the reference.
// With initialisation.shading_weight > 0 the points' distances are blended with what the
// reference image's brightness says (frontend/shading.h) before the map is scaled.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <memory>
#include <string>
#include <vector>

#include "nrslam/camera/camera.h"
#include "nrslam/frontend/frontend_options.h"
#include "nrslam/frontend/image_pyramid.h"
#include "nrslam/frontend/klt_tracker.h"
#include "nrslam/geometry/rigid3.h"
#include "nrslam/mapping/deformable_ba.h"
#include "nrslam/mapping/mapping_options.h"
#include "nrslam/tracking/tracker.h"

namespace nrslam {

// A map made from two views; the world frame is the reference camera. The seed holds the
// current camera (baseline scaled with the map), the points and their current pixels.
struct InitialMap {
  int reference_frame = -1;
  std::vector<cv::Point2f> reference_pixels;   // per point, in the reference frame
  MapSeed seed;
};

// The reference view as a keyframe: identity pose, the seed's points (ids 0..n−1, as the
// tracker numbers a seed) at their reference pixels.
Keyframe ReferenceKeyframe(const InitialMap& map);

struct InitialisationAttempt {
  bool success = false;
  std::string note;  // what happened this frame, in words
  InitialMap map;
};

class MonocularInitialiser {
 public:
  // Of `tracking`, the corner budget (max_points) and the image-dropout rule.
  MonocularInitialiser(const Camera& camera, const FrontendOptions& frontend, const TrackingOptions& tracking,
                       const InitialisationOptions& options);

  InitialisationAttempt Add(int frame, const cv::Mat& bgr, const cv::Mat& mask);
  void Reset() { reference_frame_ = -1; }  // the next Add starts a reference (and the dropout count)

 private:
  Camera camera_;
  FrontendOptions frontend_;
  int max_points_;
  InitialisationOptions options_;
  KltTracker klt_;
  int reference_frame_ = -1;
  std::vector<cv::Point2f> reference_pixels_;
  std::vector<double> reference_brightness_;  // per reference corner; read only for the shading prior
  std::vector<std::vector<cv::Point2f>> history_;  // per reference corner, its pixel in every frame since
  std::vector<bool> alive_;
  ImageDropouts dropouts_;

  InitialisationAttempt StartReference(int frame, const cv::Mat& grey, const cv::Mat& mask, const std::string& why);
  InitialisationAttempt Reconstruct(const std::vector<int>& tracks) const;
  std::vector<int> FlowClusters(const std::vector<int>& tracks) const;
  // Moves each point (reference camera frame) along its ray to the blended distance.
  void ApplyShadingPrior(const std::vector<int>& tracks, std::vector<Eigen::Vector3d>* points) const;
};

// DBSCAN over the rows of `points` (Euclidean): a label per row, −1 for noise.
std::vector<int> Dbscan(const Eigen::MatrixXd& points, double epsilon, int min_points);

}  // namespace nrslam
