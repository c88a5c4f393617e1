// Mapper, new points: candidate tracks triangulated rigidly (parallax and reprojection gates)
// and deformably (a trajectory per point tied to its tracked neighbours' flow, with the
// agreement and epipolar gates), the paper's model selection between the two sets, and the
// optional shading prior on the deformable ones' depth.
#include "nrslam/mapping/mapper.h"

#include <ceres/problem.h>
#include <ceres/solver.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <unordered_map>
#include <utility>
#include <vector>

#include "nrslam/camera/reprojection_cost.h"
#include "nrslam/deformation/regularizer_costs.h"
#include "nrslam/frontend/masks.h"
#include "nrslam/frontend/shading.h"
#include "nrslam/util/median.h"
#include "nrslam/util/stopwatch.h"

namespace nrslam {

Eigen::Vector3d Mapper::WorldRay(const CandidateTrack& track, size_t i) const {
  return track.frames[i]->cam_from_world.rotation.conjugate() * camera_.Unproject(track.pixels[i]).normalized();
}

double Mapper::EpipolarDeviationRatio(const CandidateTrack& track) const {
  const Rigid3 world_from_oldest = track.frames.front()->cam_from_world.Inverse();
  const Eigen::Vector3d oldest_bearing = camera_.Unproject(track.pixels.front()).normalized();
  double sum_squares = 0;
  int count = 0;
  for (size_t i = 1; i < track.frames.size(); ++i) {
    const Rigid3 current_from_oldest = track.frames[i]->cam_from_world * world_from_oldest;
    if (current_from_oldest.translation.squaredNorm() == 0) continue;  // no baseline, no epipolar plane
    // Summed as sines, then turned back into an angle: the rms angle for the small angles here.
    const double sine = std::sin(EpipolarAngle(EssentialFromPose(current_from_oldest), oldest_bearing,
                                               camera_.Unproject(track.pixels[i]).normalized()));
    sum_squares += sine * sine;
    ++count;
  }
  const Eigen::Vector3d oldest_ray = world_from_oldest.rotation * oldest_bearing;  // WorldRay(track, 0)
  const double parallax = std::acos(std::clamp(oldest_ray.dot(WorldRay(track, track.frames.size() - 1)), -1.0, 1.0));
  if (count == 0 || parallax == 0) return std::numeric_limits<double>::infinity();
  return std::asin(std::min(1.0, std::sqrt(sum_squares / count))) / parallax;
}

std::optional<Triangulated> Mapper::TriangulatePair(const CandidateTrack& track, size_t a, size_t b,
                                                    bool check_reprojection) const {
  const Snapshot& first = *track.frames[a];
  const Snapshot& last = *track.frames[b];
  const auto point = TriangulateMidpoint(first.cam_from_world.Inverse().translation, WorldRay(track, a),
                                         last.cam_from_world.Inverse().translation, WorldRay(track, b));
  if (!point || point->depth0 <= 0 || point->depth1 <= 0) return std::nullopt;
  if (check_reprojection &&
      (SquaredReprojectionError(camera_, first.cam_from_world, point->point, track.pixels[a]) >
          options_.max_reprojection_px2 ||
       SquaredReprojectionError(camera_, last.cam_from_world, point->point, track.pixels[b]) >
           options_.max_reprojection_px2)) {
    return std::nullopt;
  }
  return point;
}

std::optional<Triangulated> Mapper::TriangulateShortestSpan(const CandidateTrack& track, bool check_reprojection) const {
  // Enough parallax: an angle ≥ the minimum, i.e. a cosine ≤ its cosine (unit rays).
  const double max_cosine = std::cos(options_.deformable_min_parallax_px / camera_.MeanFocal());
  const size_t newest = track.frames.size() - 1;
  const Eigen::Vector3d newest_ray = WorldRay(track, newest);
  for (size_t a = newest; a-- > 0;) {
    if (WorldRay(track, a).dot(newest_ray) <= max_cosine) {
      return TriangulatePair(track, a, newest, check_reprojection);
    }
  }
  return std::nullopt;
}

std::optional<Eigen::Vector3d> Mapper::TriangulateRigid(const CandidateTrack& track,
                                                        const std::optional<Triangulated>& ends,
                                                        double map_scale) const {
  const int first = track.frames.front()->frame, last = track.frames.back()->frame;
  for (const Snapshot& snapshot : buffer_) {
    if (snapshot.frame >= first && snapshot.frame <= last &&
        snapshot.median_displacement > options_.rigidity_threshold * map_scale) {
      return std::nullopt;  // the tissue moved in between: two rays would not meet on it
    }
  }
  const double pixel_angle = 1.0 / camera_.MeanFocal();
  if (!ends || ends->parallax_rad < options_.rigid_min_parallax_px * pixel_angle ||
      ends->parallax_rad > options_.rigid_max_parallax_px * pixel_angle) {
    return std::nullopt;
  }
  return ends->point;
}

std::optional<Eigen::Vector3d> Mapper::TriangulateDeformable(const CandidateTrack& track,
                                                             const std::optional<Triangulated>& gate,
                                                             const std::vector<PointId>& neighbours,
                                                             double map_scale) const {
  const size_t n = track.frames.size();
  // Gate: a two-view rigid solution (mapping.deformable_gate_span) must be plausible, with parallax.
  if (!gate || gate->parallax_rad < options_.deformable_min_parallax_px / camera_.MeanFocal()) return std::nullopt;
  // Seed: each frame's ray at the mean distance of the neighbours seen in that frame.
  std::vector<Eigen::Vector3d> positions(n);
  std::vector<PoseParams> poses(n);
  for (size_t f = 0; f < n; ++f) {
    const Snapshot& snapshot = *track.frames[f];
    double distance = 0;
    int count = 0;
    for (PointId id : neighbours) {
      const auto it = snapshot.points.find(id);
      if (it == snapshot.points.end()) continue;
      distance += (snapshot.cam_from_world * it->second.second).norm();
      ++count;
    }
    if (count == 0) return std::nullopt;
    const Eigen::Vector3d in_camera = camera_.Unproject(track.pixels[f]).normalized() * (distance / count);
    positions[f] = snapshot.cam_from_world.Inverse() * in_camera;
    poses[f] = snapshot.cam_from_world.ToParams();
  }

  ceres::Problem problem;
  for (size_t f = 0; f < n; ++f) {
    problem.AddParameterBlock(poses[f].data(), kPoseParams);
    problem.SetParameterBlockConstant(poses[f].data());
    problem.AddResidualBlock(CreateReprojectionCost(camera_, track.pixels[f], deformation_.reprojection_sigma_px), nullptr,
                             poses[f].data(), positions[f].data());
  }
  // Neighbour flows between consecutive observations (the reference uses every pair of
  // frames: O(L²) terms that say the same thing once the consecutive ones hold).
  const double flow_sigma = options_.flow_sigma * map_scale;
  std::vector<std::vector<Eigen::Vector3d>> flows(n);
  for (size_t f = 0; f + 1 < n; ++f) {
    const Snapshot& a = *track.frames[f];
    const Snapshot& b = *track.frames[f + 1];
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (PointId id : neighbours) {
      const auto in_a = a.points.find(id);
      const auto in_b = b.points.find(id);
      if (in_a == a.points.end() || in_b == b.points.end()) continue;
      flows[f].push_back(in_b->second.second - in_a->second.second);
      mean += flows[f].back();
    }
    if (flows[f].empty()) continue;
    mean /= flows[f].size();
    problem.AddResidualBlock(NeighbourFlowCost::Create(mean, std::sqrt(flows[f].size()) / flow_sigma), nullptr,
                             positions[f].data(), positions[f + 1].data());
  }
  ceres::Solver::Options solver;
  solver.max_num_iterations = options_.deformable_iterations;
  solver.function_tolerance = options_.deformable_function_tolerance;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);

