#include "nrslam/tracking/tracker.h"

#include <ceres/loss_function.h>
#include <ceres/normal_prior.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <numeric>
#include <utility>

#include "nrslam/camera/reprojection_cost.h"
#include "nrslam/deformation/regularizer_costs.h"
#include "nrslam/eval/depth_evaluation.h"
#include "nrslam/frontend/feature_detector.h"
#include "nrslam/frontend/masks.h"
#include "nrslam/geometry/se3_manifold.h"
#include "nrslam/util/concurrent.h"
#include "nrslam/util/median.h"
#include "nrslam/util/stopwatch.h"
#include "nrslam/util/text_table.h"

namespace nrslam {
namespace {

// Moves the k entries of `by_distance` with the smallest .first (a squared distance) to its
// front, nearest first; false when it holds fewer than k.
template <typename Payload>
bool SortNearest(std::vector<std::pair<float, Payload>>* by_distance, size_t k) {
  if (by_distance->size() < k) return false;
  std::partial_sort(by_distance->begin(), by_distance->begin() + static_cast<std::ptrdiff_t>(k), by_distance->end(),
                    [](const auto& a, const auto& b) { return a.first < b.first; });
  return true;
}

ceres::Solver::Options SolverOptions(int iterations, ceres::LinearSolverType solver) {
  ceres::Solver::Options options;
  options.max_num_iterations = iterations;
  options.linear_solver_type = solver;
  options.num_threads = 1;  // two threads were slower on problems this small
  // ~500 parameter blocks: Eigen's simplicial Cholesky factors this 2.4× faster than
  // SuiteSparse's supernodal one (measured on sim-3: 2.4 vs 5.7 ms per iteration).
  options.sparse_linear_algebra_library_type = ceres::EIGEN_SPARSE;
  options.logging_type = ceres::SILENT;
  return options;
}

// Byte for byte: a look-ahead is only re-used for the image it ran on, even if a caller hands
// the next frame in a buffer it later overwrites (as a video grabber does).
bool SameImage(const cv::Mat& a, const cv::Mat& b) {
  if (a.size != b.size || a.type() != b.type()) return false;
  const size_t row_bytes = a.cols * a.elemSize();
  for (int row = 0; row < a.rows; ++row) {
    if (std::memcmp(a.ptr(row), b.ptr(row), row_bytes) != 0) return false;
  }
  return true;
}

}  // namespace

std::vector<Eigen::Vector3d> WithoutCommonMotion(std::vector<Eigen::Vector3d> motions) {
  if (motions.empty()) return motions;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& motion : motions) mean += motion;
  mean /= static_cast<double>(motions.size());
  for (Eigen::Vector3d& motion : motions) motion -= mean;
  return motions;
}

const char* ToString(TrackingState state) {
  switch (state) {
    case TrackingState::kNotInitialised: return "not_initialised";
    case TrackingState::kTracking: return "tracking";
    case TrackingState::kLost: return "lost";
  }
  return "unknown";
}

Tracker::Tracker(const Camera& camera, const FrontendOptions& frontend, const DeformationModelOptions& deformation,
                 const TrackingOptions& tracking)
    : camera_(camera),
      frontend_(frontend),
      deformation_(deformation),
      options_(tracking),
      map_(std::make_unique<Map>(deformation)),
      klt_(frontend.klt) {
  camera_.Check();
  frontend_.Check();
  deformation_.Check();
  options_.Check();
}

void Tracker::NoteViewJump(FrameResult* result) {
  if (flows_px_.empty()) return;
  const double flow = MedianInPlace(&flows_px_);
  constexpr size_t kRecentFrames = 10, kFewestToCompare = 3;
  constexpr double kSlowestRecentPx = 1.0;  // a still view's sub-pixel jitter is no scale to judge by
  if (options_.jump_flow_ratio > 0 && recent_flows_px_.size() >= kFewestToCompare) {
    flows_px_.assign(recent_flows_px_.begin(), recent_flows_px_.end());  // this frame's are done with
    const double usual = std::max(MedianInPlace(&flows_px_), kSlowestRecentPx);
    if (flow > options_.jump_flow_ratio * usual) {
      result->view_jump = true;
      if (!result->note.empty()) result->note += "; ";
      result->note += "the view jumped: its tracks moved " + FormatFixed(flow / usual, 1) +
                      " times as far as over the recent frames (" + FormatFixed(flow, 1) + " against " +
                      FormatFixed(usual, 1) + " px): frames missing from the recording, or a jerk of the scope";
    }
  }
  recent_flows_px_.push_back(flow);
  if (recent_flows_px_.size() > kRecentFrames) recent_flows_px_.pop_front();
}

FrameResult Tracker::Lost(FrameResult result, const std::string& why) {
  state_ = state_ == TrackingState::kNotInitialised ? state_ : TrackingState::kLost;
  result.state = state_;
  result.note = why;
  result.points.clear();
  return result;
}

