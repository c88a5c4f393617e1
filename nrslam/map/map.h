// map: the map points and the deformation graph over them.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <optional>
#include <vector>

#include "nrslam/deformation/deformation_graph.h"

namespace nrslam {

struct MapPoint {
  PointId id = -1;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // world, map units (its latest estimate)
  cv::Vec3b colour;                                     // BGR, for map.ply
  int created_frame = 0;
};

class Map {
 public:
  explicit Map(const DeformationModelOptions& options) : graph_(options) {}

  PointId AddPoint(const Eigen::Vector3d& position, const cv::Vec3b& colour, int frame);
  MapPoint& point(PointId id) { return points_.at(static_cast<size_t>(id)); }
  const MapPoint& point(PointId id) const { return points_.at(static_cast<size_t>(id)); }
  // Indexed by id: points are never removed, so ids are 0 … size() − 1.
  const std::vector<MapPoint>& points() const { return points_; }
  size_t size() const { return points_.size(); }

  DeformationGraph& graph() { return graph_; }
  const DeformationGraph& graph() const { return graph_; }
  PositionLookup Positions() const;

  // The length (map units) that the reference implementation's constants are expressed in:
  // it scales maps to a median depth of 3, so this is the median initial depth / 3. The
  // viscous σ of the reference weighting is a fraction of it.
  double scale() const { return scale_; }
  void set_scale(double scale) { scale_ = scale; }

 private:
  // A vector, not a hash map: the graph's per-frame edge updates look up hundreds of
  // thousands of positions by id.
  std::vector<MapPoint> points_;
  DeformationGraph graph_;
  double scale_ = 1.0;
};

}  // namespace nrslam
