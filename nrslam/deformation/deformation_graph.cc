#include "nrslam/deformation/deformation_graph.h"

#include <unordered_set>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "nrslam/util/error.h"

namespace nrslam {

DeformationGraph::DeformationGraph(const DeformationModelOptions& options, double sigma) : options_(options) {
  options_.Check();
  set_sigma(sigma);
}

void DeformationGraph::set_sigma(double sigma) {
  if (!(sigma > 0) || !std::isfinite(sigma)) throw Error("deformation graph: sigma must be > 0");
  sigma_ = sigma;
  for (size_t index = 0; index < edges_.size(); ++index) {
    if (edges_[index].a == kNoPoint) continue;  // a free slot
    edges_[index].weight = WeightOf(edges_[index].max_length);
    UpdateRanking(static_cast<int>(index));
  }
}

double DeformationGraph::RankingWeight(const GraphEdge& edge) const {
  return edge.pruned || edge.weight < options_.min_edge_weight ? -1.0 : edge.weight;
}

void DeformationGraph::UpdateRanking(int index) {
  const GraphEdge& edge = edges_[index];
  const double ranking = RankingWeight(edge);
  for (int end = 0; end < 2; ++end) {
    Node& node = nodes_[static_cast<size_t>(end == 0 ? edge.a : edge.b)];
    const auto slot = static_cast<size_t>(slots_[index][end]);
    if (slot < node.ranking.size()) node.ranking[slot] = ranking;  // a retired end has no list
  }
}

void DeformationGraph::Remeasure(int index, double length) {
  GraphEdge& edge = edges_[index];
  const bool longer = length > edge.max_length;
  if (length < edge.min_length) edge.min_length = length;
  if (longer) {  // the weight follows the longest length (an exp: only when it grows)
    edge.max_length = length;
    edge.weight = WeightOf(length);
  }
  if (!edge.pruned && (edge.max_length - edge.min_length) / edge.min_length > options_.stretch_threshold) {
    edge.pruned = true;
    --nodes_[static_cast<size_t>(edge.a)].unpruned;
    --nodes_[static_cast<size_t>(edge.b)].unpruned;
  }
  UpdateRanking(index);
}

const DeformationGraph::Node* DeformationGraph::FindNode(PointId point) const {
  return point >= 0 && static_cast<size_t>(point) < nodes_.size() ? &nodes_[static_cast<size_t>(point)] : nullptr;
}

double DeformationGraph::WeightOf(double max_length) const {
  return std::exp(-max_length * max_length / (2.0 * sigma_ * sigma_));
}

bool DeformationGraph::IsGraphId(PointId point) {
  return point >= 0 && point <= std::numeric_limits<int32_t>::max();
}

uint64_t DeformationGraph::PairKey(PointId a, PointId b) {
  // Both ids below 2³¹: the key names one pair only.
  const auto low = static_cast<uint64_t>(std::min(a, b)), high = static_cast<uint64_t>(std::max(a, b));
  return (high << 32) | low;
}

std::optional<int> DeformationGraph::FindEdge(PointId a, PointId b) const {
  if (!IsGraphId(a) || !IsGraphId(b)) return std::nullopt;
  const auto found = edge_index_.find(PairKey(a, b));
  if (found == edge_index_.end()) return std::nullopt;
  return found->second;
}

void DeformationGraph::AddEdge(PointId a, PointId b, double length) {
  CheckLive(a);
  CheckLive(b);
  if (!IsGraphId(a) || !IsGraphId(b)) {
    throw Error("deformation graph: point ids are map indices below 2^31, got " + std::to_string(a) + " and " +
                std::to_string(b));
  }
  if (a == b || FindEdge(a, b)) return;
  if (!(length > 0) || !std::isfinite(length)) return;  // coincident or invalid points: no direction to regularise
  const GraphEdge edge{a, b, length, length, length, WeightOf(length), false};
  int index;
  if (free_edges_.empty()) {
    index = static_cast<int>(edges_.size());
    edges_.push_back(edge);
    slots_.emplace_back();
  } else {
    index = free_edges_.back();
    free_edges_.pop_back();
    edges_[index] = edge;
  }
  nodes_.resize(std::max(nodes_.size(), static_cast<size_t>(std::max(a, b)) + 1));
  int end = 0;
  for (const auto& [from, to] : {std::pair(a, b), std::pair(b, a)}) {
    Node& node = nodes_[static_cast<size_t>(from)];
    slots_[index][end++] = static_cast<int>(node.edges.size());
    node.edges.push_back({static_cast<int32_t>(to), index});
    node.ranking.push_back(RankingWeight(edge));
    ++node.unpruned;
    ++node.present;
  }
  edge_index_.emplace(PairKey(a, b), index);
}

void DeformationGraph::EraseEdge(int index) {
  GraphEdge& edge = edges_[index];
  edge_index_.erase(PairKey(edge.a, edge.b));
  for (const PointId end : {edge.a, edge.b}) {
    Node& node = nodes_[static_cast<size_t>(end)];
    if (!edge.pruned) --node.unpruned;
    if (--node.present == 0) node = Node{};
  }
  edge = GraphEdge{};
  edge.a = edge.b = kNoPoint;
  edge.pruned = true;
  free_edges_.push_back(index);
}

bool DeformationGraph::IsRetired(PointId point) const {
  return point >= 0 && static_cast<size_t>(point) < retired_.size() && retired_[static_cast<size_t>(point)];
}

void DeformationGraph::CheckLive(PointId point) const {
  if (IsRetired(point)) {
    throw Error("deformation graph: point " + std::to_string(point) + " was retired and cannot be used again");
  }
}

void DeformationGraph::CheckLive(const std::vector<PointId>& points) const {
  for (const PointId point : points) CheckLive(point);
}

void DeformationGraph::Retire(const std::vector<PointId>& live, size_t point_count) {
  std::vector<bool> keep(point_count, false);
  for (const PointId id : live) {
    if (id >= 0 && static_cast<size_t>(id) < point_count) keep[static_cast<size_t>(id)] = true;
  }
  if (retired_.size() < point_count) retired_.resize(point_count, false);
  std::vector<PointId> newly_retired;
  for (size_t id = 0; id < point_count; ++id) {
    if (keep[id] || retired_[id]) continue;
    retired_[id] = true;
    newly_retired.push_back(static_cast<PointId>(id));
  }
  for (const PointId id : newly_retired) {
    if (!FindNode(id)) continue;
    // Nothing reads a retired point's lists again: they go now, and the counts stay for the
    // edges to live points. Its entries are all present (an edge is erased only once both
    // ends are retired), except those erased just now from a point retired beside it.
    Node& node = nodes_[static_cast<size_t>(id)];
    const std::vector<Incidence> incidences = std::move(node.edges);
    node.edges = {};
    node.ranking = {};
    for (const Incidence& incidence : incidences) {
      if (edges_[incidence.edge].a != kNoPoint && IsRetired(incidence.other)) EraseEdge(incidence.edge);
    }
  }
}

std::vector<int> DeformationGraph::EdgeIndices() const {
  std::vector<int> indices;
  indices.reserve(edge_count());
  for (size_t index = 0; index < edges_.size(); ++index) {
    if (edges_[index].a != kNoPoint) indices.push_back(static_cast<int>(index));
  }
  return indices;
}

void DeformationGraph::ConnectCovisible(const std::vector<PointId>& new_points, const std::vector<PointId>& existing,
                                        const PositionLookup& position) {
  CheckLive(new_points);
  CheckLive(existing);
  std::vector<std::pair<PointId, Eigen::Vector3d>> located;
  for (PointId id : new_points) {
    if (const auto p = position(id)) located.emplace_back(id, *p);
  }
  const size_t new_count = located.size();
  for (PointId id : existing) {
    if (const auto p = position(id)) located.emplace_back(id, *p);
  }
  for (size_t i = 0; i < new_count; ++i) {
    for (size_t j = i + 1; j < located.size(); ++j) {
      AddEdge(located[i].first, located[j].first, (located[i].second - located[j].second).norm());
    }
  }
}

namespace {

// Where each id sits in a list of points, as a table indexed by id: the graph asks it for
// every edge of every listed point, hundreds per point.
class ListPositions {
 public:
  explicit ListPositions(const std::vector<PointId>& points) {
    PointId largest = -1;
    for (PointId id : points) largest = std::max(largest, id);
    position_.assign(static_cast<size_t>(largest + 1), -1);
    for (size_t k = 0; k < points.size(); ++k) {
      if (points[k] < 0) throw Error("deformation graph: point ids are map indices, got " + std::to_string(points[k]));
      position_[static_cast<size_t>(points[k])] = static_cast<int>(k);
    }
  }
  bool Contains(PointId id) const { return static_cast<size_t>(id) < position_.size() && At(id) >= 0; }
  int At(PointId id) const { return position_[static_cast<size_t>(id)]; }
  size_t size() const { return position_.size(); }