FrameResult Tracker::InitialiseFromDepth(int frame, const cv::Mat& bgr, const cv::Mat& depth_mm, const cv::Mat& mask) {
  const cv::Mat grey = ToGrey(bgr);
  FeatureOptions features = frontend_.features;
  features.max_features = options_.max_points;
  MapSeed seed;
  std::vector<double> depths;
  const std::vector<cv::Point2f> corners = DetectCorners(grey, BuildValidityMask(grey, mask, frontend_.masks), {}, features);
  for (const cv::Point2f& corner : corners) {
    const auto depth = SampleDepth(depth_mm, cv::Point2d(corner.x, corner.y));
    if (!depth) continue;
    const Eigen::Vector3d bearing = camera_.Unproject(Eigen::Vector2d(corner.x, corner.y));
    if (bearing.z() <= 1e-6) continue;
    seed.pixels.push_back(corner);
    seed.points.push_back(bearing * (*depth / bearing.z()));
    depths.push_back(*depth);
  }
  if (static_cast<int>(depths.size()) < options_.min_points) {
    FrameResult result;
    result.frame = frame;
    // Whether the image or its depth fell short tells a blank frame from a hole in the depth map.
    return Lost(result, "too few points with depth to initialise (" + std::to_string(depths.size()) + " of " +
                            std::to_string(corners.size()) + " corners found)");
  }
  double mean = 0, squares = 0;
  for (double z : depths) {
    mean += z;
    squares += z * z;
  }
  mean /= depths.size();
  seed.depth_deviation = std::sqrt(std::max(1e-12, squares / depths.size() - mean * mean));
  seed.scale = Median(depths) / 3.0;
  return InitialiseFromSeed(frame, bgr, mask, seed);
}

FrameResult Tracker::InitialiseFromSeed(int frame, const cv::Mat& bgr, const cv::Mat& mask, const MapSeed& seed) {
  const auto start = Clock::now();
  FrameResult result;
  result.frame = frame;
  map_ = std::make_unique<Map>(deformation_);
  point_motion_.clear();
  tracks_.clear();
  lost_.clear();
  lookahead_.reset();
  if (static_cast<int>(seed.points.size()) < options_.min_points) {
    return Lost(result, "too few points to start a map (" + std::to_string(seed.points.size()) + ")");
  }
  const cv::Mat grey = ToGrey(bgr);
  std::map<int, std::vector<PointId>> groups;
  for (size_t i = 0; i < seed.points.size(); ++i) {
    const cv::Point2f& pixel = seed.pixels[i];
    const cv::Point pixel_int(std::clamp(cvRound(pixel.x), 0, bgr.cols - 1), std::clamp(cvRound(pixel.y), 0, bgr.rows - 1));
    const PointId id = map_->AddPoint(seed.points[i], bgr.at<cv::Vec3b>(pixel_int), frame);
    groups[seed.groups.empty() ? 0 : seed.groups[i]].push_back(id);
    tracks_.push_back({id, next_track_id_++, pixel, true, {}});
  }
  map_->set_scale(seed.scale);
  map_->graph().set_sigma(deformation_.sigma_factor * seed.depth_deviation);
  for (const auto& [group, ids] : groups) map_->graph().ConnectCovisible(ids, {}, map_->Positions());

  cam_from_world_ = seed.cam_from_world;
  motion_ = Rigid3();
  dropouts_.Reset();
  recent_flows_px_.clear();
  RefreshReference(frame, std::make_shared<const ImagePyramid>(grey, frontend_.klt.levels),
                   BuildValidityMask(grey, mask, frontend_.masks));
  state_ = TrackingState::kTracking;
  result.state = state_;
  result.cam_from_world = cam_from_world_;
  for (const PointTrack& track : tracks_) {
    if (track.active) result.points.push_back({track.id, track.pixel});
  }
  result.klt_tracked = static_cast<int>(result.points.size());
  result.ms_total = MillisecondsSince(start);
  return result;
}

void Tracker::PromoteCandidate(int track_id, PointId id) {
  for (PointTrack& track : tracks_) {
    if (track.track_id == track_id && track.id == kNoPoint) {
      track.id = id;
      return;
    }
  }
}

void Tracker::RefreshReference(int frame, std::shared_ptr<const ImagePyramid> keyframe, const cv::Mat& valid,
                               const cv::Mat& grey) {
  std::vector<PointTrack> active;
  std::vector<cv::Point2f> pixels;
  for (const PointTrack& track : tracks_) {
    if (!track.active) continue;
    active.push_back(track);
    pixels.push_back(track.pixel);
  }
  if (candidates_ && !grey.empty()) {
    FeatureOptions features = frontend_.features;
    features.max_features = std::max(0, frontend_.features.max_features - static_cast<int>(pixels.size()));
    if (features.max_features > 0) {
      for (const cv::Point2f& corner : DetectCorners(grey, valid, pixels, features)) {
        active.push_back({kNoPoint, next_track_id_++, corner, true, {}});
      }
      pixels.clear();
      for (const PointTrack& track : active) pixels.push_back(track.pixel);
    }
  }
  tracks_ = std::move(active);
  klt_.SetReference(*keyframe, pixels, valid);
  ++reference_generation_;
  for (size_t i = 0; i < tracks_.size(); ++i) {
    if (klt_.has_reference(i)) {
      tracks_[i].patch = {keyframe, tracks_[i].pixel};
    } else {
      // Under the mask here (hidden), or at the image's edge; it may be seen again elsewhere.
      LoseTrack(&tracks_[i], frame, UnderMask(valid, tracks_[i].pixel));
    }
  }
  frames_since_keyframe_ = 0;
}

void Tracker::RetireDroppedPoints(std::vector<PointId> in_use) {
  for (const PointTrack& track : tracks_) {
    if (track.active && track.id != kNoPoint) in_use.push_back(track.id);
  }
  for (const auto& entry : lost_) in_use.push_back(entry.first);
  map_->graph().Retire(in_use, map_->size());
}

bool Tracker::UnderMask(const cv::Mat& valid, const cv::Point2f& pixel) const {
  const bool inside = camera_.InImage(Eigen::Vector2d(pixel.x, pixel.y), WindowMargin());
  return inside && valid.at<uint8_t>(cvRound(pixel.y), cvRound(pixel.x)) == 0;
}

