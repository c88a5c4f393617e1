// io: a camera calibration on its own: a JSON file holding what sequence.json's "camera" holds
// (model, width, height, cx, cy, and fx, fy, k, distortion or the ocam fields), a whole
// sequence.json, whose "camera" is then read, OCamCalib's calib_results.txt (the Scaramuzza
// model, `ocam`), or an OpenCV calibration file (cv::FileStorage YAML or XML, as OpenCV's
// calibration tools and ROS's camera_info write them); and a stereo pair's OpenCV calibration.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "nrslam/camera/camera.h"
#include "nrslam/geometry/rigid3.h"

namespace nrslam {

// Reads and validates it; throws Error naming the file and what is wrong.
Camera ReadCameraFile(const std::filesystem::path& file);

// The text of OCamCalib's calib_results.txt: five lines of numbers under '#' comments, in this
// order: the direct polynomial (count, then ss), the inverse one (count, then invpol), the
// centre (row, column), the affine part (c, d, e) and the image size (height, width). Throws
// Error naming the part that is wrong.
Camera ParseOcamCalibResults(const std::string& text);

// A calibration as cv::FileStorage reads it (YAML or XML), as OpenCV's calibration sample, ROS's
// camera_info and many stereo rigs (the left camera's M1 / D1) write it:
//  - the 3×3 camera matrix: camera_matrix, cameraMatrix, K or M1 (an opencv-matrix, a
//    {rows, cols, data} map or a list of 9 numbers; no skew);
//  - the distortion: distortion_coefficients, dist_coeffs, distCoeffs, D or D1; none = pinhole;
//  - the image size: image_width and image_height, or image_size / imageSize as [width, height];
//  - optionally distortion_model: plumb_bob, radtan or rational_polynomial (OpenCV's model,
//    `opencv`, 4, 5 or 8 coefficients), or equidistant, fisheye or kannala_brandt (cv::fisheye's
//    model, `kannala_brandt`, 4 coefficients). Without it 5 or 8 coefficients are OpenCV's
//    model; 4 are ambiguous between the two and refused.
// Throws Error naming what is missing or wrong.
Camera ReadOpenCvCalibration(const std::filesystem::path& file);

// A calibrated stereo pair, as cv::stereoCalibrate gives it: each camera's own lens and where the
// second camera is, x_right = R·x_left + T.
struct StereoCalibration {
  Camera left, right;
  Rigid3 right_from_left;  // translation in mm
};

// A stereo pair's calibration (cv::FileStorage YAML or XML), in one of three forms:
//  - OpenCV's names: M1, D1, M2, D2, R and T, as cv::stereoCalibrate gives them, OpenCV's
//    stereo_calib sample writes them and the SCARED dataset ships them; each entry is taken
//    from the first of `files` that has it (the sample writes intrinsics.yml and extrinsics.yml).
//    The image size is the file's (as ReadOpenCvCalibration reads it) or else `image_size`
//    (width, height).
//  - Kalibr's camchain: cam0 and cam1 (camera_model pinhole; distortion_model radtan,
//    equidistant or none; intrinsics, distortion_coeffs, resolution), cam1's T_cn_cnm1.
//  - two ROS camera_info files, left then right, with ROS's rectification (rectification_matrix,
//    projection_matrix), from which the pair's relative pose is recovered.
// The translation is in units of `translation_unit_mm` (0: the format's own: mm for OpenCV's
// names, as SCARED's; metres for Kalibr and ROS). Throws Error naming the files and what is
// missing or wrong.
StereoCalibration ReadStereoCalibration(const std::vector<std::filesystem::path>& files,
                                        std::optional<std::pair<int, int>> image_size, double translation_unit_mm);

}  // namespace nrslam