 private:
  std::vector<int> position_;  // −1: not listed
};

}  // namespace

void DeformationGraph::UpdatePoints(const std::vector<PointId>& points, const PositionLookup& position) {
  CheckLive(points);
  const ListPositions listed(points);
  // The edges in storage order, one pass over memory rather than a jump per neighbour (a
  // complete graph gives each point hundreds), and each point's position looked up once
  // (every end of an edge has a node, so the tables need no growing).
  enum Lookup : uint8_t { kNotYet, kFound, kNone };
  std::vector<Lookup> lookup(nodes_.size(), kNotYet);
  std::vector<Eigen::Vector3d> found(nodes_.size());
  const auto locate = [&](PointId id) -> const Eigen::Vector3d* {
    const auto slot = static_cast<size_t>(id);
    if (lookup[slot] == kNotYet) {
      const std::optional<Eigen::Vector3d> p = position(id);
      lookup[slot] = p ? kFound : kNone;
      if (p) found[slot] = *p;
    }
    return lookup[slot] == kFound ? &found[slot] : nullptr;
  };
  for (size_t index = 0; index < edges_.size(); ++index) {
    const GraphEdge& edge = edges_[index];
    if (edge.a == kNoPoint || !(listed.Contains(edge.a) || listed.Contains(edge.b))) continue;
    const Eigen::Vector3d* here = locate(edge.a);
    const Eigen::Vector3d* there = here ? locate(edge.b) : nullptr;
    if (!there) continue;
    // Most lengths fall between the two bounds, and then nothing changes: the pruning test
    // was made when the bounds last moved.
    const double length = (*here - *there).norm();
    if (length < edge.min_length || length > edge.max_length) Remeasure(static_cast<int>(index), length);
  }
}

void DeformationGraph::ResetRestShape(const std::vector<PointId>& points, const PositionLookup& position) {
  CheckLive(points);
  const std::unordered_set<PointId> chosen(points.begin(), points.end());
  for (PointId point : points) {
    const Node* node = FindNode(point);
    const auto here = position(point);
    if (!node || !here) continue;
    for (const auto& [other, index] : node->edges) {
      if (other < point && chosen.count(other)) continue;  // done from the other end
      if (!chosen.count(other)) continue;
      const auto there = position(other);
      if (!there) continue;
      GraphEdge& edge = edges_[index];
      const double length = (*here - *there).norm();
      edge.rest_length = edge.min_length = edge.max_length = length;
      edge.weight = WeightOf(length);
      UpdateRanking(index);
    }
  }
}

template <typename Eligible>
void DeformationGraph::SelectBest(PointId point, const Eligible& eligible, std::vector<GraphNeighbour>* best) const {
  best->clear();
  const Node* node = FindNode(point);
  if (!node) return;
  // The best D so far, best first: highest b, ties broken by id so the choice never depends
  // on insertion order. A complete graph gives a point hundreds of edges of which D are kept,
  // so an edge that would not enter is set aside before `eligible` is asked about it.
  const auto better = [](double weight, PointId id, const GraphNeighbour& than) {
    return weight != than.weight ? weight > than.weight : id < than.id;
  };
  const auto degree = static_cast<size_t>(options_.max_degree_D);
  best->reserve(degree);  // one allocation per list, not one per doubling (a list per lost point per frame)
  const double* ranking = node->ranking.data();
  const Incidence* incidences = node->edges.data();
  const size_t count = node->edges.size();
  // Below `entry` an edge can be set aside on its weight alone, which is what nearly all are:
  // the loop then reads one array (b ≥ 0 always, so −1 marks what may not regularise).
  double entry = 0.0;
  for (size_t slot = 0; slot < count; ++slot) {
    const double weight = ranking[slot];
    if (weight < entry) continue;
    const auto& [other, index] = incidences[slot];
    if (best->size() == degree && !better(weight, other, best->back())) continue;
    if (!eligible(other)) continue;
    if (best->size() == degree) best->pop_back();
    auto place = best->end();
    while (place != best->begin() && better(weight, other, *(place - 1))) --place;
    best->insert(place, {other, index, weight});
    if (best->size() == degree) entry = best->back().weight;
  }
}

std::vector<GraphNeighbour> DeformationGraph::BestNeighbours(PointId point,
                                                             const std::function<bool(PointId)>& eligible) const {
  CheckLive(point);
  std::vector<GraphNeighbour> best;
  if (eligible) {
    SelectBest(point, eligible, &best);
  } else {
    SelectBest(point, [](PointId) { return true; }, &best);
  }
  return best;
}

std::vector<GraphPair> DeformationGraph::PairsAmong(const std::vector<PointId>& points) const {
  CheckLive(points);
  const ListPositions listed(points);
  const auto is_listed = [&](PointId id) { return listed.Contains(id); };
  // Point i's chosen neighbours (list positions) are chosen[i·D, i·D + chosen_count[i]):
  // one allocation per call rather than one per point, as this runs every frame.
  const auto degree = static_cast<size_t>(options_.max_degree_D);
  std::vector<size_t> chosen(points.size() * degree), chosen_count(points.size(), 0);
  std::vector<GraphPair> pairs;
  std::vector<GraphNeighbour> best;
  for (size_t i = 0; i < points.size(); ++i) {
    SelectBest(points[i], is_listed, &best);
    for (const GraphNeighbour& neighbour : best) {
      const auto j = static_cast<size_t>(listed.At(neighbour.id));
      chosen[i * degree + chosen_count[i]++] = j;
      // With a point listed earlier, the pair exists already if that point chose this one.
      const size_t* j_first = chosen.data() + j * degree;
      const size_t* j_end = j_first + chosen_count[j];
      if (j < i && std::find(j_first, j_end, i) != j_end) continue;
      pairs.push_back({i, j, neighbour.edge, neighbour.weight});
    }
  }
  return pairs;
}

int DeformationGraph::GoodEdgeCount(PointId point) const {
  CheckLive(point);
  const Node* node = FindNode(point);
  return node ? node->unpruned : 0;
}

size_t DeformationGraph::pruned_count() const {
  return static_cast<size_t>(
      std::count_if(edges_.begin(), edges_.end(), [](const GraphEdge& e) { return e.pruned && e.a != kNoPoint; }));
}

}  // namespace nrslam
