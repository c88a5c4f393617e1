#include "nrslam/tracking/tracker.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <utility>

#include "nrslam/eval/depth_evaluation.h"
#include "nrslam/frontend/feature_detector.h"
#include "nrslam/frontend/masks.h"
#include "nrslam/util/concurrent.h"
#include "nrslam/util/median.h"
#include "nrslam/util/stopwatch.h"
#include "nrslam/util/text_table.h"

namespace nrslam {
namespace {

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
