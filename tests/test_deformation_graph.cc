#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <random>
#include <utility>

#include "nrslam/deformation/deformation_graph.h"
#include "nrslam/util/error.h"

namespace nrslam {
namespace {

struct Positions {
  std::map<PointId, Eigen::Vector3d> at;
  PositionLookup Lookup() const {
    return [this](PointId id) -> std::optional<Eigen::Vector3d> {
      const auto found = at.find(id);
      if (found == at.end()) return std::nullopt;
      return found->second;
    };
  }
  std::vector<PointId> Ids() const {
    std::vector<PointId> ids;
    for (const auto& entry : at) ids.push_back(entry.first);
    return ids;
  }
};

TEST(DeformationGraph, CreationJoinsCovisiblePointsWithTheirLengthsAndWeights) {
  DeformationModelOptions options;
  DeformationGraph graph(options, 2.0);
  Positions positions;
  positions.at = {{1, {0, 0, 0}}, {2, {1, 0, 0}}, {3, {0, 2, 0}}};
  graph.ConnectCovisible(positions.Ids(), {}, positions.Lookup());
  EXPECT_EQ(graph.edge_count(), 3u);
  const GraphEdge& edge = graph.edge(*graph.FindEdge(3, 1));
  EXPECT_DOUBLE_EQ(edge.rest_length, 2.0);
  EXPECT_DOUBLE_EQ(edge.weight, std::exp(-4.0 / 8.0));
  // A new point joins every existing point, not only its nearest.
  positions.at[4] = {5, 5, 0};
  graph.ConnectCovisible({4}, {1, 2, 3, 99}, positions.Lookup());  // 99 has no position: skipped
  EXPECT_EQ(graph.edge_count(), 6u);
  EXPECT_FALSE(graph.FindEdge(4, 99));
  // Adding an existing edge again changes nothing.
  graph.AddEdge(2, 1, 7.0);
  EXPECT_EQ(graph.edge_count(), 6u);
  EXPECT_DOUBLE_EQ(graph.edge(*graph.FindEdge(1, 2)).rest_length, 1.0);
}

TEST(DeformationGraph, EachPointUsesItsBestDEdgesByWeight) {
  DeformationModelOptions options;
  options.max_degree_D = 3;
  DeformationGraph graph(options, 4.0);
  Positions positions;
  positions.at[0] = {0, 0, 0};
  for (int i = 1; i <= 12; ++i) positions.at[i] = {0.5 * i, 0, 0};  // farther and farther
  graph.ConnectCovisible({0}, positions.Ids(), positions.Lookup());
  const auto best = graph.BestNeighbours(0);
  ASSERT_EQ(best.size(), 3u);
  EXPECT_EQ(best[0].id, 1);
  EXPECT_EQ(best[1].id, 2);
  EXPECT_EQ(best[2].id, 3);
  EXPECT_GT(best[0].weight, best[1].weight);
  // Edges with b below min_edge_weight (d_max > 1.5σ = 6) are never used, however many slots.
  options.max_degree_D = 100;
  DeformationGraph wide(options, 4.0);
  wide.ConnectCovisible({0}, positions.Ids(), positions.Lookup());
  EXPECT_EQ(wide.BestNeighbours(0).size(), 12u);  // 0.5 … 6.0: all within 1.5σ
  wide.set_sigma(2.0);                             // now only d <= 3 qualifies
  EXPECT_EQ(wide.BestNeighbours(0).size(), 6u);
}

// Equal weights are ranked by id, and a neighbour the caller rules out leaves its slot to the
// next best, however many better ones it outranks.
TEST(DeformationGraph, TiesGoToTheLowerIdAndIneligibleNeighboursLeaveTheirSlot) {
  DeformationModelOptions options;
  options.max_degree_D = 3;
  DeformationGraph graph(options, 4.0);
  Positions positions;
  positions.at[0] = {0, 0, 0};
  for (int i = 1; i <= 12; ++i) {  // all at distance 1 from point 0, in an order unlike their ids
    const double angle = 2.0 * M_PI * ((i * 5) % 12) / 12.0;
    positions.at[i] = {std::cos(angle), std::sin(angle), 0};
  }
  positions.at[13] = {0.5, 0, 0};  // the one nearer neighbour
  graph.ConnectCovisible({0}, positions.Ids(), positions.Lookup());
  const auto ids = [](const std::vector<GraphNeighbour>& best) {
    std::vector<PointId> out;
    for (const GraphNeighbour& neighbour : best) out.push_back(neighbour.id);
    return out;
  };
  EXPECT_EQ(ids(graph.BestNeighbours(0)), (std::vector<PointId>{13, 1, 2}));
  const auto odd_only = [](PointId id) { return id % 2 == 1; };
  EXPECT_EQ(ids(graph.BestNeighbours(0, odd_only)), (std::vector<PointId>{13, 1, 3}));
  const auto above_eight = [](PointId id) { return id > 8; };
  EXPECT_EQ(ids(graph.BestNeighbours(0, above_eight)), (std::vector<PointId>{13, 9, 10}));
  EXPECT_TRUE(graph.BestNeighbours(0, [](PointId) { return false; }).empty());
}

// Re-measuring a few points reaches every edge with one end among them and a position at the
// other, and no edge between two others.
TEST(DeformationGraph, UpdatingSomePointsMeasuresExactlyTheEdgesThatTouchThem) {
  DeformationModelOptions options;
  DeformationGraph graph(options, 10.0);
  Positions positions;
  positions.at = {{0, {0, 0, 0}}, {1, {1, 0, 0}}, {2, {0, 1, 0}}, {3, {1, 1, 0}}};
  graph.ConnectCovisible(positions.Ids(), {}, positions.Lookup());
  for (auto& [id, position] : positions.at) position *= 2.0;
  Positions without_three = positions;
  without_three.at.erase(3);
  graph.UpdatePoints({1, 0}, without_three.Lookup());
  const auto longest = [&](PointId a, PointId b) { return graph.edge(*graph.FindEdge(a, b)).max_length; };
  EXPECT_DOUBLE_EQ(longest(0, 1), 2.0);
  EXPECT_DOUBLE_EQ(longest(0, 2), 2.0);
  EXPECT_DOUBLE_EQ(longest(1, 2), 2.0 * std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(longest(0, 3), std::sqrt(2.0));  // no position for 3: untouched
  EXPECT_DOUBLE_EQ(longest(2, 3), 1.0);             // neither end listed
}

// The pairs a solver regularises among a subset of the points: exactly the union of each
// listed point's best D edges to other listed points, each pair once, in first-use order.
TEST(DeformationGraph, PairsAmongListedPointsAreTheirBestEdgesEachOnce) {
  DeformationModelOptions options;
  options.max_degree_D = 3;
  DeformationGraph graph(options, 2.0);
  Positions positions;
  std::mt19937 random(11);
  std::uniform_real_distribution<double> coordinate(0.0, 3.0);
  for (PointId id = 0; id < 30; ++id) positions.at[id] = {coordinate(random), coordinate(random), 0.0};
  graph.ConnectCovisible(positions.Ids(), {}, positions.Lookup());
  const std::vector<PointId> listed = {17, 3, 25, 8, 0, 12, 29, 21, 5, 14};  // not sorted: order is the caller's
  const auto is_listed = [&](PointId id) { return std::count(listed.begin(), listed.end(), id) > 0; };
  const auto unordered = [](PointId a, PointId b) { return std::make_pair(std::min(a, b), std::max(a, b)); };
  std::vector<std::pair<PointId, PointId>> expected;  // unordered pairs in order of first use
  for (const PointId id : listed) {
    for (const GraphNeighbour& neighbour : graph.BestNeighbours(id, is_listed)) {
      const auto key = unordered(id, neighbour.id);
      if (std::find(expected.begin(), expected.end(), key) == expected.end()) expected.push_back(key);
    }
  }
  const std::vector<GraphPair> pairs = graph.PairsAmong(listed);
  ASSERT_EQ(pairs.size(), expected.size());
  ASSERT_LT(pairs.size(), listed.size() * 3);  // some pairs were chosen from both ends
  for (size_t p = 0; p < pairs.size(); ++p) {
    const PointId a = listed[pairs[p].i], b = listed[pairs[p].j];
    EXPECT_EQ(unordered(a, b), expected[p]);
    const GraphEdge& edge = graph.edge(pairs[p].edge);
    EXPECT_EQ(unordered(edge.a, edge.b), expected[p]);
    EXPECT_EQ(pairs[p].weight, edge.weight);
  }
  EXPECT_TRUE(graph.PairsAmong({}).empty());
  EXPECT_THROW(graph.PairsAmong({1, kNoPoint}), Error);
}

// Two clusters that separate (the lap-lobes situation): every edge across is pruned, none within.
TEST(DeformationGraph, PrunesEdgesBetweenSeparatingClusters) {
  DeformationModelOptions options;
  DeformationGraph graph(options, 10.0);
  Positions positions;
  for (int i = 0; i < 8; ++i) {
    positions.at[i] = {0.3 * (i % 4), 0.3 * (i / 4), 0};       // cluster A
    positions.at[100 + i] = {2.0 + 0.3 * (i % 4), 0.3 * (i / 4), 0};  // cluster B
  }
  graph.ConnectCovisible(positions.Ids(), {}, positions.Lookup());
  const size_t edges = graph.edge_count();
  EXPECT_EQ(edges, 16u * 15u / 2u);
  for (int step = 1; step <= 30; ++step) {  // B slides away rigidly
    for (int i = 0; i < 8; ++i) positions.at[100 + i].x() += 0.2;
    graph.UpdatePoints(positions.Ids(), positions.Lookup());
  }
  size_t across_pruned = 0, within_pruned = 0;
  for (const int e : graph.EdgeIndices()) {
    const GraphEdge& edge = graph.edge(e);
    const bool across = (edge.a < 100) != (edge.b < 100);
    (across ? across_pruned : within_pruned) += edge.pruned ? 1 : 0;
  }
  EXPECT_EQ(across_pruned, 64u);
  EXPECT_EQ(within_pruned, 0u);
  EXPECT_EQ(graph.pruned_count(), 64u);
  for (const PointId id : positions.Ids()) {
    EXPECT_EQ(graph.GoodEdgeCount(id), 7);
    EXPECT_FALSE(graph.IsWeaklyConnected(id));
    for (const auto& neighbour : graph.BestNeighbours(id)) EXPECT_EQ(neighbour.id < 100, id < 100);
  }
}

TEST(DeformationGraph, WeightFollowsTheLongestLengthEverSeen) {
  DeformationModelOptions options;
  DeformationGraph graph(options, 1.0);
  Positions positions;
  positions.at = {{1, {0, 0, 0}}, {2, {1, 0, 0}}};
  graph.ConnectCovisible({1, 2}, {}, positions.Lookup());
  positions.at[2] = {1.5, 0, 0};
  graph.UpdatePoints({1}, positions.Lookup());
  positions.at[2] = {1.0, 0, 0};  // back to rest: the weight does not recover
  graph.UpdatePoints({2}, positions.Lookup());
  const GraphEdge& edge = graph.edge(0);
  EXPECT_DOUBLE_EQ(edge.max_length, 1.5);
  EXPECT_DOUBLE_EQ(edge.min_length, 1.0);
  EXPECT_DOUBLE_EQ(edge.weight, std::exp(-1.5 * 1.5 / 2.0));
  EXPECT_FALSE(edge.pruned);  // stretch 0.5 < 1.1
  positions.at[2] = {0.4, 0, 0};  // d_min 0.4: (1.5 − 0.4)/0.4 = 2.75 > 1.1
  graph.UpdatePoints({2}, positions.Lookup());
  EXPECT_TRUE(graph.edge(0).pruned);
}

TEST(DeformationGraph, ResettingTheRestShapeTouchesOnlyEdgesAmongTheGivenPoints) {
  DeformationModelOptions options;
  DeformationGraph graph(options, 2.0);
  Positions positions;
  positions.at = {{1, {0, 0, 0}}, {2, {1, 0, 0}}, {3, {0, 2, 0}}};
  graph.ConnectCovisible(positions.Ids(), {}, positions.Lookup());
  positions.at[2] = {3, 0, 0};  // re-estimated structure: 1–2 is now 3 long, 2–3 √13
  positions.at[3] = {0, 4, 0};  // 3 is not reset: its edges keep their lengths
  graph.ResetRestShape({1, 2}, positions.Lookup());
  const GraphEdge& reset = graph.edge(*graph.FindEdge(1, 2));
  EXPECT_DOUBLE_EQ(reset.rest_length, 3.0);
  EXPECT_DOUBLE_EQ(reset.min_length, 3.0);
  EXPECT_DOUBLE_EQ(reset.max_length, 3.0);
  EXPECT_DOUBLE_EQ(reset.weight, std::exp(-9.0 / 8.0));
  EXPECT_DOUBLE_EQ(graph.edge(*graph.FindEdge(1, 3)).rest_length, 2.0);
  EXPECT_DOUBLE_EQ(graph.edge(*graph.FindEdge(2, 3)).rest_length, std::sqrt(5.0));
}

// Ids are map indices: a negative one or one beyond 2³¹ is refused when an edge is made and
// finds no edge, rather than aliasing another pair.
TEST(DeformationGraph, IdsOutsideTheMapIndexRangeAreRefused) {
  DeformationModelOptions options;
  DeformationGraph graph(options, 1.0);
  graph.AddEdge(1, 2, 0.5);
  EXPECT_THROW(graph.AddEdge(-3, 2, 0.5), Error);
  EXPECT_THROW(graph.AddEdge(1, PointId{1} << 31, 0.5), Error);
  EXPECT_TRUE(graph.FindEdge(2, 1));
  EXPECT_FALSE(graph.FindEdge(2, 1 + (PointId{1} << 32)));
  EXPECT_FALSE(graph.FindEdge(-1, 2));
  EXPECT_EQ(graph.edge_count(), 1u);
}

TEST(DeformationGraph, FlagsPointsLeftWithTooFewEdges) {
  DeformationModelOptions options;
  options.min_good_edges = 2;
  DeformationGraph graph(options, 5.0);
  Positions positions;
  positions.at = {{1, {0, 0, 0}}, {2, {1, 0, 0}}, {3, {0, 1, 0}}};
  graph.ConnectCovisible(positions.Ids(), {}, positions.Lookup());
  EXPECT_FALSE(graph.IsWeaklyConnected(1));
  positions.at[1] = {-5, -5, 0};  // point 1 tears away from both
  graph.UpdatePoints({1}, positions.Lookup());
  EXPECT_EQ(graph.GoodEdgeCount(1), 0);
  EXPECT_TRUE(graph.IsWeaklyConnected(1));
  EXPECT_THROW(graph.set_sigma(0.0), Error);
}

// The graph keeps per-point counts and a packed copy of the weights for speed; after any
// sequence of updates they must say what the edge records themselves say.
// The point's unpruned-edge count and best D edges, worked out from the edge records alone.
void ExpectCountsAndBestEdgesFromTheRecords(const DeformationGraph& graph, const DeformationModelOptions& options,
                                            PointId id) {
  int unpruned = 0;
  std::vector<std::pair<double, PointId>> usable;
  for (const int e : graph.EdgeIndices()) {
    const GraphEdge& edge = graph.edge(e);
    if (edge.a != id && edge.b != id) continue;
    if (!edge.pruned) ++unpruned;
    if (!edge.pruned && edge.weight >= options.min_edge_weight) {
      usable.emplace_back(-edge.weight, edge.a == id ? edge.b : edge.a);
    }
  }
  EXPECT_EQ(graph.GoodEdgeCount(id), unpruned) << "point " << id;
  std::sort(usable.begin(), usable.end());
  usable.resize(std::min<size_t>(usable.size(), static_cast<size_t>(options.max_degree_D)));
  const auto best = graph.BestNeighbours(id);
  ASSERT_EQ(best.size(), usable.size()) << "point " << id;
  for (size_t i = 0; i < best.size(); ++i) {
    EXPECT_EQ(best[i].id, usable[i].second) << "point " << id;
    EXPECT_EQ(best[i].weight, -usable[i].first) << "point " << id;
  }
}

TEST(DeformationGraph, CountsAndBestEdgesAgreeWithTheEdgeRecordsAfterUpdates) {
  DeformationModelOptions options;
  options.max_degree_D = 4;
  options.stretch_threshold = 0.3;
  DeformationGraph graph(options, 1.5);
  Positions positions;
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(0.0, 3.0), jitter(-0.25, 0.25);
  for (PointId id = 0; id < 40; ++id) positions.at[id] = {coordinate(random), coordinate(random), coordinate(random)};
  graph.ConnectCovisible(positions.Ids(), {}, positions.Lookup());
  for (int step = 0; step < 12; ++step) {
    for (auto& [id, position] : positions.at) position += Eigen::Vector3d(jitter(random), jitter(random), jitter(random));
    graph.UpdatePoints(positions.Ids(), positions.Lookup());
    if (step == 5) graph.set_sigma(1.0);
    if (step == 8) graph.ResetRestShape({0, 1, 2, 3, 4, 5}, positions.Lookup());
  }
  ASSERT_GT(graph.pruned_count(), 0u);
  ASSERT_LT(graph.pruned_count(), graph.edge_count());
  for (const PointId id : positions.Ids()) ExpectCountsAndBestEdgesFromTheRecords(graph, options, id);
}

TEST(DeformationGraph, RetiringErasesOnlyTheEdgesBetweenRetiredPoints) {
  DeformationModelOptions options;
  DeformationGraph graph(options, 5.0);
  Positions positions;
  for (PointId id = 0; id < 6; ++id) positions.at[id] = {0.5 * id, 0.1 * id * id, 0};
  graph.ConnectCovisible(positions.Ids(), {}, positions.Lookup());
  ASSERT_EQ(graph.edge_count(), 15u);
  graph.Retire({0, 1, 2}, 6);
  EXPECT_TRUE(graph.IsRetired(3));
  EXPECT_FALSE(graph.IsRetired(2));
  EXPECT_EQ(graph.edge_count(), 12u);  // 3–4, 3–5, 4–5 erased
  EXPECT_FALSE(graph.FindEdge(3, 4));
  EXPECT_TRUE(graph.FindEdge(0, 3));
  EXPECT_EQ(graph.GoodEdgeCount(0), 5);  // its edges to retired points still count
  // A retired point's edges to live ones are still measured from the live end, and pruned.
  positions.at[0] = {-20, 0, 0};
  graph.UpdatePoints({0}, positions.Lookup());
  EXPECT_TRUE(graph.edge(*graph.FindEdge(0, 4)).pruned);
  EXPECT_EQ(graph.GoodEdgeCount(0), 0);
  // Handing a retired point back is a logic error, never silently a different graph.
  EXPECT_THROW(graph.GoodEdgeCount(3), Error);
  EXPECT_THROW(graph.UpdatePoints({1, 3}, positions.Lookup()), Error);
  EXPECT_THROW(graph.PairsAmong({0, 4}), Error);
  EXPECT_THROW(graph.BestNeighbours(5), Error);
  EXPECT_THROW(graph.ResetRestShape({5}, positions.Lookup()), Error);
  positions.at[6] = {1, 1, 1};
  EXPECT_THROW(graph.ConnectCovisible({6}, {3}, positions.Lookup()), Error);
  // Retired stays retired; new edges fill the erased ones' slots.
  graph.Retire({0, 1, 3}, 6);
  EXPECT_TRUE(graph.IsRetired(3));
  EXPECT_EQ(graph.edge_count(), 9u);  // and 2–3, 2–4, 2–5
  const std::vector<int> before = graph.EdgeIndices();
  graph.ConnectCovisible({6}, {0, 1}, positions.Lookup());
  EXPECT_EQ(graph.edge_count(), 11u);
  for (const int e : graph.EdgeIndices()) EXPECT_LT(e, 15);
  EXPECT_DOUBLE_EQ(graph.edge(*graph.FindEdge(6, 1)).rest_length, (positions.at[6] - positions.at[1]).norm());
  EXPECT_EQ(graph.GoodEdgeCount(6), 2);
  EXPECT_EQ(before.size() + 2, graph.EdgeIndices().size());
}

// Retiring is a memory measure: two graphs fed the same run, one retiring the points the run
// has dropped and one keeping every edge, must answer every question about the points still
// in play the same, to the bit.
TEST(DeformationGraph, RetiringChangesNoAnswerAboutLivePoints) {
  DeformationModelOptions options;
  options.max_degree_D = 4;
  options.stretch_threshold = 0.4;
  DeformationGraph kept(options, 1.5), retiring(options, 1.5);
  std::mt19937 random(11);
  std::uniform_real_distribution<double> coordinate(0.0, 3.0), jitter(-0.2, 0.2), chance(0.0, 1.0);
  std::vector<Eigen::Vector3d> position;  // by id; every point keeps one, like a map
  std::vector<PointId> live;
  const PositionLookup lookup = [&](PointId id) -> std::optional<Eigen::Vector3d> { return position.at(id); };
  const auto add_points = [&](int count) {
    std::vector<PointId> created;
    for (int n = 0; n < count; ++n) {
      created.push_back(static_cast<PointId>(position.size()));
      position.emplace_back(coordinate(random), coordinate(random), coordinate(random));
    }
    kept.ConnectCovisible(created, live, lookup);
    retiring.ConnectCovisible(created, live, lookup);
    live.insert(live.end(), created.begin(), created.end());
  };
  add_points(30);
  for (int step = 0; step < 40; ++step) {
    for (const PointId id : live) position[id] += Eigen::Vector3d(jitter(random), jitter(random), jitter(random));
    kept.UpdatePoints(live, lookup);
    retiring.UpdatePoints(live, lookup);
    std::vector<PointId> still;  // a tenth of the points leave for good each step, new ones join
    for (const PointId id : live) {
      if (chance(random) > 0.1) still.push_back(id);
    }
    live = still;
    retiring.Retire(live, position.size());
    add_points(4);
    for (const PointId id : live) {
      ASSERT_EQ(kept.GoodEdgeCount(id), retiring.GoodEdgeCount(id)) << "point " << id << " at step " << step;
      // Not only the same answers: the right ones, though edges of retired points were erased
      // and new ones took their slots.
      ExpectCountsAndBestEdgesFromTheRecords(retiring, options, id);
      const auto a = kept.BestNeighbours(id), b = retiring.BestNeighbours(id);
      ASSERT_EQ(a.size(), b.size());
      for (size_t n = 0; n < a.size(); ++n) {
        EXPECT_EQ(a[n].id, b[n].id);
        EXPECT_EQ(a[n].weight, b[n].weight);
      }
    }
    const auto pairs_kept = kept.PairsAmong(live), pairs_retiring = retiring.PairsAmong(live);
    ASSERT_EQ(pairs_kept.size(), pairs_retiring.size());
    for (size_t p = 0; p < pairs_kept.size(); ++p) {
      EXPECT_EQ(pairs_kept[p].i, pairs_retiring[p].i);
      EXPECT_EQ(pairs_kept[p].j, pairs_retiring[p].j);
      EXPECT_EQ(kept.edge(pairs_kept[p].edge).rest_length, retiring.edge(pairs_retiring[p].edge).rest_length);
      EXPECT_EQ(kept.edge(pairs_kept[p].edge).max_length, retiring.edge(pairs_retiring[p].edge).max_length);
    }
  }
  // Most points have left by now, and with them most edges.
  ASSERT_LT(live.size(), position.size() / 2);
  EXPECT_LT(2 * retiring.edge_count(), kept.edge_count());
  RecordProperty("edges", std::to_string(retiring.edge_count()) + " of " + std::to_string(kept.edge_count()));
}

}  // namespace
}  // namespace nrslam
