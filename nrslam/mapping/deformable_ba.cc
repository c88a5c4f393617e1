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

DbaRegularisers WindowRegularisers(const DeformationGraph& graph, const std::vector<Keyframe*>& window) {
  // Point id → index per keyframe. Pairs come out in the iteration order of these maps, which
  // fixes the order of the adjustment's residual blocks and so its floating-point sums.
  std::vector<std::unordered_map<PointId, size_t>> index(window.size());
  for (size_t k = 0; k < window.size(); ++k) {
    for (size_t i = 0; i < window[k]->ids.size(); ++i) index[k][window[k]->ids[i]] = i;
  }
  DbaRegularisers regularisers(window.size());
  for (size_t k = 0; k < window.size(); ++k) {
    const auto index_next = [&](PointId id) {
      if (k + 1 >= window.size()) return -1;
      const auto found = index[k + 1].find(id);
      return found == index[k + 1].end() ? -1 : static_cast<int>(found->second);
    };
    std::vector<PointId> ids;
    std::vector<size_t> keyframe_index;  // of ids[n] in window[k]
    for (const auto& [id, i] : index[k]) {
      ids.push_back(id);
      keyframe_index.push_back(i);
    }
    for (const GraphPair& graph_pair : graph.PairsAmong(ids)) {
      DbaPair pair;
      pair.i = keyframe_index[graph_pair.i];
      pair.j = keyframe_index[graph_pair.j];
      pair.rest_length = graph.edge(graph_pair.edge).rest_length;
      pair.weight_b = graph_pair.weight;
      pair.next_i = index_next(ids[graph_pair.i]);
      pair.next_j = index_next(ids[graph_pair.j]);
      if (pair.next_i < 0 || pair.next_j < 0) pair.next_i = pair.next_j = -1;
      regularisers[k].push_back(pair);
    }
  }
  return regularisers;
}

DbaReport DeformableBundleAdjustment(const Camera& camera, const DeformationModelOptions& options,
                                     const DbaRegularisers& regularisers, double map_scale, int iterations, bool rigid,
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
  // A position block per (keyframe, point), but in rigid mode every keyframe shares one block
  // per point (kept in `shared`, seeded from the newest keyframe that sees it).
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
      std::vector<Eigen::Vector3d>& positions = window[k]->positions;
      for (const DbaPair& pair : regularisers[k]) {
        if (options.elastic) {
          problem.AddResidualBlock(ElasticCost::Create(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                                       pair.rest_length, ElasticMultiplier(options, pair.rest_length)),
                                   nullptr, positions[pair.i].data(), positions[pair.j].data());
          ++report.residual_blocks;
        }
        if (options.viscous && pair.next_i >= 0) {
          std::vector<Eigen::Vector3d>& next = window[k + 1]->positions;
          problem.AddResidualBlock(ViscousKeyframeCost::Create(ViscousMultiplier(options, pair.weight_b, map_scale)),
                                   new ceres::HuberLoss(options.huber_deformation), positions[pair.i].data(),
                                   next[static_cast<size_t>(pair.next_i)].data(), positions[pair.j].data(),
                                   next[static_cast<size_t>(pair.next_j)].data());
          ++report.residual_blocks;
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
