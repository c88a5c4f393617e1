#include "nrslam/map/map.h"

namespace nrslam {

PointId Map::AddPoint(const Eigen::Vector3d& position, const cv::Vec3b& colour, int frame) {
  const auto id = static_cast<PointId>(points_.size());
  points_.push_back(MapPoint{id, position, colour, frame});
  return id;
}

PositionLookup Map::Positions() const {
  return [this](PointId id) -> std::optional<Eigen::Vector3d> {
    if (id < 0 || static_cast<size_t>(id) >= points_.size()) return std::nullopt;
    return points_[static_cast<size_t>(id)].position;
  };
}

}  // namespace nrslam