  int flow_terms = 0, flow_outliers = 0, reprojection_outliers = 0;
  for (size_t f = 0; f + 1 < n; ++f) {
    for (const Eigen::Vector3d& flow : flows[f]) {
      ++flow_terms;
      const Eigen::Vector3d residual = ((positions[f + 1] - positions[f]) - flow) / flow_sigma;
      if (residual.squaredNorm() > options_.flow_outlier_chi2) ++flow_outliers;
    }
  }
  const double sigma2 = deformation_.reprojection_sigma_px * deformation_.reprojection_sigma_px;
  for (size_t f = 0; f < n; ++f) {
    if (SquaredReprojectionError(camera_, track.frames[f]->cam_from_world, positions[f], track.pixels[f]) / sigma2 >
        options_.reprojection_outlier_chi2) {
      ++reprojection_outliers;
    }
  }
  if (flow_terms == 0 || 2 * flow_outliers > flow_terms || 2 * reprojection_outliers > static_cast<int>(n)) {
    return std::nullopt;
  }
  // The newest position, put exactly on the newest ray at its optimised distance.
  const Rigid3& newest = track.frames.back()->cam_from_world;
  const Eigen::Vector3d ray = camera_.Unproject(track.pixels.back()).normalized();
  const double along = ray.dot(newest * positions.back());
  if (!(along > 0) || !positions.back().allFinite()) return std::nullopt;
  return newest.Inverse() * (ray * along);
}

