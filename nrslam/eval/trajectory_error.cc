#include "nrslam/eval/trajectory_error.h"

#include <Eigen/Geometry>

#include <cmath>

#include "nrslam/util/error.h"

namespace nrslam {

namespace {

struct Alignment {
  Eigen::Matrix3Xd aligned, groundtruth;
  double scale;
};

std::optional<Alignment> Align(const TrajectorySegment& map) {
  if (map.estimated.size() != map.groundtruth.size()) {
    throw Error("trajectory alignment: a map has different numbers of estimated and true poses");
  }
  const auto n = static_cast<Eigen::Index>(map.estimated.size());
  Eigen::Matrix3Xd estimated(3, n), groundtruth(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    estimated.col(i) = map.estimated[static_cast<size_t>(i)];
    groundtruth.col(i) = map.groundtruth[static_cast<size_t>(i)];
  }
  if (!estimated.allFinite() || !groundtruth.allFinite()) throw Error("trajectory alignment: a non-finite pose");
  // A camera that did not move gives no scale to align.
  const Eigen::Vector3d mean = estimated.rowwise().mean();
  if (n < 3 || (estimated.colwise() - mean).squaredNorm() == 0) return std::nullopt;
  const Eigen::Matrix4d similarity = Eigen::umeyama(estimated, groundtruth, true);
  Eigen::Matrix3Xd aligned =
      (similarity.topLeftCorner<3, 3>() * estimated).colwise() + Eigen::Vector3d(similarity.topRightCorner<3, 1>());
  return Alignment{std::move(aligned), std::move(groundtruth), similarity.topLeftCorner<3, 3>().col(0).norm()};
}

}  // namespace

TrajectoryError AlignedTrajectoryError(const std::vector<TrajectorySegment>& maps) {
  TrajectoryError error;
  double squared_sum = 0;
  size_t longest = 0;
  for (const TrajectorySegment& map : maps) {
    const std::optional<Alignment> alignment = Align(map);
    if (!alignment) continue;  // that map is left out
    squared_sum += (alignment->aligned - alignment->groundtruth).squaredNorm();
    error.poses += static_cast<int>(map.estimated.size());
    ++error.maps;
    if (map.estimated.size() > longest) {
      longest = map.estimated.size();
      error.scale = alignment->scale;
    }
  }
  error.evaluated = error.poses > 0;
  if (error.evaluated) error.rmse_mm = std::sqrt(squared_sum / error.poses);
  return error;
}

std::optional<std::vector<Eigen::Vector3d>> AlignedCentres(const TrajectorySegment& map) {
  const std::optional<Alignment> alignment = Align(map);
  if (!alignment) return std::nullopt;
  std::vector<Eigen::Vector3d> centres;
  for (Eigen::Index i = 0; i < alignment->aligned.cols(); ++i) centres.push_back(alignment->aligned.col(i));
  return centres;
}

}  // namespace nrslam
