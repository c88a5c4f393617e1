// io: TUM trajectory files, one "timestamp tx ty tz qx qy qz qw" line per pose,
// world_from_camera (T_wc), as the TUM RGB-D tools and evo read them.
#pragma once

#include <filesystem>
#include <vector>

#include "nrslam/geometry/rigid3.h"

namespace nrslam {

struct StampedPose {
  double timestamp = 0.0;  // s
  Rigid3 world_from_camera;
};

void WriteTum(const std::filesystem::path& path, const std::vector<StampedPose>& poses);
// Throws Error with the file and line number on a malformed line or non-finite value.
std::vector<StampedPose> ReadTum(const std::filesystem::path& path);

}  // namespace nrslam
