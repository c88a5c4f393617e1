// io: a camera calibration on its own, as a JSON file holding what sequence.json's "camera"
// holds (model, width, height, fx, fy, cx, cy, and k for kannala_brandt), or a whole
// sequence.json, whose "camera" is then read.
#pragma once

#include <filesystem>

#include "nrslam/camera/camera.h"

namespace nrslam {

// Reads and validates it; throws Error naming the file and what is wrong.
Camera ReadCameraFile(const std::filesystem::path& file);

}  // namespace nrslam
