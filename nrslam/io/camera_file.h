// io: a camera calibration on its own: a JSON file holding what sequence.json's "camera" holds
// (model, width, height, cx, cy, and fx, fy, k or the ocam fields), a whole sequence.json, whose
// "camera" is then read, or OCamCalib's calib_results.txt (the Scaramuzza model, `ocam`).
#pragma once

#include <filesystem>
#include <string>

#include "nrslam/camera/camera.h"

namespace nrslam {

// Reads and validates it; throws Error naming the file and what is wrong.
Camera ReadCameraFile(const std::filesystem::path& file);

// The text of OCamCalib's calib_results.txt: five lines of numbers under '#' comments, in this
// order: the direct polynomial (count, then ss), the inverse one (count, then invpol), the
// centre (row, column), the affine part (c, d, e) and the image size (height, width). Throws
// Error naming the part that is wrong.
Camera ParseOcamCalibResults(const std::string& text);

}  // namespace nrslam
