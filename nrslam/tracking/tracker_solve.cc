// Tracker, one frame's solves: the rigid pose-only refinement with its outlier rounds, then
// (unless rigid) the joint Ceres problem of the pose and one displacement per point.
#include "nrslam/tracking/tracker.h"

#include <ceres/loss_function.h>
#include <ceres/normal_prior.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>

#include "nrslam/camera/reprojection_cost.h"
#include "nrslam/deformation/regularizer_costs.h"
#include "nrslam/geometry/se3_manifold.h"
#include "nrslam/util/median.h"
#include "nrslam/util/stopwatch.h"

namespace nrslam {
namespace {

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

}  // namespace

std::vector<Eigen::Vector3d> WithoutCommonMotion(std::vector<Eigen::Vector3d> motions) {
  if (motions.empty()) return motions;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& motion : motions) mean += motion;
  mean /= static_cast<double>(motions.size());
  for (Eigen::Vector3d& motion : motions) motion -= mean;
  return motions;
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
}  // namespace nrslam
