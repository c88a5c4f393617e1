// Mapper: keyframes, the temporal buffer and the sliding-window DBA with its model selection;
// new points are in mapper_triangulation.cc.
#include "nrslam/mapping/mapper.h"

#include <utility>

#include "nrslam/camera/reprojection_cost.h"
#include "nrslam/util/median.h"
#include "nrslam/util/stopwatch.h"

namespace nrslam {

Mapper::Mapper(const Camera& camera, const FrontendOptions& frontend, const DeformationModelOptions& deformation,
               const MappingOptions& options, bool rigid)
    : camera_(camera), frontend_(frontend), deformation_(deformation), options_(options), rigid_(rigid) {
  options_.Check();
}

Keyframe Mapper::MakeKeyframe(const FrameResult& result, const Tracker& tracker) const {
  Keyframe keyframe;
  keyframe.frame = result.frame;
  keyframe.cam_from_world = result.cam_from_world;
  for (const TrackedPoint& point : result.points) {
    keyframe.ids.push_back(point.id);
    keyframe.pixels.push_back(Eigen::Vector2d(point.pixel.x, point.pixel.y));
    keyframe.positions.push_back(tracker.map().point(point.id).position);
  }
  return keyframe;
}

void Mapper::Record(const FrameResult& result, const Tracker& tracker) {
  Snapshot snapshot;
  snapshot.frame = result.frame;
  snapshot.cam_from_world = result.cam_from_world;
  snapshot.median_displacement = result.median_displacement;
  for (const TrackedPoint& point : result.points) {
    snapshot.points.emplace(point.id, std::make_pair(point.pixel, tracker.map().point(point.id).position));
  }
  for (const CandidateObservation& candidate : result.candidates) snapshot.candidates.emplace(candidate.track_id, candidate.pixel);
  buffer_.push_back(std::move(snapshot));
  while (static_cast<int>(buffer_.size()) > options_.temporal_window + 1) buffer_.pop_front();
}

void Mapper::StartMap(const FrameResult& start, const Tracker& tracker, const std::optional<Keyframe>& reference) {
  pending_dba_.reset();  // an adjustment of the old map (waits for it to end)
  buffer_.clear();
  keyframes_.clear();
  if (reference) keyframes_.push_back(*reference);
  keyframes_.push_back(MakeKeyframe(start, tracker));
  map_keyframes_ = static_cast<int>(keyframes_.size());
  two_view_map_ = reference.has_value();
  start_points_ = static_cast<int>(start.points.size());
  Record(start, tracker);
}

MappingReport Mapper::Process(const FrameResult& result, const cv::Mat& bgr, const cv::Mat& mask, Tracker* tracker) {
  MappingReport report;
  Record(result, *tracker);
  if (pending_dba_ && (result.frame >= pending_dba_->apply_frame || result.keyframe)) {
    FinishDba(result.frame, tracker, &report);
  }
  if (result.keyframe) {
    keyframes_.push_back(MakeKeyframe(result, *tracker));
    ++map_keyframes_;
    while (static_cast<int>(keyframes_.size()) > options_.dba_window) keyframes_.pop_front();
    if (options_.dba && static_cast<int>(keyframes_.size()) >= options_.dba_min_keyframes) {
      StartDba(result.frame, tracker, &report);
    }
  } else {
    Triangulate(result, bgr, mask, tracker, &report);
  }
  return report;
}

std::vector<PointId> Mapper::WindowPoints() const {
  std::vector<PointId> ids;
  for (const Keyframe& keyframe : keyframes_) ids.insert(ids.end(), keyframe.ids.begin(), keyframe.ids.end());
  return ids;
}

namespace {

std::vector<Keyframe*> Pointers(std::deque<Keyframe>* keyframes) {
  std::vector<Keyframe*> pointers;
  for (Keyframe& keyframe : *keyframes) pointers.push_back(&keyframe);
  return pointers;
}

}  // namespace

double Mapper::InlierFraction(const std::deque<Keyframe>& keyframes) const {
  int observations = 0, inliers = 0;
  for (const Keyframe& keyframe : keyframes) {
    for (size_t i = 0; i < keyframe.ids.size(); ++i, ++observations) {
      inliers += SquaredReprojectionError(camera_, keyframe.cam_from_world, keyframe.positions[i], keyframe.pixels[i]) <=
                 options_.max_reprojection_px2;
    }
  }
  return observations > 0 ? static_cast<double>(inliers) / observations : 0.0;
}

double Mapper::BaselineRatio(const std::deque<Keyframe>& keyframes) const {
  const Keyframe& newest = keyframes.back();
  std::vector<double> depths;
  for (const Eigen::Vector3d& x : newest.positions) depths.push_back((newest.cam_from_world * x).z());
  if (depths.empty()) return 0;
  const double travel = (newest.cam_from_world.Inverse().translation -
                         keyframes.front().cam_from_world.Inverse().translation).norm();
  return travel / Median(depths);
}

double Mapper::TrackedDeformation(int since_frame, double map_scale) const {
  std::vector<double> deformations;
  for (const Snapshot& snapshot : buffer_) {
    if (snapshot.frame >= since_frame) deformations.push_back(snapshot.median_displacement / map_scale);
  }
  return deformations.empty() ? -1 : Median(deformations);
}

void Mapper::StartDba(int frame, Tracker* tracker, MappingReport* report) {
  const auto start = Clock::now();
  const Map& map = tracker->map();
  const bool warmup = !rigid_ && two_view_map_ && map_keyframes_ <= options_.rigid_warmup_keyframes;
  WindowModel model = WindowModel::kSelected;
  if (rigid_ || (warmup && options_.rigid_warmup_min_inliers == 0)) {
    model = WindowModel::kRigid;
  } else if (warmup) {
    model = WindowModel::kRigidIfInliers;
  }
  DbaRegularisers regularisers =
      model == WindowModel::kRigid ? DbaRegularisers{} : WindowRegularisers(map.graph(), Pointers(&keyframes_));
  PendingDba pending;
  pending.keyframe_frame = frame;
  pending.apply_frame = frame + options_.dba_lag_frames;
  pending.newest_before = keyframes_.back();
  // The job owns its copy of the window, which it adjusts and hands back.
  auto adjust = [this, keyframes = keyframes_, regularisers = std::move(regularisers), scale = map.scale(), model,
                 deformation = two_view_map_ || options_.rigid_dba_max_deformation == 0
                                   ? -1.0
                                   : TrackedDeformation(keyframes_.front().frame, map.scale())]() mutable {
    return AdjustWindow(std::move(keyframes), regularisers, scale, model, deformation);
  };
  // Deferred: run by FinishDba on this thread.
  pending.adjusted =
      std::async(options_.dba_lag_frames > 0 ? std::launch::async : std::launch::deferred, std::move(adjust));
  pending_dba_ = std::move(pending);
  report->ms_dba += MillisecondsSince(start);
  if (options_.dba_lag_frames == 0) FinishDba(frame, tracker, report);
}

Mapper::AdjustedWindow Mapper::AdjustWindow(std::deque<Keyframe> keyframes, const DbaRegularisers& regularisers,
                                            double map_scale, WindowModel model, double tracked_deformation) const {
  AdjustedWindow result;
  bool rigid_shape = model == WindowModel::kRigid;
  bool adjusted = false;
  double baseline_ratio = -1, rigid_inlier_fraction = -1;  // not measured
  // A rigid adjustment of the window, kept when this fraction of it reprojects well.
  const auto try_rigid = [&](double min_inliers) {
    std::deque<Keyframe> trial = keyframes;
    const DbaReport rigid_report = DeformableBundleAdjustment(camera_, deformation_, {}, map_scale,
                                                              options_.dba_iterations, true, Pointers(&trial));
    rigid_inlier_fraction = InlierFraction(trial);
    if (rigid_inlier_fraction < min_inliers) return;
    keyframes = std::move(trial);
    result.report = rigid_report;
    rigid_shape = adjusted = true;
  };
  if (model == WindowModel::kRigidIfInliers) {
    try_rigid(options_.rigid_warmup_min_inliers);
  } else if (model == WindowModel::kSelected && options_.dba_model_selection) {
    // The tracked camera travel, before any adjustment: a short baseline leaves a rigid fit
    // free to turn deformation into depth error, however well it reprojects.
    baseline_ratio = BaselineRatio(keyframes);
    const bool still = tracked_deformation < 0 || tracked_deformation <= options_.rigid_dba_max_deformation;
    if (baseline_ratio >= options_.rigid_dba_min_baseline && still) try_rigid(options_.rigid_dba_min_inliers);
  }
  if (!adjusted) {
    result.report = DeformableBundleAdjustment(camera_, deformation_, regularisers, map_scale, options_.dba_iterations,
                                               rigid_shape, Pointers(&keyframes));
  }
  result.report.rigid = rigid_shape;
  result.report.baseline_ratio = baseline_ratio;
  result.report.rigid_inlier_fraction = rigid_inlier_fraction;
  result.report.tracked_deformation = tracked_deformation;
  result.keyframes = std::move(keyframes);
  return result;
}

void Mapper::FinishDba(int frame, Tracker* tracker, MappingReport* report) {
  const auto start = Clock::now();
  PendingDba pending = std::move(*pending_dba_);
  pending_dba_.reset();
  AdjustedWindow adjusted = pending.adjusted.get();
  report->dba_report = adjusted.report;
  report->dba = true;
  // The newest keyframe's shape and pose are what tracking goes on from. When frames were
  // tracked since, their motion is kept on top: a point becomes its adjusted position plus
  // how far tracking moved it after the keyframe, and the camera keeps its pose relative to
  // the keyframe's (both exact no-ops when the result is applied on the keyframe itself).
  const Keyframe& before = pending.newest_before;
  const Keyframe& after = adjusted.keyframes.back();
  std::unordered_map<PointId, size_t> index;
  for (size_t i = 0; i < after.ids.size(); ++i) index.emplace(after.ids[i], i);
  const auto corrected = [&](PointId id, const Eigen::Vector3d& position) {
    const size_t i = index.at(id);
    return Eigen::Vector3d(after.positions[i] + (position - before.positions[i]));
  };
  const auto corrected_pose = [&](const Rigid3& cam_from_world, int at_frame) {
    return at_frame == pending.keyframe_frame ? after.cam_from_world
                                              : cam_from_world * before.cam_from_world.Inverse() * after.cam_from_world;
  };
  Map& map = tracker->mutable_map();
  for (const PointId id : after.ids) map.point(id).position = corrected(id, map.point(id).position);
  for (Snapshot& snapshot : buffer_) {
    if (snapshot.frame < pending.keyframe_frame) continue;
    for (const PointId id : after.ids) {
      const auto found = snapshot.points.find(id);
      if (found != snapshot.points.end()) found->second.second = corrected(id, found->second.second);
    }
    snapshot.cam_from_world = corrected_pose(snapshot.cam_from_world, snapshot.frame);
  }
  if (adjusted.report.rigid && !rigid_) map.graph().ResetRestShape(after.ids, map.Positions());
  tracker->SetPose(corrected_pose(tracker->pose(), frame));
  keyframes_ = std::move(adjusted.keyframes);
  report->ms_dba += MillisecondsSince(start);
}

}  // namespace nrslam
