// Tracker, lost map points: a track lost this frame marked hidden when the view hid it, the
// solved motion propagated to lost and demoted points, points lost too long forgotten, and
// mid-term re-association of lost points by a KLT seeded at their projection.
#include "nrslam/tracking/tracker.h"

#include <algorithm>
#include <utility>

#include "nrslam/util/median.h"

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

}  // namespace

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
}  // namespace nrslam
