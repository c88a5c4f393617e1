#include "nrslam/mapping/deformable_ba.h"

#include <ceres/loss_function.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <algorithm>
#include <set>
#include <unordered_map>

#include "nrslam/camera/reprojection_cost.h"
#include "nrslam/deformation/regularizer_costs.h"
#include "nrslam/geometry/se3_manifold.h"

namespace nrslam {

DbaReport DeformableBundleAdjustment(const Camera& camera, const DeformationModelOptions& options,
                                     const DeformationGraph& graph, double map_scale, int iterations, bool rigid,
                                     const std::vector<Keyframe*>& window) {
  DbaReport report;
  report.keyframes = static_cast<int>(window.size());
  if (window.size() < 2) return report;
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  Se3Manifold manifold;

  std::vector<PoseParams> poses;
  for (const Keyframe* keyframe : window) poses.push_back(keyframe->cam_from_world.ToParams());
  // Per keyframe: point id → its position block. In rigid mode every keyframe shares one
  // block per point (kept in `shared`, seeded from the newest keyframe that sees it).
  std::vector<std::unordered_map<PointId, double*>> blocks(window.size());
  std::unordered_map<PointId, Eigen::Vector3d> shared;
  if (rigid) {
    for (const Keyframe* keyframe : window) {
      for (size_t i = 0; i < keyframe->ids.size(); ++i) shared[keyframe->ids[i]] = keyframe->positions[i];
    }
  }
  std::set<PointId> points;
  for (size_t k = 0; k < window.size(); ++k) {
    problem.AddParameterBlock(poses[k].data(), kPoseParams, &manifold);
    Keyframe& keyframe = *window[k];
    for (size_t i = 0; i < keyframe.ids.size(); ++i) {
      double* block = rigid ? shared.at(keyframe.ids[i]).data() : keyframe.positions[i].data();
      // A shared position seeded from another keyframe can lie behind this one's camera when
      // the tissue moved in between; its residual would fail Ceres's first evaluation and
      // with it the whole solve, so that observation sits the adjustment out.
      if (rigid && !camera.Project(keyframe.cam_from_world * Eigen::Map<const Eigen::Vector3d>(block))) continue;
      blocks[k][keyframe.ids[i]] = block;
      points.insert(keyframe.ids[i]);
      problem.AddResidualBlock(CreateReprojectionCost(camera, keyframe.pixels[i], options.reprojection_sigma_px),
                               new ceres::HuberLoss(options.huber_reprojection), poses[k].data(), block);
      ++report.residual_blocks;
    }
  }
  problem.SetParameterBlockConstant(poses.front().data());
  report.points = static_cast<int>(points.size());

  if (!rigid) {
    for (size_t k = 0; k < window.size(); ++k) {
      const auto seen = [&](PointId id) { return blocks[k].count(id) > 0; };
      const auto seen_next = [&](PointId id) { return seen(id) && k + 1 < window.size() && blocks[k + 1].count(id) > 0; };
      std::set<std::pair<PointId, PointId>> done;
      for (const auto& [id, block] : blocks[k]) {
        for (const GraphNeighbour& neighbour : graph.BestNeighbours(id, seen)) {
          if (!done.insert(std::minmax(id, neighbour.id)).second) continue;
          const GraphEdge& edge = graph.edge(neighbour.edge);
          problem.AddResidualBlock(ElasticCost::Create(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), edge.rest_length,
                                                       ElasticMultiplier(options, edge.rest_length)),
                                   nullptr, block, blocks[k].at(neighbour.id));
          ++report.residual_blocks;
          if (seen_next(id) && seen_next(neighbour.id)) {
            problem.AddResidualBlock(ViscousKeyframeCost::Create(ViscousMultiplier(options, neighbour.weight, map_scale)),
                                     new ceres::HuberLoss(options.huber_deformation), block,
                                     blocks[k + 1].at(id), blocks[k].at(neighbour.id), blocks[k + 1].at(neighbour.id));
            ++report.residual_blocks;
          }
        }
      }
    }
  }

  ceres::Solver::Options solver;
  solver.max_num_iterations = iterations;
  solver.linear_solver_type = ceres::CGNR;
  solver.num_threads = 1;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  report.initial_cost = summary.initial_cost;
  report.final_cost = summary.final_cost;

  for (size_t k = 0; k < window.size(); ++k) {
    window[k]->cam_from_world = Rigid3::FromParams(poses[k].data());
    if (rigid) {
      for (size_t i = 0; i < window[k]->ids.size(); ++i) window[k]->positions[i] = shared.at(window[k]->ids[i]);
    }
  }
  return report;
}

}  // namespace nrslam