void Tracker::MarkHiddenLosses(int frame) {
  const auto k = static_cast<size_t>(options_.reassociation_consensus_k);
  if (k == 0 || options_.hidden_recent_frames == 0 || lost_now_.empty()) return;
  const auto inside = [&](const cv::Point2f& pixel, double margin) {
    return camera_.InImage(Eigen::Vector2d(pixel.x, pixel.y), margin);
  };
  around_.clear();  // map points found this frame, and those lost lately where the KLT could see
  for (const PointTrack& track : tracks_) {
    if (track.active && track.id != kNoPoint) around_.emplace_back(track.pixel, false);
  }
  for (const auto& [id, lost] : lost_) {
    if (frame - lost.lost_frame <= options_.hidden_recent_frames && inside(lost.pixel, WindowMargin())) {
      around_.emplace_back(lost.pixel, true);
    }
  }
  const double edge_margin = options_.hidden_min_edge_fraction * std::min(camera_.width(), camera_.height());
  for (PointId id : lost_now_) {
    LostPoint& lost = lost_.at(id);
    if (lost.hidden || !inside(lost.pixel, edge_margin)) continue;
    nearest_.clear();
    for (const auto& [pixel, lately_lost] : around_) {
      const cv::Point2f apart = pixel - lost.pixel;
      const float squared = apart.dot(apart);
      if (squared > 0) nearest_.emplace_back(squared, lately_lost);  // not the point itself
    }
    if (!SortNearest(&nearest_, k)) continue;
    size_t lately_lost = 0;
    for (size_t j = 0; j < k; ++j) lately_lost += nearest_[j].second;
    lost.hidden = 2 * lately_lost >= k;
  }
}

bool Tracker::LoseTrack(PointTrack* track, int frame, bool hidden) {
  track->active = false;
  if (!track->patch.keyframe || track->id == kNoPoint) return false;
  if (!options_.rigid && map_->graph().IsWeaklyConnected(track->id)) return false;
  lost_[track->id] = {track->patch, frame, track->pixel, hidden};
  return true;
}

int Tracker::PropagateMotion(const std::vector<std::optional<Eigen::Vector3d>>& optimised,
                             const std::vector<PointId>& demoted) {
  std::vector<PointId> candidates = demoted;
  for (const auto& entry : lost_) candidates.push_back(entry.first);
  const auto is_optimised = [&](PointId id) { return optimised[static_cast<size_t>(id)].has_value(); };
  // All moves are computed from this frame's optimised displacements before any is applied,
  // so the order of the candidates does not matter.
  std::vector<std::pair<PointId, Eigen::Vector3d>> moves;
  for (PointId id : candidates) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double total = 0.0;
    for (const GraphNeighbour& neighbour : map_->graph().BestNeighbours(id, is_optimised)) {
      const double weight = neighbour.weight * neighbour.weight;
      sum += weight * *optimised[static_cast<size_t>(neighbour.id)];
      total += weight;
    }
    if (total > 0.0) moves.emplace_back(id, sum / total);
  }
  for (const auto& [id, move] : moves) map_->point(id).position += move;
  return static_cast<int>(moves.size());
}

void Tracker::ForgetLostPoints(int frame) {
  for (auto it = lost_.begin(); it != lost_.end();) {
    const bool stale = frame - it->second.lost_frame > options_.lost_max_age_frames;
    const bool cut_loose = !options_.rigid && map_->graph().IsWeaklyConnected(it->first);
    it = stale || cut_loose ? lost_.erase(it) : std::next(it);
  }
}