Mapper::CandidatePoints Mapper::TriangulateCandidate(const CandidateObservation& candidate,
                                                     const DeformableGate& gate, double map_scale) const {
  CandidatePoints points;
  const Snapshot& newest = buffer_.back();
  const double crowding2 = options_.crowding_radius_px * options_.crowding_radius_px;
  const double radius2 = options_.neighbour_radius_px * options_.neighbour_radius_px;
  // Crowding gate and neighbours: the nearest tracked 3D points in the image.
  std::vector<std::pair<double, PointId>> near;
  for (const auto& [id, observation] : newest.points) {
    const cv::Point2f offset = observation.first - candidate.pixel;
    const double distance2 = offset.dot(offset);
    if (distance2 < crowding2) return points;
    if (distance2 <= radius2) near.emplace_back(distance2, id);
  }
  if (near.empty()) return points;
  const size_t keep = std::min(near.size(), static_cast<size_t>(options_.neighbours));
  std::partial_sort(near.begin(), near.begin() + keep, near.end());
  std::vector<PointId> neighbours;
  for (size_t i = 0; i < keep; ++i) neighbours.push_back(near[i].second);

  CandidateTrack track;
  for (const Snapshot& snapshot : buffer_) {
    const auto it = snapshot.candidates.find(candidate.track_id);
    if (it == snapshot.candidates.end()) continue;
    track.frames.push_back(&snapshot);
    track.pixels.push_back(Eigen::Vector2d(it->second.x, it->second.y));
  }
  if (track.frames.size() < 2) return points;
  // A new point lies on the surface its neighbours span: its depth now is within
  // max_depth_ratio of theirs. Low parallax leaves a triangulated depth free to run off
  // (measured on lap-lobes: points at 4 % of the median depth, which then drag the map).
  const auto depth_now = [&](const Eigen::Vector3d& point) { return (newest.cam_from_world * point).z(); };
  double nearest = std::numeric_limits<double>::infinity(), farthest = 0;
  for (PointId id : neighbours) {
    const double z = depth_now(newest.points.at(id).second);
    nearest = std::min(nearest, z);
    farthest = std::max(farthest, z);
    points.neighbour_depth += z / static_cast<double>(neighbours.size());
  }
  const auto plausible = [&](const Eigen::Vector3d& point) {
    const double z = depth_now(point);
    return z * options_.max_depth_ratio >= nearest && z <= options_.max_depth_ratio * farthest;
  };
  const std::optional<Triangulated> ends = TriangulatePair(track, 0, track.frames.size() - 1);
  if (const auto point = TriangulateRigid(track, ends, map_scale); point && plausible(*point)) points.rigid = point;
  if (!rigid_ && options_.deformable_triangulation &&
      static_cast<int>(track.frames.size()) >= options_.deformable_min_track &&
      (gate.max_epipolar_ratio == 0 || EpipolarDeviationRatio(track) <= gate.max_epipolar_ratio)) {
    const std::optional<Triangulated> gate_pair =
        gate.shortest_span ? TriangulateShortestSpan(track, gate.check_reprojection) : ends;
    // The fit and the gate's two rays model the same point differently; where their depths
    // disagree, the fit's depth is mostly its seed (mapping.deformable_agreement_ratio).
    const auto agrees = [&](const Eigen::Vector3d& point) {
      const double ratio = gate.agreement_ratio, z = depth_now(point), two_ray_z = depth_now(gate_pair->point);
      return ratio == 0 || (z <= ratio * two_ray_z && two_ray_z <= ratio * z);
    };
    if (const auto point = TriangulateDeformable(track, gate_pair, neighbours, map_scale);
        point && plausible(*point) && agrees(*point)) {
      points.deformable = point;
    }
  }
  return points;
}

