// datasets: importing public dataset layouts into the sequence format.
//
//   endomapper-sim  rgb/image_%04d.png, depth/aov_image_%04d.exr (Unity reversed-Z depth
//                   buffer in channel R, linearised with near/far), trajectory.csv
//                   ("tX;tY;tZ;rX;rY;rZ;rW;time", camera_from_world). Pinhole; default
//                   intrinsics are the Endomapper simulation's (fx = fy = 472.6496, principal
//                   point at the image centre) unless a calibration file is given.
//   hamlyn          the rectified release: image01/ (left), image02/ (right), depth01/; or
//                   Endo-Depth-and-Motion's tracking data: color/, depth/. Depth 16-bit mm;
//                   frames paired across folders by the numbers in their names.
//                   intrinsics.txt: K by rows (3×3, 3×4 or 4×4), optionally then a line with
//                   the baseline in mm (the right images are used only with it).
//   c3vd            NNNN_color.png, NNNN_depth.tiff (16-bit, 0–65535 ↦ 0–100 mm), pose.txt
//                   (one 4×4 world_from_camera per line, 16 numbers, mm; row- or column-major
//                   is recognised from where the translation is). Calibration file required.
//   images          a folder of images (sorted by name) or a video file, with a calibration
//                   file; no ground truth (runs need monocular initialisation).
//   stereo          a raw stereo recording: the left images (folder or video) and the right
//                   ones, or one stream holding both views side by side or one above the other,
//                   with the pair's stereo calibration (io/camera_file.h); rectified
//                   (datasets/stereo_rectification.h) into a pinhole pair with its baseline, so
//                   nrslam_stereo_gt can give it depth. No ground truth.
//
// A calibration file is whatever io/camera_file.h reads: a JSON camera as in sequence.json,
// OCamCalib's calib_results.txt or an OpenCV / ROS calibration (YAML or XML).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "nrslam/datasets/stereo_depth.h"
#include "nrslam/io/sequence_info.h"

namespace nrslam {

struct ImportOptions {
  std::string format;                  // endomapper-sim, hamlyn, c3vd, images, stereo
  std::filesystem::path input;         // the dataset's folder (or video file for "images")
  std::filesystem::path calibration;   // camera JSON; required for c3vd and images; stereo's calibration for stereo
  // A fixed validity mask of the dataset's images (non-zero = usable; e.g. the black border of an
  // endoscope's image, whose edge would otherwise be tracked as corners that never move), written
  // as the sequence's mask.png; empty = none.
  std::filesystem::path mask;
  double fps = 30.0;                   // frames per second (timestamps of the ground truth)
  int max_frames = 0;                  // import at most this many frames; 0 = all
  // Keep every frame_step-th frame of the dataset (2 turns a 50 fps video into 25 fps); the
  // sequence's fps is fps / frame_step. max_frames counts the frames kept.
  int frame_step = 1;
  double depth_unit_mm = 0.01;         // resolution of the written 16-bit depth, mm
  // Resize factor for every image, depth map and the calibration (which describes the dataset's
  // own images), in (0, 4]: 0.5 halves Endomapper's 1440×1080 to 720×540, as the reference does.
  // Colour is area-averaged down (bilinear up); depth takes the nearest pixel, so no written depth
  // blends two surfaces across an edge.
  double scale = 1.0;
  // stereo: the right camera's images (folder or video), unless `stereo_layout` says the input's
  // images hold both views: "side-by-side" (left half is the left camera) or "top-bottom" (top
  // half is the left camera, as SCARED's videos).
  std::filesystem::path right;
  std::string stereo_layout;
  // stereo: a second calibration file: the entries the first lacks (OpenCV's stereo_calib sample
  // writes M1 D1 M2 D2 to intrinsics.yml and R T to extrinsics.yml), or the right camera's ROS
  // camera_info when `calibration` is the left one's; empty = none (io/camera_file.h).
  std::filesystem::path second_calibration;
  // stereo: mm per unit of the calibration's translation; 0 = the format's own (mm for OpenCV's
  // names, as SCARED's; metres for Kalibr and ROS).
  double stereo_unit_mm = 0.0;
  // stereo: the rectified images' size, px (0 × 0 = automatic) and cv::stereoRectify's alpha
  // (see StereoRectificationOptions).
  int rectified_width = 0, rectified_height = 0;
  double rectify_alpha = 0.0;
  // Depth from the rectified pair (datasets/stereo_depth.h), written as the sequence's depth as
  // nrslam_stereo_gt would: for stereo recordings and Hamlyn without depth01/.
  bool stereo_depth = false;
  StereoDepthOptions stereo_depth_options;
  double near = 0.01, far = 4.0;       // endomapper-sim: depth-buffer planes, scene units
  double scene_unit_mm = 1000.0;       // endomapper-sim: mm per scene unit (Unity: metres)
  void Check() const;
};

std::vector<std::string> ImportFormats();

// Reads the dataset at options.input and writes a complete sequence folder at `out`.
// Throws Error naming the format, the file and what is wrong.
SequenceInfo ImportDataset(const ImportOptions& options, const std::filesystem::path& out);

}  // namespace nrslam