void Tracker::Reassociate(const ImagePyramid& pyramid, const cv::Mat& valid, FrameResult* result) {
  // Candidates: projecting far enough inside the image for a whole window and onto valid
  // pixels (not under the mask, not in a highlight), grouped by the keyframe of their patch.
  // Groups keep the order they were first met in: ordered by address, found points would join
  // the tracks in an order that changes from run to run, and so would the results.
  const double margin = WindowMargin();
  using Candidates = std::vector<std::pair<PointId, Eigen::Vector2d>>;  // id, projection
  std::vector<std::pair<const ImagePyramid*, Candidates>> groups;
  std::unordered_map<const ImagePyramid*, size_t> group_of;
  for (const auto& [id, lost] : lost_) {
    const auto pixel = camera_.Project(cam_from_world_ * map_->point(id).position);
    if (!pixel || !camera_.InImage(*pixel, margin)) continue;
    if (!valid.at<uint8_t>(cvRound(pixel->y()), cvRound(pixel->x()))) continue;
    const auto [it, added] = group_of.emplace(lost.patch.keyframe.get(), groups.size());
    if (added) groups.emplace_back(lost.patch.keyframe.get(), Candidates{});
    groups[it->second].second.emplace_back(id, *pixel);
  }
  KltOptions near_search = frontend_.klt;
  near_search.levels = std::min(near_search.levels, options_.reassociation_levels);  // the seed is close
  const bool search_far = options_.reassociation_consensus_k > 0;
  std::vector<FoundAgain> near, far;
  for (const auto& [keyframe, candidates] : groups) {
    std::vector<cv::Point2f> patches, seeds;
    for (const auto& [id, projection] : candidates) {
      patches.push_back(lost_.at(id).patch.pixel);
      seeds.emplace_back(static_cast<float>(projection.x()), static_cast<float>(projection.y()));
    }
    KltTracker klt(near_search);
    klt.SetReference(*keyframe, patches);
    std::vector<KltResult> found;
    klt.Track(pyramid, seeds, frontend_.klt.ssim_reassociation, &found);
    std::vector<cv::Point2f> missed_patches, missed_seeds;
    std::vector<PointId> missed;
    for (size_t i = 0; i < candidates.size(); ++i) {
      const cv::Point2f offset = found[i].position - seeds[i];
      if (found[i].status == KltStatus::kTracked && offset.dot(offset) <= options_.reassociation_gate_px2) {
        near.push_back({candidates[i].first, seeds[i], found[i].position});
      } else if (search_far && lost_.at(candidates[i].first).hidden) {
        missed.push_back(candidates[i].first);
        missed_patches.push_back(patches[i]);
        missed_seeds.push_back(seeds[i]);
      }
    }
    if (missed.empty()) continue;
    KltTracker full_pyramid(frontend_.klt);
    full_pyramid.SetReference(*keyframe, missed_patches);
    full_pyramid.Track(pyramid, missed_seeds, frontend_.klt.ssim_reassociation, &found);
    for (size_t i = 0; i < missed.size(); ++i) {
      if (found[i].status == KltStatus::kTracked) far.push_back({missed[i], missed_seeds[i], found[i].position});
    }
  }
  // The consensus reads only the finds, so near ones can become tracks before far ones are judged.
  const auto track_again = [&](const FoundAgain& point) {
    const PatchSource patch = lost_.at(point.id).patch;
    klt_.Append(*patch.keyframe, {patch.pixel});
    tracks_.push_back({point.id, next_track_id_++, point.pixel, klt_.has_reference(klt_.size() - 1), patch});
    lost_.erase(point.id);
    if (!tracks_.back().active) return;
    result->points.push_back({point.id, point.pixel, true});
    ++result->reassociated;
  };
  for (const FoundAgain& point : near) track_again(point);
  for (const FoundAgain& point : far) {
    if (MovedWithItsNeighbours(point, near, far)) track_again(point);
  }
}

bool Tracker::MovedWithItsNeighbours(const FoundAgain& point, const std::vector<FoundAgain>& near,
                                     const std::vector<FoundAgain>& far) {
  consensus_.clear();  // squared distance between projections, the neighbour's offset
  for (const std::vector<FoundAgain>* found : {&near, &far}) {
    for (const FoundAgain& other : *found) {
      if (&other == &point) continue;
      const cv::Point2f apart = other.projection - point.projection;
      consensus_.emplace_back(apart.dot(apart), other.pixel - other.projection);
    }
  }
  const auto k = static_cast<size_t>(options_.reassociation_consensus_k);
  if (!SortNearest(&consensus_, k)) return false;
  offsets_x_.clear();
  offsets_y_.clear();
  for (size_t j = 0; j < k; ++j) {
    offsets_x_.push_back(consensus_[j].second.x);
    offsets_y_.push_back(consensus_[j].second.y);
  }
  const cv::Point2f from_theirs =
      point.pixel - point.projection - cv::Point2f(MedianInPlace(&offsets_x_), MedianInPlace(&offsets_y_));
  return from_theirs.dot(from_theirs) <= options_.reassociation_gate_px2;
}

bool Tracker::ReprojectsWithinChi2(const Rigid3& cam_from_world, const Eigen::Vector3d& world,
                                   const Eigen::Vector2d& observed, double sigma_px) const {
  const double sigma2 = sigma_px * sigma_px;
  return SquaredReprojectionError(camera_, cam_from_world, world, observed) / sigma2 <= options_.outlier_chi2;
}

std::vector<bool> Tracker::RefinePose(const std::vector<Observation>& observations,
                                      const std::vector<Eigen::Vector3d>& start, Rigid3* pose) const {
  const PoseParams seed = pose->ToParams();
  std::vector<bool> inliers(observations.size(), true);
  std::vector<Eigen::Vector3d> points;
  for (size_t i = 0; i < observations.size(); ++i) {
    points.push_back(map_->point(observations[i].id).position + start[i]);
  }
  Se3Manifold manifold;
  PoseParams params = seed;
  for (int round = 0; round < options_.pose_rounds; ++round) {
    params = seed;  // every round restarts from the seed, as the reference does
    ceres::Problem::Options problem_options;
    problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(problem_options);
    problem.AddParameterBlock(params.data(), kPoseParams, &manifold);
    int used = 0;
    for (size_t i = 0; i < observations.size(); ++i) {
      if (!inliers[i]) continue;
      problem.AddResidualBlock(CreateReprojectionCost(camera_, observations[i].pixel, options_.pose_sigma_px),
                               new ceres::HuberLoss(deformation_.huber_reprojection), params.data(), points[i].data());
      problem.SetParameterBlockConstant(points[i].data());
      ++used;
    }
    if (used < options_.min_points) break;
    ceres::Solver::Summary summary;
    ceres::Solve(SolverOptions(options_.pose_iterations, ceres::DENSE_QR), &problem, &summary);
    const Rigid3 estimate = Rigid3::FromParams(params.data());
    for (size_t i = 0; i < observations.size(); ++i) {
      inliers[i] = ReprojectsWithinChi2(estimate, points[i], observations[i].pixel, options_.pose_sigma_px);
    }
  }
  *pose = Rigid3::FromParams(params.data());
  return inliers;
}

