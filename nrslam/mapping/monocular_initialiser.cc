#include "nrslam/mapping/monocular_initialiser.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>

#include "nrslam/frontend/feature_detector.h"
#include "nrslam/frontend/masks.h"
#include "nrslam/frontend/shading.h"
#include "nrslam/geometry/two_view.h"
#include "nrslam/util/median.h"

namespace nrslam {

std::vector<int> Dbscan(const Eigen::MatrixXd& points, double epsilon, int min_points) {
  const int n = static_cast<int>(points.rows());
  const double epsilon2 = epsilon * epsilon;
  std::vector<std::vector<int>> near(n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      if ((points.row(i) - points.row(j)).squaredNorm() <= epsilon2) near[i].push_back(j);
    }
  }
  constexpr int kUnvisited = -2, kNoise = -1;
  std::vector<int> label(n, kUnvisited);
  int clusters = 0;
  for (int seed = 0; seed < n; ++seed) {
    if (label[seed] != kUnvisited) continue;
    if (static_cast<int>(near[seed].size()) < min_points) {
      label[seed] = kNoise;
      continue;
    }
    const int cluster = clusters++;
    label[seed] = cluster;
    std::deque<int> frontier(near[seed].begin(), near[seed].end());
    while (!frontier.empty()) {
      const int i = frontier.front();
      frontier.pop_front();
      if (label[i] == kNoise) label[i] = cluster;  // a border point
      if (label[i] != kUnvisited) continue;
      label[i] = cluster;
      if (static_cast<int>(near[i].size()) >= min_points) frontier.insert(frontier.end(), near[i].begin(), near[i].end());
    }
  }
  return label;
}

Keyframe ReferenceKeyframe(const InitialMap& map) {
  Keyframe keyframe;
  keyframe.frame = map.reference_frame;
  for (size_t i = 0; i < map.seed.points.size(); ++i) {
    keyframe.ids.push_back(static_cast<PointId>(i));
    keyframe.pixels.emplace_back(map.reference_pixels[i].x, map.reference_pixels[i].y);
    keyframe.positions.push_back(map.seed.points[i]);
  }
  return keyframe;
}

MonocularInitialiser::MonocularInitialiser(const Camera& camera, const FrontendOptions& frontend,
                                           const TrackingOptions& tracking, const InitialisationOptions& options)
    : camera_(camera), frontend_(frontend), max_points_(tracking.max_points), options_(options),
      klt_(frontend.klt), dropouts_(tracking) {
  tracking.Check();
  options_.Check();
}

InitialisationAttempt MonocularInitialiser::StartReference(int frame, const cv::Mat& grey, const cv::Mat& mask,
                                                           const std::string& why) {
  const cv::Mat valid = BuildValidityMask(grey, mask, frontend_.masks);
  FeatureOptions features = frontend_.features;
  features.max_features = max_points_;
  reference_pixels_ = DetectCorners(grey, valid, {}, features);
  klt_.SetReference(ImagePyramid(grey, frontend_.klt.levels), reference_pixels_, valid);
  reference_brightness_.clear();
  if (options_.shading_weight > 0) {
    reference_brightness_ = LinearBrightness(grey, valid, reference_pixels_, frontend_.shading);
  }
  reference_frame_ = frame;
  dropouts_.Reset();
  history_.assign(reference_pixels_.size(), {});
  alive_.assign(reference_pixels_.size(), false);
  for (size_t i = 0; i < reference_pixels_.size(); ++i) {
    alive_[i] = klt_.has_reference(i);
    history_[i].push_back(reference_pixels_[i]);
  }
  InitialisationAttempt attempt;
  attempt.note = why + "; new reference with " + std::to_string(reference_pixels_.size()) + " corners";
  return attempt;
}

