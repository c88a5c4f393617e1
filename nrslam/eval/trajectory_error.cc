#include "nrslam/eval/trajectory_error.h"

#include <Eigen/Geometry>

#include <cmath>

#include "nrslam/util/error.h"

namespace nrslam {

TrajectoryError AlignedTrajectoryError(const std::vector<TrajectorySegment>& maps) {
  TrajectoryError error;
  double squared_sum = 0;
  size_t longest = 0;
  for (const TrajectorySegment& map : maps) {
    if (map.estimated.size() != map.groundtruth.size()) {
      throw Error("AlignedTrajectoryError: a map has different numbers of estimated and true poses");
    }
    const auto n = static_cast<Eigen::Index>(map.estimated.size());
    Eigen::Matrix3Xd estimated(3, n), groundtruth(3, n);
    for (Eigen::Index i = 0; i < n; ++i) {
      estimated.col(i) = map.estimated[static_cast<size_t>(i)];
      groundtruth.col(i) = map.groundtruth[static_cast<size_t>(i)];
    }
    if (!estimated.allFinite() || !groundtruth.allFinite()) throw Error("AlignedTrajectoryError: a non-finite pose");
    // A camera that did not move gives no scale to align: that map is left out.
    const Eigen::Vector3d mean = estimated.rowwise().mean();
    if (n < 3 || (estimated.colwise() - mean).squaredNorm() == 0) continue;
    const Eigen::Matrix4d similarity = Eigen::umeyama(estimated, groundtruth, true);
    const Eigen::Matrix3Xd aligned = (similarity.topLeftCorner<3, 3>() * estimated).colwise() +
                                     Eigen::Vector3d(similarity.topRightCorner<3, 1>());
    squared_sum += (aligned - groundtruth).squaredNorm();
    error.poses += static_cast<int>(n);
    ++error.maps;
    if (map.estimated.size() > longest) {
      longest = map.estimated.size();
      error.scale = similarity.topLeftCorner<3, 3>().col(0).norm();
    }
  }
  error.evaluated = error.poses > 0;
  if (error.evaluated) error.rmse_mm = std::sqrt(squared_sum / error.poses);
  return error;
}

}  // namespace nrslam