Tracker::JointSolveTimes Tracker::SolveDeformation(const std::vector<Observation>& observations,
                                                   const std::vector<Eigen::Vector3d>& start, Rigid3* pose,
                                                   std::vector<Eigen::Vector3d>* displacements,
                                                   std::vector<bool>* inliers) const {
  const size_t n = observations.size();
  std::vector<PointId> ids(n);
  std::vector<Eigen::Vector3d> points(n);
  for (size_t i = 0; i < n; ++i) {
    ids[i] = observations[i].id;
    points[i] = map_->point(observations[i].id).position;
  }
  // Regularised pairs: each point's best D edges to other tracked points, each pair once,
  // lower index first (the orientation is free, but it moves the solver's rounding).
  struct Pair {
    size_t i, j;
    double rest_length, viscous_multiplier;
  };
  std::vector<Pair> pairs;
  for (const GraphPair& pair : map_->graph().PairsAmong(ids)) {
    pairs.push_back({std::min(pair.i, pair.j), std::max(pair.i, pair.j), map_->graph().edge(pair.edge).rest_length,
                     ViscousMultiplier(deformation_, pair.weight, map_->scale())});
  }

  const PoseParams rigid = pose->ToParams();
  Se3Manifold manifold;
  // A point the refined pose puts behind the camera (or off the lens) would make every
  // evaluation of the problem fail, and Ceres would return at once: it starts as an outlier.
  inliers->assign(n, true);
  for (size_t i = 0; i < n; ++i) (*inliers)[i] = camera_.Project(*pose * (points[i] + start[i])).has_value();
  // A viscous term whose residual ended a round beyond the Huber δ sits the next round out:
  // neighbours that really move apart (strong or discontinuous deformation) stop pulling.
  std::vector<bool> viscous_on(pairs.size(), true);
  PoseParams params = rigid;
  // The residuals are the same functions in every round (only which ones take part changes):
  // built once, owned here, and lent to each round's problem.
  std::vector<std::unique_ptr<ceres::CostFunction>> reprojection_costs, elastic_costs, viscous_costs;
  for (size_t i = 0; i < n; ++i) {
    reprojection_costs.emplace_back(CreateDeformedReprojectionCost(camera_, observations[i].pixel, points[i],
                                                                   deformation_.reprojection_sigma_px));
  }
  for (const Pair& pair : pairs) {
    if (deformation_.elastic) {
      elastic_costs.emplace_back(ElasticCost::Create(points[pair.i], points[pair.j], pair.rest_length,
                                                     ElasticMultiplier(deformation_, pair.rest_length)));
    }
    if (deformation_.viscous) viscous_costs.emplace_back(ViscousCost::Create(pair.viscous_multiplier));
  }
  std::unique_ptr<ceres::CostFunction> displacement_prior;
  if (options_.displacement_prior_sigma > 0) {
    displacement_prior = std::make_unique<ceres::NormalPrior>(
        Eigen::Matrix3d::Identity() / (options_.displacement_prior_sigma * map_->scale()), Eigen::Vector3d::Zero());
  }
  ceres::HuberLoss reprojection_loss(deformation_.huber_reprojection), deformation_loss(deformation_.huber_deformation);
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  // Ceres's default preconditioner for CGNR is block Jacobi.
  ceres::Solver::Options solver_options = SolverOptions(
      options_.deformation_iterations,
      options_.joint_linear_solver == "cgnr" ? ceres::CGNR : ceres::SPARSE_NORMAL_CHOLESKY);
  if (options_.joint_trust_region == "dogleg") solver_options.trust_region_strategy_type = ceres::DOGLEG;
  JointSolveTimes times;
  for (int round = 0; round < options_.deformation_rounds; ++round) {
    params = rigid;  // every round restarts from the rigid pose and the start δ
    *displacements = start;
    ceres::Problem problem(problem_options);
    problem.AddParameterBlock(params.data(), kPoseParams, &manifold);
    for (size_t i = 0; i < n; ++i) {
      problem.AddParameterBlock((*displacements)[i].data(), 3);
      if (displacement_prior) problem.AddResidualBlock(displacement_prior.get(), nullptr, (*displacements)[i].data());
      if ((*inliers)[i]) {
        problem.AddResidualBlock(reprojection_costs[i].get(), &reprojection_loss, params.data(),
                                 (*displacements)[i].data());
      }
    }
    for (size_t p = 0; p < pairs.size(); ++p) {
      const Pair& pair = pairs[p];
      double* delta_i = (*displacements)[pair.i].data();
      double* delta_j = (*displacements)[pair.j].data();
      if (deformation_.elastic) problem.AddResidualBlock(elastic_costs[p].get(), &deformation_loss, delta_i, delta_j);
      // An outlier's motion is not evidence for its neighbours': its viscous terms go too.
      if (deformation_.viscous && (*inliers)[pair.i] && (*inliers)[pair.j] && viscous_on[p]) {
        problem.AddResidualBlock(viscous_costs[p].get(), &deformation_loss, delta_i, delta_j);
      }
    }
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &problem, &summary);
    times.ms_total += 1e3 * summary.total_time_in_seconds;
    times.ms_linear += 1e3 * summary.linear_solver_time_in_seconds;
    const Rigid3 estimate = Rigid3::FromParams(params.data());
    for (size_t i = 0; i < n; ++i) {
      (*inliers)[i] = ReprojectsWithinChi2(estimate, points[i] + (*displacements)[i], observations[i].pixel,
                                           deformation_.reprojection_sigma_px);
    }
    const double viscous_chi2 = deformation_.huber_deformation * deformation_.huber_deformation;
    for (size_t p = 0; p < pairs.size(); ++p) {
      const Pair& pair = pairs[p];
      viscous_on[p] =
          (pair.viscous_multiplier * ((*displacements)[pair.i] - (*displacements)[pair.j])).squaredNorm() <= viscous_chi2;
    }
  }
  *pose = Rigid3::FromParams(params.data());
  return times;
}