InitialisationAttempt MonocularInitialiser::Add(int frame, const cv::Mat& bgr, const cv::Mat& mask) {
  const cv::Mat grey = ToGrey(bgr);
  if (reference_frame_ < 0) return StartReference(frame, grey, mask, "start");
  if (frame - reference_frame_ > options_.max_reference_age) return StartReference(frame, grey, mask, "reference too old");

  std::vector<cv::Point2f> guesses;
  for (size_t i = 0; i < history_.size(); ++i) guesses.push_back(alive_[i] ? history_[i].back() : cv::Point2f(NAN, NAN));
  std::vector<KltResult> matches;
  klt_.Track(ImagePyramid(grey, frontend_.klt.levels), guesses, frontend_.klt.ssim_initialisation, &matches);
  // A track that lands on an invalid pixel (the sequence's mask, a highlight) is dropped.
  const cv::Mat valid = BuildValidityMask(grey, mask, frontend_.masks);
  const auto on_valid = [&](const cv::Point2f& p) {
    const int x = cvRound(p.x), y = cvRound(p.y);
    return x >= 0 && y >= 0 && x < valid.cols && y < valid.rows && valid.at<uint8_t>(y, x) != 0;
  };
  std::vector<bool> found(history_.size());
  std::vector<ImageDropouts::LiveTrack> live;
  for (size_t i = 0; i < history_.size(); ++i) {
    found[i] = alive_[i] && matches[i].status == KltStatus::kTracked && on_valid(matches[i].position);
    if (alive_[i]) live.push_back({found[i], matches[i].ssim, matches[i].gain});
  }
  // Counted before any track is cut, so that a skipped frame leaves the tracks as they were.
  // By the share alone: tracks that run out gradually restart the reference below, as before.
  if (dropouts_.Skip(live, 0)) {
    InitialisationAttempt attempt;
    attempt.note = dropouts_.Note("tracks found", "");
    return attempt;
  }
  std::vector<int> tracks;
  for (size_t i = 0; i < history_.size(); ++i) {
    alive_[i] = found[i];
    if (!alive_[i]) continue;
    history_[i].push_back(matches[i].position);
    tracks.push_back(static_cast<int>(i));
  }
  if (static_cast<int>(tracks.size()) < options_.min_tracks) {
    return StartReference(frame, grey, mask, "only " + std::to_string(tracks.size()) + " tracks left");
  }
  InitialisationAttempt attempt = Reconstruct(tracks);
  if (attempt.success) {
    attempt.map.reference_frame = reference_frame_;
    reference_frame_ = -1;
  }
  return attempt;
}

InitialisationAttempt MonocularInitialiser::Reconstruct(const std::vector<int>& tracks) const {
  InitialisationAttempt attempt;
  // Rays by track, so inlier flags and pixels always index the same list (the reference's
  // compacted-vs-full index mismatch, §9.2, cannot happen).
  Bearings reference, current;
  for (int t : tracks) {
    const cv::Point2f& r = reference_pixels_[t];
    const cv::Point2f& c = history_[t].back();
    reference.push_back(camera_.Unproject(Eigen::Vector2d(r.x, r.y)).normalized());
    current.push_back(camera_.Unproject(Eigen::Vector2d(c.x, c.y)).normalized());
  }
  EssentialRansacOptions ransac;
  ransac.iterations = options_.ransac_iterations;
  ransac.epipolar_threshold_rad = options_.epipolar_threshold_px / camera_.MeanFocal();
  const auto essential = EstimateEssential(reference, current, ransac);
  if (!essential) {
    attempt.note = "no essential matrix";
    return attempt;
  }
  const Rigid3 current_from_reference = RefineRelativePose(
      reference, current, essential->inliers,
      DecomposeEssential(essential->essential, reference, current, essential->inliers),
      ransac.epipolar_threshold_rad);
  const Eigen::Vector3d centre = current_from_reference.Inverse().translation;
  const Eigen::Matrix3d reference_from_current = current_from_reference.rotation.conjugate().toRotationMatrix();
  const double min_parallax = options_.min_parallax_px / camera_.MeanFocal();

  std::vector<int> kept;
  std::vector<Eigen::Vector3d> points;
  std::vector<double> parallaxes;
  int low_parallax = 0;
  for (size_t i = 0; i < tracks.size(); ++i) {
    if (!essential->inliers[i]) continue;
    const auto point = TriangulateMidpoint(Eigen::Vector3d::Zero(), reference[i], centre,
                                           reference_from_current * current[i]);
    if (!point || point->parallax_rad < min_parallax) {
      ++low_parallax;
      continue;
    }
    if (point->depth0 <= 0 || point->depth1 <= 0) continue;
    const cv::Point2f& r = reference_pixels_[tracks[i]];
    const cv::Point2f& c = history_[tracks[i]].back();
    const auto in_reference = camera_.Project(point->point);
    const auto in_current = camera_.Project(current_from_reference * point->point);
    if (!in_reference || !in_current) continue;
    if ((*in_reference - Eigen::Vector2d(r.x, r.y)).squaredNorm() > options_.max_reprojection_px2 ||
        (*in_current - Eigen::Vector2d(c.x, c.y)).squaredNorm() > options_.max_reprojection_px2) {
      continue;
    }
    kept.push_back(tracks[i]);
    points.push_back(point->point);
    parallaxes.push_back(point->parallax_rad);
  }
  const double low_fraction = static_cast<double>(low_parallax) / std::max(1, essential->inlier_count);
  if (static_cast<int>(points.size()) < options_.min_points || low_fraction > options_.max_low_parallax_fraction) {
    attempt.note = std::to_string(essential->inlier_count) + " E inliers, " + std::to_string(points.size()) +
                   " triangulated, " + std::to_string(static_cast<int>(100 * low_fraction)) + " % low parallax";
    return attempt;
  }

  if (options_.point_min_parallax_snr > 0) {
    const Eigen::Matrix3d refined_essential = EssentialFromPose(current_from_reference);
    std::vector<double> epipolar_errors;
    for (size_t i = 0; i < tracks.size(); ++i) {
      if (essential->inliers[i]) epipolar_errors.push_back(std::abs(EpipolarAngle(refined_essential, reference[i], current[i])));
    }
    const double min_point_parallax = options_.point_min_parallax_snr * 1.4826 * Median(epipolar_errors);
    std::vector<int> passing_tracks;
    std::vector<Eigen::Vector3d> passing_points;
    for (size_t i = 0; i < points.size(); ++i) {
      if (parallaxes[i] < min_point_parallax) continue;
      passing_tracks.push_back(kept[i]);
      passing_points.push_back(points[i]);
    }
    if (static_cast<int>(passing_points.size()) >= options_.min_points) {
      kept = std::move(passing_tracks);
      points = std::move(passing_points);
    }
  }

  if (options_.shading_weight > 0) ApplyShadingPrior(kept, &points);

  // Scale: median reference-camera depth → options_.median_depth.
  std::vector<double> depths;
  for (const auto& p : points) depths.push_back(p.z());
  const double factor = options_.median_depth / Median(depths);
  double mean = 0, squares = 0;
  for (auto& p : points) {
    p *= factor;
    mean += p.z();
    squares += p.z() * p.z();
  }
  mean /= points.size();
  MapSeed& seed = attempt.map.seed;
  seed.cam_from_world = Rigid3(current_from_reference.rotation, current_from_reference.translation * factor);
  seed.points = std::move(points);
  seed.depth_deviation = std::sqrt(std::max(0.0, squares / seed.points.size() - mean * mean));
  seed.scale = options_.median_depth / 3.0;
  for (int t : kept) {
    seed.pixels.push_back(history_[t].back());
    attempt.map.reference_pixels.push_back(reference_pixels_[t]);
  }
  if (options_.initial_graph == "flow_clusters") seed.groups = FlowClusters(kept);
  attempt.success = true;
  attempt.note = std::to_string(essential->inlier_count) + " E inliers, " + std::to_string(seed.points.size()) +
                 " points, " + std::to_string(static_cast<int>(100 * low_fraction)) + " % low parallax";
  return attempt;
}

