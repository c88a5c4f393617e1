// The importers of the public datasets' own layouts: Endomapper's simulation, Hamlyn, C3VD.
#include "nrslam/datasets/frame_source.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>
#include <map>
#include <optional>

#include "nrslam/io/sequence_info.h"
#include "nrslam/util/text_table.h"

namespace nrslam::importer {
namespace fs = std::filesystem;

namespace {

// What a Hamlyn intrinsics.txt gives: the rectified pinhole and, when it has one, the baseline.
struct HamlynIntrinsics {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  double baseline_mm = 0;  // 0: not given
};

// K as three rows of 3 numbers, or of 4 (a 3×4 projection matrix), or four rows of 4 (a
// homogeneous 4×4, last row 0 0 0 1); then, optionally, one line holding the baseline in mm.
// Read by rows: taken as one list of numbers, a 3×4 put 0 where fy is. A rectified right
// camera's projection matrix (OpenCV's stereoRectify P2) has fx·(−B) atop its last column:
// the baseline (in the calibration's unit, mm for Hamlyn), when no line gives it.
HamlynIntrinsics ReadHamlynIntrinsics(const ImportOptions& options) {
  std::vector<std::vector<double>> rows;
  for (const NumberLine& line : NumberLines(options, "intrinsics.txt")) {
    if (line.numbers.empty()) {
      Fail(options, "intrinsics.txt line " + std::to_string(line.line) + " is not a row of numbers");
    }
    rows.push_back(line.numbers);
  }
  const std::string expected =
      "intrinsics.txt: expected K as three rows \"fx 0 cx\", \"0 fy cy\", \"0 0 1\" (each may have a 4th number, "
      "as a 3x4 projection matrix), then optionally a line with the baseline in mm";
  if (rows.size() < 3 || rows.size() > 4) Fail(options, expected);
  for (int r = 0; r < 3; ++r) {
    if (rows[r].size() != 3 && rows[r].size() != 4) Fail(options, expected);
  }
  if (rows[0][1] != 0 || rows[1][0] != 0 || rows[2][0] != 0 || rows[2][1] != 0 || rows[2][2] != 1) {
    Fail(options, expected + " (a skew or a last row other than 0 0 1 is not a pinhole K)");
  }
  HamlynIntrinsics intrinsics{rows[0][0], rows[1][1], rows[0][2], rows[1][2]};
  const auto translation = [&](int r) { return rows[r].size() == 4 ? rows[r][3] : 0.0; };
  if (translation(1) != 0 || translation(2) != 0) {
    Fail(options, expected + " (a 4th column other than 0 0 0 or that of a rectified right camera, fx·(-B) 0 0)");
  }
  // fx ≤ 0 is refused with the camera, after this.
  const double projected_baseline_mm =
      translation(0) != 0 && intrinsics.fx > 0 ? std::abs(translation(0) / intrinsics.fx) : 0.0;
  if (rows.size() == 4) {
    const std::vector<double>& last = rows[3];
    if (last.size() == 1) {
      if (last[0] == 0) Fail(options, "intrinsics.txt: the baseline (after K) is 0 mm");
      intrinsics.baseline_mm = std::abs(last[0]);
      const double disagreement = std::abs(projected_baseline_mm - intrinsics.baseline_mm);
      if (projected_baseline_mm > 0 && disagreement > 0.01 * intrinsics.baseline_mm) {
        Fail(options, "intrinsics.txt: the baseline after K (" + FormatFixed(intrinsics.baseline_mm, 3) +
                          " mm) is not the one its projection matrix gives (" + FormatFixed(projected_baseline_mm, 3) +
                          " mm, its 4th column over fx)");
      }
    } else if (last != std::vector<double>{0, 0, 0, 1}) {
      Fail(options, expected + " (the 4th line holds " + std::to_string(last.size()) + " numbers)");
    }
  }
  if (intrinsics.baseline_mm == 0) intrinsics.baseline_mm = projected_baseline_mm;
  return intrinsics;
}

}  // namespace

FrameSource EndomapperSim(const ImportOptions& options) {
  FrameSource source;
  auto rgb_file = [&](int i) {
    char name[32];
    std::snprintf(name, sizeof name, "image_%04d.png", i);
    return options.input / "rgb" / name;
  };
  auto depth_file = [&](int i) {
    char name[32];
    std::snprintf(name, sizeof name, "aov_image_%04d.exr", i);
    return options.input / "depth" / name;
  };
  while (fs::exists(rgb_file(source.count))) ++source.count;
  if (source.count == 0) Fail(options, "no rgb/image_0000.png");
  for (int i = 0; i < source.count; ++i) {
    if (!fs::exists(depth_file(i))) Fail(options, "missing " + depth_file(i).string());
  }
  const cv::Mat first = ReadImage(options, rgb_file(0), cv::IMREAD_COLOR);
  source.camera = options.calibration.empty()
                      ? Camera::Pinhole(first.cols, first.rows, 472.6496, 472.6496, 0.5 * (first.cols - 1),
                                        0.5 * (first.rows - 1))
                      : LoadCalibration(options);
  source.rgb = [&options, rgb_file](int i) { return ReadImage(options, rgb_file(i), cv::IMREAD_COLOR); };
  source.depth_mm = [&options, depth_file](int i) {
    const cv::Mat raw = ReadImage(options, depth_file(i), cv::IMREAD_UNCHANGED);
    if (raw.depth() != CV_32F) Fail(options, depth_file(i).string() + " is not a float EXR");
    cv::Mat buffer;
    cv::extractChannel(raw, buffer, raw.channels() >= 3 ? 2 : 0);  // R in OpenCV's BGR order
    cv::Mat depth(buffer.size(), CV_32F, cv::Scalar(0));
    const double near = options.near, far = options.far;
    for (int y = 0; y < buffer.rows; ++y) {
      for (int x = 0; x < buffer.cols; ++x) {
        const double d = buffer.at<float>(y, x);  // Unity reversed Z: 1 at near, 0 at far
        if (!(d > 0.0) || d > 1.0) continue;      // far plane (no surface) or invalid
        const double z = 1.0 / ((1.0 - far / near) / far * (1.0 - d) + (far / near) / far);
        depth.at<float>(y, x) = static_cast<float>(z * options.scene_unit_mm);
      }
    }
    return depth;
  };
  const std::vector<NumberLine> lines = NumberLines(options, "trajectory.csv");
  for (const NumberLine& line : lines) {
    const std::vector<double>& v = line.numbers;
    // The header, when there is one: skipping the first line regardless would shift every pose.
    if (&line == &lines.front() && v.empty()) continue;
    if (v.size() < 7) {
      Fail(options, "trajectory.csv line " + std::to_string(line.line) + ": expected tX;tY;tZ;rX;rY;rZ;rW;time");
    }
    const Eigen::Quaterniond rotation(v[6], v[3], v[4], v[5]);
    if (!IsUnitQuaternion(rotation)) {
      Fail(options, "trajectory.csv line " + std::to_string(line.line) + ": rX;rY;rZ;rW is not a unit quaternion (length " +
                        FormatFixed(rotation.norm(), 4) + ")");
    }
    const Rigid3 camera_from_world(rotation, Eigen::Vector3d(v[0], v[1], v[2]) * options.scene_unit_mm);
    source.world_from_camera.push_back(camera_from_world.Inverse());
  }
  KeepOnePosePerFrame(options, "trajectory.csv", &source);
  return source;
}

// Hamlyn in either of its published layouts: the rectified release (image01/ left, image02/
// right, depth01/) or Endo-Depth-and-Motion's tracking data (color/, depth/), both with depth
// as 16-bit mm. Frames are paired across the folders by the number in their names.
FrameSource Hamlyn(const ImportOptions& options) {
  const bool edam_layout =
      !fs::is_directory(options.input / "image01") && fs::is_directory(options.input / "color");
  const std::string left_folder = edam_layout ? "color" : "image01";
  const std::string depth_folder = edam_layout ? "depth" : "depth01";
  if (!fs::is_directory(options.input)) Fail(options, "is not a folder");
  FrameSource source;
  const std::vector<fs::path> left = ImageFiles(options.input / left_folder);
  if (left.empty()) {
    std::string hint;  // an archive unpacked into a folder of the same name (rectified08/rectified08/)
    for (const auto& entry : fs::directory_iterator(options.input)) {
      if (fs::is_directory(entry.path() / "image01") || fs::is_directory(entry.path() / "color")) {
        hint = "; " + entry.path().string() + " has them: import that folder";
        break;
      }
    }
    Fail(options, "no images in image01/ (the rectified release) or color/ (Endo-Depth-and-Motion's)" + hint);
  }
  const std::map<int, fs::path> right_of_frame =
      edam_layout ? std::map<int, fs::path>() : FilesByFrame(options, {options.input / "image02"});
  const std::map<int, fs::path> depth_of_frame = FilesByFrame(options, {options.input / depth_folder});
  // The file of `folder` (`of_frame`, empty when the folder has none) with the left image's frame number.
  const auto pair_with = [&](const fs::path& left_file, int number, const std::map<int, fs::path>& of_frame,
                             const std::string& folder, std::vector<fs::path>* paired) {
    if (of_frame.empty()) return;
    const auto found = of_frame.find(number);
    if (found == of_frame.end()) {
      Fail(options, folder + "/ has no image of frame " + std::to_string(number) + " (" + left_folder + "/" +
                        left_file.filename().string() + ")");
    }
    paired->push_back(found->second);
  };
  std::vector<fs::path> right, depth;
  for (const fs::path& file : left) {
    const std::optional<int> number = FrameNumberOf(file.stem().string());
    if (!number) Fail(options, left_folder + "/" + file.filename().string() + " has no frame number in its name");
    pair_with(file, *number, right_of_frame, "image02", &right);
    pair_with(file, *number, depth_of_frame, depth_folder, &depth);
  }
  source.count = static_cast<int>(left.size());
  const cv::Mat first = ReadImage(options, left[0], cv::IMREAD_COLOR);
  // With a calibration file, intrinsics.txt (if there) gives only the baseline.
  const bool has_intrinsics = options.calibration.empty() || fs::exists(options.input / "intrinsics.txt");
  const HamlynIntrinsics intrinsics = has_intrinsics ? ReadHamlynIntrinsics(options) : HamlynIntrinsics();
  source.camera =
      options.calibration.empty()
          ? Camera::Pinhole(first.cols, first.rows, intrinsics.fx, intrinsics.fy, intrinsics.cx, intrinsics.cy)
          : LoadCalibration(options);
  source.rgb = [&options, left](int i) { return ReadImage(options, left[i], cv::IMREAD_COLOR); };
  if (!right.empty() && intrinsics.baseline_mm == 0 && options.stereo_depth) {
    Fail(options, "--stereo-depth needs the baseline, which intrinsics.txt does not give (a line after K, in mm)");
  }
  if (!right.empty() && intrinsics.baseline_mm > 0) {
    source.baseline_mm = intrinsics.baseline_mm;
    source.right = [&options, right](int i) { return ReadImage(options, right[i], cv::IMREAD_COLOR); };
  }
  if (!depth.empty()) {
    source.depth_mm = [&options, depth](int i) {
      const cv::Mat raw = ReadImage(options, depth[i], cv::IMREAD_UNCHANGED);
      if (raw.type() != CV_16UC1) Fail(options, depth[i].string() + " is not a 16-bit single-channel image");
      cv::Mat mm;
      raw.convertTo(mm, CV_32F);  // already mm
      return mm;
    };
  }
  return source;
}

FrameSource C3vd(const ImportOptions& options) {
  if (options.calibration.empty()) Fail(options, "needs --calibration (a camera JSON)");
  FrameSource source;
  const std::vector<fs::path> colour = ImageFiles(options.input, "_color");
  if (colour.empty()) Fail(options, "no N_color.png frames");
  // C3VD writes colour without leading zeros ("12_color.png") and depth with four
  // ("0012_depth.tiff"), in the sequence's folder or, in its later release, in depth/.
  const std::map<int, fs::path> depth_of_frame =
      FilesByFrame(options, {options.input, options.input / "depth"}, "_depth");
  std::vector<fs::path> depth;
  for (int frame = 0; frame < static_cast<int>(colour.size()); ++frame) {
    // pose.txt has no frame numbers: its lines are frames 0, 1, 2 …, so the images must be too.
    if (FrameNumberOf(colour[frame].stem().string()) != frame) {
      Fail(options, colour[frame].filename().string() + " is where frame " + std::to_string(frame) +
                        " should be: the colour images must be numbered 0, 1, 2 … as pose.txt's lines are");
    }
    const auto found = depth_of_frame.find(frame);
    if (found == depth_of_frame.end()) {
      Fail(options, "no depth of frame " + std::to_string(frame) + " (" + std::to_string(frame) +
                        "_depth.tiff, with leading zeros or none, here or in depth/)");
    }
    depth.push_back(found->second);
  }
  source.count = static_cast<int>(colour.size());
  source.camera = LoadCalibration(options);
  source.rgb = [&options, colour](int i) { return ReadImage(options, colour[i], cv::IMREAD_COLOR); };
  source.depth_mm = [&options, depth](int i) {
    const cv::Mat raw = ReadImage(options, depth[i], cv::IMREAD_UNCHANGED);
    if (raw.type() != CV_16UC1) Fail(options, depth[i].string() + " is not a 16-bit single-channel TIFF");
    cv::Mat mm;
    raw.convertTo(mm, CV_32F, 100.0 / 65535.0);
    return mm;
  };
  for (const NumberLine& line : NumberLines(options, "pose.txt")) {
    const std::vector<double>& v = line.numbers;
    if (v.size() != 16) {
      Fail(options, "pose.txt line " + std::to_string(line.line) + ": expected 16 numbers (a 4x4 matrix)");
    }
    // Row-major keeps the translation in entries 3, 7, 11; column-major in 12, 13, 14.
    const bool column_major = std::abs(v[12]) + std::abs(v[13]) + std::abs(v[14]) > std::abs(v[3]) + std::abs(v[7]) + std::abs(v[11]);
    Eigen::Matrix4d matrix;
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) matrix(r, c) = column_major ? v[c * 4 + r] : v[r * 4 + c];
    }
    const Eigen::Matrix3d rotation = matrix.topLeftCorner<3, 3>();
    if (!IsRotation(rotation)) {
      Fail(options, "pose.txt line " + std::to_string(line.line) + ": not a rotation");
    }
    source.world_from_camera.emplace_back(Eigen::Quaterniond(rotation), matrix.topRightCorner<3, 1>());
  }
  KeepOnePosePerFrame(options, "pose.txt", &source);
  return source;
}

}  // namespace nrslam::importer
