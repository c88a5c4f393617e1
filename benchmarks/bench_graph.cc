// The deformation graph's per-frame work on a graph the size of a depth-initialised sim-0 map:
// 600 points joined by a complete graph (179,700 edges), of which 180 are tracked in a frame
// and 420 lost. Per frame the tracker (1) picks the regularised pairs among the tracked points,
// (2) re-measures their edges after the solve and (3) moves each lost point by its best tracked
// neighbours. Each benchmark times one of the three on a surface that keeps deforming, so that
// lengths keep leaving their [d_min, d_max] and weights keep changing, as in a run.
#include <benchmark/benchmark.h>

#include <cmath>
#include <functional>
#include <optional>
#include <random>
#include <vector>

#include "nrslam/deformation/deformation_graph.h"

namespace {

using nrslam::PointId;

constexpr int kPoints = 600;
constexpr int kTrackedEvery = 10;  // ids with id % 10 < 3 are tracked: 180 of 600
constexpr double kSigma = 1.5;

class DeformingGraph {
 public:
  DeformingGraph() : graph(nrslam::DeformationModelOptions{}, kSigma), rest_(kPoints), now_(kPoints) {
    std::mt19937 random(7);
    std::normal_distribution<double> normal;
    for (auto& p : rest_) p = Eigen::Vector3d(normal(random), normal(random), 0.3 * normal(random));
    now_ = rest_;
    std::vector<PointId> all;
    for (PointId id = 0; id < kPoints; ++id) {
      all.push_back(id);
      ((id % kTrackedEvery) < 3 ? tracked : lost).push_back(id);
    }
    graph.ConnectCovisible(all, {}, Lookup());
  }

  // The surface one frame on: a travelling wave across it plus a little noise.
  void Advance() {
    ++frame_;
    for (size_t i = 0; i < rest_.size(); ++i) {
      const double wave = 0.2 * std::sin(0.1 * frame_ + rest_[i].x());
      now_[i] = rest_[i] + Eigen::Vector3d(0.01 * noise_(random_), 0.01 * noise_(random_), wave);
    }
  }

  nrslam::PositionLookup Lookup() const {
    return [this](PointId id) -> std::optional<Eigen::Vector3d> { return now_[static_cast<size_t>(id)]; };
  }
  bool IsTracked(PointId id) const { return (id % kTrackedEvery) < 3; }

  nrslam::DeformationGraph graph;
  std::vector<PointId> tracked, lost;

 private:
  std::vector<Eigen::Vector3d> rest_, now_;
  int frame_ = 0;
  std::mt19937 random_{11};
  std::normal_distribution<double> noise_;
};

void BM_GraphRemeasureTrackedEdges(benchmark::State& state) {
  DeformingGraph scene;
  for (auto _ : state) {
    state.PauseTiming();
    scene.Advance();
    state.ResumeTiming();
    scene.graph.UpdatePoints(scene.tracked, scene.Lookup());
  }
  state.counters["edges"] = static_cast<double>(scene.graph.edge_count());
  state.counters["pruned"] = static_cast<double>(scene.graph.pruned_count());
}

void BM_GraphPairsAmongTracked(benchmark::State& state) {
  DeformingGraph scene;
  size_t pairs = 0;
  for (auto _ : state) {
    state.PauseTiming();
    scene.Advance();
    scene.graph.UpdatePoints(scene.tracked, scene.Lookup());
    state.ResumeTiming();
    pairs = scene.graph.PairsAmong(scene.tracked).size();
    benchmark::DoNotOptimize(pairs);
  }
  state.counters["pairs"] = static_cast<double>(pairs);
}

void BM_GraphBestTrackedNeighboursOfLost(benchmark::State& state) {
  DeformingGraph scene;
  const std::function<bool(PointId)> is_tracked = [&](PointId id) { return scene.IsTracked(id); };
  for (auto _ : state) {
    state.PauseTiming();
    scene.Advance();
    scene.graph.UpdatePoints(scene.tracked, scene.Lookup());
    state.ResumeTiming();
    for (const PointId id : scene.lost) benchmark::DoNotOptimize(scene.graph.BestNeighbours(id, is_tracked).data());
  }
  state.counters["lost"] = static_cast<double>(scene.lost.size());
}

}  // namespace

BENCHMARK(BM_GraphRemeasureTrackedEdges)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GraphPairsAmongTracked)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GraphBestTrackedNeighboursOfLost)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
