#include "nrslam/map/map.h"

namespace nrslam {

PointId Map::AddPoint(const Eigen::Vector3d& position, const cv::Vec3b& colour, int frame) {
  const PointId id = next_id_++;
  points_.emplace(id, MapPoint{id, position, colour, frame});
  return id;
}

PositionLookup Map::Positions() const {
  return [this](PointId id) -> std::optional<Eigen::Vector3d> {
    const auto found = points_.find(id);
    if (found == points_.end()) return std::nullopt;
    return found->second.position;
  };
}

}  // namespace nrslam