std::vector<size_t> Tracker::JointSolveSubset(const std::vector<Observation>& observations) const {
  std::vector<size_t> order(observations.size());
  std::iota(order.begin(), order.end(), size_t{0});
  const auto cap = static_cast<size_t>(options_.joint_solve_max_points);
  if (cap == 0 || observations.size() <= cap) return order;
  // Each cell's points oldest first (ids grow as points are made), and a different one of them
  // from frame to frame, so that every point is solved for now and then; a point left out
  // for good would only ever follow its neighbours (measured worse on the monocular suite).
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return observations[a].id < observations[b].id; });
  const double cell = std::sqrt(static_cast<double>(camera_.width()) * camera_.height() / static_cast<double>(cap));
  const int columns = static_cast<int>(std::ceil(camera_.width() / cell));
  const int rows = static_cast<int>(std::ceil(camera_.height() / cell));
  std::vector<std::vector<size_t>> by_cell(static_cast<size_t>(columns * rows));
  for (size_t i : order) {
    const int column = std::clamp(static_cast<int>(observations[i].pixel.x() / cell), 0, columns - 1);
    const int row = std::clamp(static_cast<int>(observations[i].pixel.y() / cell), 0, rows - 1);
    by_cell[static_cast<size_t>(row * columns + column)].push_back(i);
  }
  std::vector<bool> chosen(observations.size(), false);
  size_t count = 0;
  for (const std::vector<size_t>& members : by_cell) {
    if (members.empty() || count == cap) continue;
    chosen[members[static_cast<size_t>(frames_since_keyframe_) % members.size()]] = true;
    ++count;
  }
  // Where the points leave cells empty (a dark lumen), the oldest of the rest fill the budget.
  for (size_t i : order) {
    if (count == cap) break;
    if (!chosen[i]) {
      chosen[i] = true;
      ++count;
    }
  }
  std::vector<size_t> solved;
  for (size_t i = 0; i < observations.size(); ++i) {
    if (chosen[i]) solved.push_back(i);
  }
  return solved;
}

std::vector<cv::Point2f> Tracker::KltGuesses() const {
  std::vector<cv::Point2f> guesses;
  guesses.reserve(tracks_.size());
  for (const PointTrack& track : tracks_) guesses.push_back(track.active ? track.pixel : cv::Point2f(NAN, NAN));
  return guesses;
}

void Tracker::MatchTracks(const ImagePyramid& pyramid, const std::vector<cv::Point2f>& guesses, const Lookahead* ahead,
                          std::vector<KltResult>* matches) const {
  // The look-ahead ran every track there was then, from the pixel it still has (tracks move
  // only here) unless it is inactive now (a track is never reactivated: a point found again
  // gets a new one); the tracks after those were re-associated since.
  const size_t done = ahead ? std::min(ahead->matches.size(), guesses.size()) : 0;
  std::vector<cv::Point2f> rest = guesses;
  std::fill(rest.begin(), rest.begin() + static_cast<std::ptrdiff_t>(done), cv::Point2f(NAN, NAN));
  if (std::any_of(rest.begin(), rest.end(), [](const cv::Point2f& guess) { return !std::isnan(guess.x); })) {
    klt_.Track(pyramid, rest, frontend_.klt.ssim_tracking, matches);
  } else {
    matches->assign(guesses.size(), KltResult{});
  }
  if (ahead) std::copy_n(ahead->matches.begin(), done, matches->begin());
}

Tracker::Lookahead Tracker::RunAhead(const cv::Mat& next_bgr, const std::vector<cv::Point2f>& guesses,
                                     int reference_generation) const {
  const auto start = Clock::now();
  Lookahead ahead;
  ahead.grey = ToGrey(next_bgr);
  ahead.pyramid = std::make_shared<const ImagePyramid>(ahead.grey, frontend_.klt.levels);
  // One thread: the other core is this frame's solve.
  klt_.Track(*ahead.pyramid, guesses, frontend_.klt.ssim_tracking, &ahead.matches, 1);
  ahead.reference_generation = reference_generation;
  ahead.ms = MillisecondsSince(start);
  return ahead;
}

