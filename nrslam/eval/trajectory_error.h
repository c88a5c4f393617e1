// eval: camera trajectory error after a similarity alignment (ATE), a column beside the depth
// RMSE (design README §5 welcomes it; it never replaces the headline).
//
// A monocular map has its own scale and gauge, so each map's estimated camera centres are
// aligned to the ground-truth ones by the least-squares similarity (Umeyama 1991: rotation,
// translation, scale) before the RMSE of their distances, in ground-truth units (mm), is taken.
// A run that started several maps (a monocular run re-initialises after a loss) aligns each
// on its own and pools the squared distances.
#pragma once

#include <Eigen/Core>

#include <optional>
#include <vector>

namespace nrslam {

// One map's tracked frames: camera centres in the map's world and in the ground truth's.
struct TrajectorySegment {
  std::vector<Eigen::Vector3d> estimated, groundtruth;
};

struct TrajectoryError {
  bool evaluated = false;  // false when no map had 3 frames with the camera moving
  int poses = 0;           // frames aligned, over all maps
  int maps = 0;            // maps aligned
  double rmse_mm = 0.0;    // over all aligned frames
  double scale = 0.0;      // of the map with the most frames: map units → mm
};

TrajectoryError AlignedTrajectoryError(const std::vector<TrajectorySegment>& maps);

// The map's estimated camera centres carried onto the true ones by that least-squares
// similarity, in ground-truth units: what the error above measures, e.g. to plot. nullopt
// when the map cannot be aligned (fewer than 3 frames, or a camera that did not move).
std::optional<std::vector<Eigen::Vector3d>> AlignedCentres(const TrajectorySegment& map);

}  // namespace nrslam