void Mapper::Triangulate(const FrameResult& result, const cv::Mat& bgr, const cv::Mat& mask, Tracker* tracker,
                         MappingReport* report) {
  const auto start = Clock::now();
  if (buffer_.size() < 2 || result.candidates.empty()) return;
  Map& map = tracker->mutable_map();
  const bool starving = two_view_map_ && static_cast<double>(result.points.size()) <
                                            options_.shortest_gate_below_fraction * static_cast<double>(start_points_);
  DeformableGate gate;
  gate.shortest_span = options_.deformable_gate_span == "shortest" || starving;
  gate.check_reprojection = !starving || options_.starving_two_ray_check;
  gate.agreement_ratio = starving ? 0 : options_.deformable_agreement_ratio;
  gate.max_epipolar_ratio = starving ? options_.starving_max_epipolar_ratio : options_.deformable_max_epipolar_ratio;
  // Each candidate is its own small problem: they are solved on every core, each into its own
  // slot, and gathered in candidate order, so the outcome is the same as one at a time.
  const int count = static_cast<int>(result.candidates.size());
  std::vector<CandidatePoints> solved(result.candidates.size());
#pragma omp parallel for schedule(dynamic, 4)
  for (int c = 0; c < count; ++c) solved[c] = TriangulateCandidate(result.candidates[c], gate, map.scale());
  std::vector<std::pair<int, Eigen::Vector3d>> rigid, deformable;  // track id, world position
  std::unordered_map<int, double> neighbour_depths;                  // by track id
  for (int c = 0; c < count; ++c) {
    neighbour_depths.emplace(result.candidates[c].track_id, solved[c].neighbour_depth);
    if (solved[c].rigid) rigid.emplace_back(result.candidates[c].track_id, *solved[c].rigid);
    if (solved[c].deformable) deformable.emplace_back(result.candidates[c].track_id, *solved[c].deformable);
  }
  report->rigid_candidates = static_cast<int>(rigid.size());
  report->deformable_candidates = static_cast<int>(deformable.size());
  const double factor = options_.model_selection_factor;
  std::vector<std::pair<int, Eigen::Vector3d>>* chosen = nullptr;
  if (rigid.size() > factor * deformable.size()) {
    chosen = &rigid;
  } else if (deformable.size() >= factor * rigid.size()) {
    chosen = &deformable;
  }
  if (chosen && !chosen->empty()) {
    std::unordered_map<int, cv::Point2f> pixels;
    for (const CandidateObservation& candidate : result.candidates) pixels.emplace(candidate.track_id, candidate.pixel);
    if (chosen == &deformable && options_.new_point_shading_weight > 0) {
      ApplyShadingPrior(bgr, mask, pixels, &deformable);
    }
    // The batch as a whole against the map it joins (mapping.max_batch_depth_bias): each
    // point's own gate allows its neighbours' whole depth range, so a batch can sit deeper or
    // nearer than the map as a group (an error of the poses shared by all its ray pairs), and
    // on lap-lobes one such batch decided a run. Turned away, its tracks stay candidates.
    std::vector<double> ratios;
    for (const auto& [track_id, position] : *chosen) {
      ratios.push_back((buffer_.back().cam_from_world * position).z() / neighbour_depths.at(track_id));
    }
    report->new_point_depth_bias = MedianInPlace(&ratios);
    const double limit = options_.max_batch_depth_bias;
    report->batch_rejected = limit > 0 && static_cast<int>(chosen->size()) >= options_.batch_check_min_points &&
                             (report->new_point_depth_bias > limit || report->new_point_depth_bias * limit < 1);
    if (!report->batch_rejected) {
      std::vector<PointId> created, existing;
      for (const TrackedPoint& point : result.points) existing.push_back(point.id);
      for (const auto& [track_id, position] : *chosen) {
        const cv::Point2f& pixel = pixels.at(track_id);
        const cv::Point at(std::clamp(cvRound(pixel.x), 0, bgr.cols - 1), std::clamp(cvRound(pixel.y), 0, bgr.rows - 1));
        const PointId id = map.AddPoint(position, bgr.at<cv::Vec3b>(at), result.frame);
        created.push_back(id);
        tracker->PromoteCandidate(track_id, id);
      }
      map.graph().ConnectCovisible(created, existing, map.Positions());
      report->new_points = static_cast<int>(created.size());
    }
  }
  report->ms_triangulation = MillisecondsSince(start);
}

void Mapper::ApplyShadingPrior(const cv::Mat& bgr, const cv::Mat& mask,
                               const std::unordered_map<int, cv::Point2f>& pixels,
                               std::vector<std::pair<int, Eigen::Vector3d>>* points) const {
  const cv::Mat grey = ToGrey(bgr);
  const cv::Mat valid = BuildValidityMask(grey, mask, frontend_.masks);
  // Calibration: the frame's tracked points (buffer_.back() is this frame), whose distances
  // the map holds.
  const Snapshot& now = buffer_.back();
  std::vector<cv::Point2f> tracked_pixels;
  ShadedPoints tracked;
  for (const auto& [id, observation] : now.points) {
    tracked_pixels.push_back(observation.first);
    tracked.distances.push_back((now.cam_from_world * observation.second).norm());
  }
  tracked.brightness = LinearBrightness(grey, valid, tracked_pixels, frontend_.shading);
  std::vector<cv::Point2f> new_pixels;
  std::vector<Eigen::Vector3d> in_camera;
  ShadedPoints created;
  for (const auto& [track_id, position] : *points) {
    new_pixels.push_back(pixels.at(track_id));
    in_camera.push_back(now.cam_from_world * position);
    created.distances.push_back(in_camera.back().norm());
  }
  created.brightness = LinearBrightness(grey, valid, new_pixels, frontend_.shading);
  const std::vector<double> blended = BlendWithShading(tracked, created, options_.new_point_shading_weight);
  const Rigid3 world_from_cam = now.cam_from_world.Inverse();
  for (size_t i = 0; i < points->size(); ++i) {
    (*points)[i].second = world_from_cam * (in_camera[i] * (blended[i] / created.distances[i]));
  }
}

}  // namespace nrslam