std::optional<std::string> Tracker::SolvePoseAndDeformation(std::vector<Observation>* observations_in_view,
                                                            FrameSolution* solution, FrameResult* result) {
  // Pose: constant-velocity seed, rigid refinement. A point that the seed puts behind the
  // camera (or outside the lens) would make every Ceres evaluation fail: it sits this frame out.
  const auto pose_start = Clock::now();
  std::vector<Observation>& observations = *observations_in_view;
  Rigid3& pose = solution->pose;
  pose = motion_ * cam_from_world_;
  observations.erase(std::remove_if(observations.begin(), observations.end(),
                                    [&](const Observation& o) {
                                      return !camera_.Project(pose * map_->point(o.id).position);
                                    }),
                     observations.end());
  if (static_cast<int>(observations.size()) < options_.min_points) {
    return "only " + std::to_string(observations.size()) + " points in front of the camera";
  }
  std::vector<Eigen::Vector3d> motion_seeds(observations.size(), Eigen::Vector3d::Zero());
  if (!options_.rigid && options_.deformation_motion_seed) {
    for (size_t i = 0; i < observations.size(); ++i) {
      const auto id = static_cast<size_t>(observations[i].id);
      if (id < point_motion_.size()) motion_seeds[i] = point_motion_[id];  // new points: none yet
    }
    motion_seeds = WithoutCommonMotion(std::move(motion_seeds));
  }
  std::vector<bool>& inliers = solution->inliers;
  inliers = RefinePose(observations, motion_seeds, &pose);
  result->ms_pose = MillisecondsSince(pose_start);

  // Deformation.
  const auto deformation_start = Clock::now();
  std::vector<Eigen::Vector3d> displacements(observations.size(), Eigen::Vector3d::Zero());
  std::vector<bool>& demoted = solution->demoted;
  demoted.assign(observations.size(), false);
  if (!options_.rigid) {
    // This frame's seeds are taken: the buffer now holds where every point starts, and below
    // becomes how far tracking moved it (the next frame's seeds), without a new allocation.
    if (options_.deformation_motion_seed) {
      point_motion_.resize(map_->size());
      for (size_t id = 0; id < point_motion_.size(); ++id) point_motion_[id] = map_->points()[id].position;
    }
    const std::vector<size_t> solved = JointSolveSubset(observations);
    std::vector<Observation> solved_observations;
    std::vector<Eigen::Vector3d> solved_seeds, solved_displacements;
    for (size_t i : solved) {
      solved_observations.push_back(observations[i]);
      solved_seeds.push_back(motion_seeds[i]);
    }
    std::vector<bool> solved_inliers, in_solve(observations.size(), false);
    const JointSolveTimes times =
        SolveDeformation(solved_observations, solved_seeds, &pose, &solved_displacements, &solved_inliers);
    for (size_t k = 0; k < solved.size(); ++k) {
      in_solve[solved[k]] = true;
      displacements[solved[k]] = solved_displacements[k];
      inliers[solved[k]] = solved_inliers[k];
    }
    result->ms_joint_solve = times.ms_total;
    result->ms_linear_solve = times.ms_linear;
    // Demote points whose displacement is an outlier (IQR fence on ‖δ‖); they keep their position.
    std::vector<double> norms, sorted, inlier_norms;
    for (const auto& d : displacements) norms.push_back(d.norm());
    for (size_t i : solved) sorted.push_back(norms[i]);
    std::sort(sorted.begin(), sorted.end());
    const double q1 = sorted[sorted.size() / 4], q3 = sorted[(3 * sorted.size()) / 4];
    const double fence = q3 + options_.displacement_iqr_factor * (q3 - q1);
    for (size_t i : solved) {
      if (inliers[i]) inlier_norms.push_back(norms[i]);
    }
    if (!inlier_norms.empty()) result->median_displacement = Median(inlier_norms);
    for (size_t i = 0; i < observations.size(); ++i) {
      demoted[i] = in_solve[i] && norms[i] >= fence && norms[i] > 0;
      if (in_solve[i] && !demoted[i]) map_->point(observations[i].id).position += displacements[i];
    }
    std::vector<std::optional<Eigen::Vector3d>> optimised(map_->size());
    std::vector<PointId> moved_by_neighbours, updated_ids;  // the demoted ones, and those left out of the solve
    for (size_t i = 0; i < observations.size(); ++i) {
      if (demoted[i] || !in_solve[i]) moved_by_neighbours.push_back(observations[i].id);
      if (!in_solve[i] || !inliers[i] || demoted[i]) continue;
      updated_ids.push_back(observations[i].id);
      optimised[static_cast<size_t>(observations[i].id)] = displacements[i];
    }
    map_->graph().UpdatePoints(updated_ids, map_->Positions());
    result->propagated = PropagateMotion(optimised, moved_by_neighbours);
    // A point left out of the solve is reported where its neighbours took it, if its track agrees.
    for (size_t i = 0; i < observations.size(); ++i) {
      if (in_solve[i]) continue;
      inliers[i] = ReprojectsWithinChi2(pose, map_->point(observations[i].id).position, observations[i].pixel,
                                        deformation_.reprojection_sigma_px);
    }
    for (size_t id = 0; id < point_motion_.size(); ++id) {
      point_motion_[id] = map_->points()[id].position - point_motion_[id];
    }
  }
  result->ms_deformation = MillisecondsSince(deformation_start);
  return std::nullopt;
}