void MonocularInitialiser::ApplyShadingPrior(const std::vector<int>& tracks,
                                             std::vector<Eigen::Vector3d>* points) const {
  // The two-view map calibrates the brightness of its own points: the blend changes the
  // shape of the map, not its scale.
  ShadedPoints shaded;
  for (size_t i = 0; i < points->size(); ++i) {
    shaded.distances.push_back((*points)[i].norm());
    shaded.brightness.push_back(reference_brightness_[tracks[i]]);
  }
  const std::vector<double> blended = BlendWithShading(shaded, shaded, options_.shading_weight);
  for (size_t i = 0; i < points->size(); ++i) (*points)[i] *= blended[i] / shaded.distances[i];
}

std::vector<int> MonocularInitialiser::FlowClusters(const std::vector<int>& tracks) const {
  // One vector per track: its frame-to-frame flow since the reference, 2·(L−1) numbers.
  const int steps = static_cast<int>(history_[tracks.front()].size()) - 1;
  Eigen::MatrixXd flows(tracks.size(), 2 * std::max(1, steps));
  flows.setZero();
  for (size_t row = 0; row < tracks.size(); ++row) {
    const auto& path = history_[tracks[row]];
    for (int s = 0; s < steps; ++s) {
      flows(row, 2 * s) = path[s + 1].x - path[s].x;
      flows(row, 2 * s + 1) = path[s + 1].y - path[s].y;
    }
  }
  std::vector<int> labels = Dbscan(flows, options_.dbscan_epsilon_px * flows.cols(), options_.dbscan_min_points);
  // Noise joins the cluster of its nearest clustered flow; with no cluster at all, one group.
  const std::vector<int> clustered = labels;
  for (size_t i = 0; i < labels.size(); ++i) {
    if (clustered[i] >= 0) continue;
    double best = std::numeric_limits<double>::infinity();
    labels[i] = 0;
    for (size_t j = 0; j < labels.size(); ++j) {
      if (clustered[j] < 0) continue;
      const double distance = (flows.row(i) - flows.row(j)).squaredNorm();
      if (distance < best) {
        best = distance;
        labels[i] = clustered[j];
      }
    }
  }
  return labels;
}

}  // namespace nrslam
