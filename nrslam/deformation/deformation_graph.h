// deformation: the Dynamic Deformation Graph (DDG).
//
// Nodes are map points; an edge joins two points that were seen together when one of them
// was created. Each edge keeps its rest length d0 (its length at creation, what the spring
// pulls towards), the shortest and longest lengths ever observed, d_min and d_max, and its
// weight b = exp(−d_max² / 2σ²). An edge is pruned — for good, since d_max only grows and
// d_min only shrinks — once (d_max − d_min)/d_min exceeds the stretching threshold: the two
// points no longer deform together. Each point is regularised by its best D unpruned edges.
//
// Points that the system has dropped for good are retired (Retire): an edge between two
// retired points can never be read again and is erased, so a long run holds the edges of the
// points still in play rather than every edge it ever made.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <unordered_map>
#include <vector>

#include "nrslam/deformation/deformation_options.h"

namespace nrslam {

using PointId = int64_t;
constexpr PointId kNoPoint = -1;  // a 2D track without a map point

struct GraphEdge {
  PointId a = -1, b = -1;
  double rest_length = 0.0;  // d0
  double min_length = 0.0;   // d_min
  double max_length = 0.0;   // d_max
  double weight = 0.0;       // b = exp(−d_max²/2σ²)
  bool pruned = false;
};

struct GraphNeighbour {
  PointId id;
  int edge;       // index into DeformationGraph::edge()
  double weight;  // b of that edge
};

// A regularised pair among a list of points: their positions in that list, i the one whose
// best D edges chose the pair first, j its neighbour.
struct GraphPair {
  size_t i, j;
  int edge;       // index into DeformationGraph::edge()
  double weight;  // b of that edge
};

// Current position of a point, or nullopt if it has none now.
using PositionLookup = std::function<std::optional<Eigen::Vector3d>(PointId)>;

class DeformationGraph {
 public:
  explicit DeformationGraph(const DeformationModelOptions& options, double sigma = 1.0);

  double sigma() const { return sigma_; }
  // Sets σ (map units) and recomputes every weight.
  void set_sigma(double sigma);

  // Adds the edge a–b with the given current length; no-op if it exists or a == b. Ids are map
  // indices below 2³¹: any other throws.
  void AddEdge(PointId a, PointId b, double length);
  // Joins each new point to every other new point and to every existing point that has a
  // position: the points co-visible at creation.
  void ConnectCovisible(const std::vector<PointId>& new_points, const std::vector<PointId>& existing,
                        const PositionLookup& position);
  // Re-measures the edges of `points` from current positions: d_min, d_max, b, pruning. An edge
  // between two of them is measured once. Neighbours without a position keep their edge
  // untouched. Ids are map indices (a table as long as the largest one is built).
  void UpdatePoints(const std::vector<PointId>& points, const PositionLookup& position);

  // Takes the current lengths of the edges among `points` as their rest lengths (and d_min,
  // d_max): for a map whose structure was re-estimated, not deformed.
  void ResetRestShape(const std::vector<PointId>& points, const PositionLookup& position);

  // Up to max_degree_D unpruned edges with b >= min_edge_weight, highest b first, to
  // neighbours that pass `eligible` (all if empty): e.g. only the points tracked this frame,
  // so lost neighbours do not use up the point's D regularisers.
  std::vector<GraphNeighbour> BestNeighbours(PointId point, const std::function<bool(PointId)>& eligible = {}) const;
  // The regularisers among `points` (map indices): each one's BestNeighbours among the others,
  // each pair once, in the order of the points and then of their neighbours. That order
  // fixes the order of a solver's residual blocks, and so its floating-point sums.
  std::vector<GraphPair> PairsAmong(const std::vector<PointId>& points) const;
  // Unpruned edges of the point (kept as a count: asked for every point every frame).
  int GoodEdgeCount(PointId point) const;

  // Retires every point with an id below `point_count` that is not in `live`; retired points
  // stay retired. The caller promises never to hand a retired point to the functions above
  // (they throw if it does): the tracker and mapper drop a point for good once it is neither
  // tracked, nor lost and looked for, nor in the DBA window. An edge between two retired
  // points is then never read again and is erased. An edge from a retired point to a live one
  // stays: the live end still measures it, and it still counts towards the live end's
  // unpruned edges until it is pruned. So retiring changes no result, only the memory.
  void Retire(const std::vector<PointId>& live, size_t point_count);
  bool IsRetired(PointId point) const;
  // Fewer than min_good_edges unpruned edges left: the point's deformation is unconstrained.
  bool IsWeaklyConnected(PointId point) const { return GoodEdgeCount(point) < options_.min_good_edges; }

  const GraphEdge& edge(int index) const { return edges_[index]; }
  // Every edge's index (erased edges leave holes that new edges fill).
  std::vector<int> EdgeIndices() const;
  size_t edge_count() const { return edges_.size() - free_edges_.size(); }
  size_t pruned_count() const;
  std::optional<int> FindEdge(PointId a, PointId b) const;

 private:
  DeformationModelOptions options_;
  double sigma_;
  struct Incidence {
    int32_t other;  // ids are below 2³¹ (AddEdge checks): half the memory of a PointId
    int edge;
  };
  struct Node {
    // Append-only while the point is live, so an edge keeps its slot in both ends' lists; a
    // retired point's lists are emptied (nothing reads them again).
    std::vector<Incidence> edges;
    // Per slot, the edge's b if it may regularise (unpruned, b >= min_edge_weight), else −1:
    // what the best-D choice reads, kept beside the point's list because a complete graph gives
    // every point hundreds of edges, the choice is made for every point every frame, and only a
    // few of the weights change in a frame.
    std::vector<double> ranking;
    int unpruned = 0;
    int present = 0;  // edges not erased; the node's storage goes when it reaches 0
  };
  std::vector<GraphEdge> edges_;           // a free slot has a == kNoPoint
  std::vector<std::array<int, 2>> slots_;  // per edge, its slot in the lists of a and of b
  std::vector<int> free_edges_;
  std::vector<bool> retired_;  // by point id
  std::vector<Node> nodes_;    // by point id
  std::unordered_map<uint64_t, int> edge_index_;  // keyed by the unordered pair

  double WeightOf(double max_length) const;
  template <typename Eligible>
  void SelectBest(PointId point, const Eligible& eligible, std::vector<GraphNeighbour>* best) const;
  // A length outside [d_min, d_max]: the bounds, b, pruning and the ranking follow it.
  void Remeasure(int index, double length);
  void UpdateRanking(int index);  // copies the edge's ranking weight into both ends' lists
  double RankingWeight(const GraphEdge& edge) const;
  const Node* FindNode(PointId point) const;
  void EraseEdge(int index);
  // Throws unless every point may still be read (none is retired).
  void CheckLive(const std::vector<PointId>& points) const;
  void CheckLive(PointId point) const;
  static bool IsGraphId(PointId point);  // a map index below 2³¹
  static uint64_t PairKey(PointId a, PointId b);
};

}  // namespace nrslam