FrameResult Tracker::Track(int frame, const cv::Mat& bgr, const cv::Mat& mask, const cv::Mat& next_bgr) {
  const auto start = Clock::now();
  FrameResult result;
  result.frame = frame;
  if (state_ != TrackingState::kTracking) return Lost(result, "no map to track");

  // Short-term association, from the look-ahead the previous frame ran if it ran on this image.
  const cv::Mat grey = ToGrey(bgr);
  std::optional<Lookahead> ahead = std::exchange(lookahead_, std::nullopt);
  if (ahead && !SameImage(ahead->grey, grey)) ahead.reset();
  const auto pyramid = ahead ? ahead->pyramid : std::make_shared<const ImagePyramid>(grey, frontend_.klt.levels);
  // Its pyramid still serves; its matches do not once the reference patches have been replaced.
  const bool matches_ahead = ahead && ahead->reference_generation == reference_generation_;
  const std::vector<cv::Point2f> guesses = KltGuesses();
  std::vector<KltResult> matches;
  MatchTracks(*pyramid, guesses, matches_ahead ? &*ahead : nullptr, &matches);
  if (ahead) result.ms_klt_ahead = ahead->ms;
  // An image that matches too few of the map's tracks (blank, saturated, washed out) is skipped
  // before anything here changes: the next frame starts from where the last tracked one left them.
  map_tracks_.clear();
  for (size_t i = 0; i < tracks_.size(); ++i) {
    if (!tracks_[i].active || tracks_[i].id == kNoPoint) continue;
    map_tracks_.push_back({matches[i].status == KltStatus::kTracked, matches[i].ssim, matches[i].gain});
  }
  const bool dropout = dropouts_.Skip(map_tracks_, options_.min_points);
  result.note = dropouts_.Note("points tracked", ", the map kept");
  result.sudden_occlusion = dropouts_.SuddenOcclusion();
  if (dropout) {
    result.state = TrackingState::kLost;
    result.dropout = true;
    result.klt_tracked = dropouts_.found();
    result.ms_klt = MillisecondsSince(start);
    result.ms_total = result.ms_klt;
    return result;
  }
  std::vector<Observation> observations;
  lost_now_.clear();
  flows_px_.clear();
  for (size_t i = 0; i < tracks_.size(); ++i) {
    if (!tracks_[i].active) continue;
    if (matches[i].status != KltStatus::kTracked) {
      tracks_[i].pixel = guesses[i];  // where the KLT looked for it
      if (LoseTrack(&tracks_[i], frame, result.sudden_occlusion)) lost_now_.push_back(tracks_[i].id);
      continue;
    }
    if (tracks_[i].id != kNoPoint) flows_px_.push_back(cv::norm(matches[i].position - tracks_[i].pixel));
    tracks_[i].pixel = matches[i].position;
    if (tracks_[i].id == kNoPoint) {
      result.candidates.push_back({tracks_[i].track_id, tracks_[i].pixel});
      continue;
    }
    observations.push_back({i, tracks_[i].id, Eigen::Vector2d(matches[i].position.x, matches[i].position.y)});
  }
  NoteViewJump(&result);
  result.klt_tracked = static_cast<int>(observations.size());
  MarkHiddenLosses(frame);
  result.ms_klt = MillisecondsSince(start);
  if (static_cast<int>(observations.size()) < options_.min_points) {
    return Lost(result, "only " + std::to_string(observations.size()) + " points tracked");
  }

  // Pose and deformation; beside them, on the other core, the next frame's pyramid and KLT
  // from the tracks as they are now, and this frame's validity mask, which re-association will
  // most likely need. (On a frame that refreshes the reference only the pyramid will serve.)
  FrameSolution solution;
  std::optional<std::string> lost;
  const auto solve = [&] { lost = SolvePoseAndDeformation(&observations, &solution, &result); };
  cv::Mat valid;
  // Not in rigid mode: its pose-only solve is shorter than the KLT on one core, which it would wait for.
  if (options_.klt_lookahead && !options_.rigid && !next_bgr.empty()) {
    Lookahead next;
    const auto run_ahead = [&, guesses = KltGuesses()] {
      next = RunAhead(next_bgr, guesses, reference_generation_);
      valid = BuildValidityMask(grey, mask, frontend_.masks);
    };
    RunConcurrently(run_ahead, solve);
    lookahead_ = std::move(next);
  } else {
    solve();
  }
  if (lost) return Lost(result, *lost);
  const Rigid3& pose = solution.pose;
  const std::vector<bool>& inliers = solution.inliers;
  const std::vector<bool>& demoted = solution.demoted;

  for (size_t i = 0; i < observations.size(); ++i) {
    // An outlier sits this frame out but stays a 2D track: the KLT keeps following it and it
    // re-enters the next frame's problem (the reference's demotion to TRACKED and re-use).
    // Only a point the graph has cut loose is dropped for good.
    if (!options_.rigid && map_->graph().IsWeaklyConnected(observations[i].id)) {
      tracks_[observations[i].track].active = false;
      ++result.outliers;
      continue;
    }
    if (!inliers[i] || demoted[i]) {
      ++result.outliers;
      continue;
    }
    result.points.push_back({observations[i].id, tracks_[observations[i].track].pixel});
  }
  motion_ = pose * cam_from_world_.Inverse();
  cam_from_world_ = pose;
  ForgetLostPoints(frame);
  // One validity mask per frame, shared by re-association and a reference refresh.
  const bool refresh = frames_since_keyframe_ + 1 >= options_.keyframe_period;
  const bool search = options_.reassociation && !lost_.empty();
  if ((search || refresh) && valid.empty()) valid = BuildValidityMask(grey, mask, frontend_.masks);
  if (search) {
    // A point the KLT lost where the mask now is was hidden, not lost to its own failure.
    for (PointId id : lost_now_) {
      const auto entry = lost_.find(id);  // not if forgotten since
      if (entry != lost_.end() && UnderMask(valid, entry->second.pixel)) entry->second.hidden = true;
    }
    Reassociate(*pyramid, valid, &result);
  }
  if (static_cast<int>(result.points.size()) < options_.min_points) {
    return Lost(result, "only " + std::to_string(result.points.size()) + " points left after outlier rejection");
  }
  if (++frames_since_keyframe_ >= options_.keyframe_period) {
    RefreshReference(frame, pyramid, valid, grey);
    result.keyframe = true;
    result.candidates.clear();  // the refresh may have dropped some and added new ones
    for (const PointTrack& track : tracks_) {
      if (track.active && track.id == kNoPoint) result.candidates.push_back({track.track_id, track.pixel});
    }
  }
  result.state = state_;
  result.cam_from_world = cam_from_world_;
  result.ms_total = MillisecondsSince(start);
  return result;
}

}  // namespace nrslam
