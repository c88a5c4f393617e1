#include "nrslam/datasets/dataset_import.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <opencv2/videoio/registry.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string_view>

#include "nrslam/datasets/stereo_depth.h"
#include "nrslam/datasets/stereo_rectification.h"
#include "nrslam/geometry/rigid3.h"
#include "nrslam/io/camera_file.h"
#include "nrslam/io/sequence_info.h"
#include "nrslam/io/sequence_writer.h"
#include "nrslam/util/error.h"
#include "nrslam/util/source_revision.h"
#include "nrslam/util/text_file.h"

namespace nrslam {
namespace fs = std::filesystem;

namespace {

// What an importer found: per-frame readers and the sequence-level facts.
struct FrameSource {
  int count = 0;
  Camera camera;
  std::function<cv::Mat(int)> rgb;       // BGR
  std::function<cv::Mat(int)> depth_mm;  // CV_32F mm, 0 = none; empty when no depth
  std::function<cv::Mat(int)> right;     // empty when no right camera
  double baseline_mm = 0.0;
  std::vector<Rigid3> world_from_camera;  // per frame, or empty
  nlohmann::json provenance = nlohmann::json::object();  // what the importer did beyond reading
};

[[noreturn]] void Fail(const ImportOptions& options, const std::string& message) {
  throw Error(options.format + " dataset " + options.input.string() + ": " + message);
}

// A text file of the dataset (poses, intrinsics), opened to read; Fail when it is missing or a
// folder has its name.
std::ifstream OpenText(const ImportOptions& options, const std::string& name) {
  if (!fs::exists(options.input / name)) Fail(options, "missing " + name);
  try {
    return OpenToRead(options.input / name, "text file");
  } catch (const Error& e) {
    Fail(options, e.what());
  }
}

cv::Mat ReadImage(const ImportOptions& options, const fs::path& file, int flags) {
  // Checked first: OpenCV would print a warning of its own before our message.
  if (!fs::is_regular_file(file)) Fail(options, file.string() + " does not exist");
  cv::Mat image = cv::imread(file.string(), flags);
  if (image.empty()) Fail(options, "cannot read " + file.string() + " (missing or corrupt)");
  return image;
}

bool IsDigit(char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }

// Name order that reads each run of digits as a number, so that "frame_2.png" comes before
// "frame_10.png": folders numbered without leading zeros (ffmpeg's %d, C3VD's "12_color.png")
// keep their frames' order. Names that differ only in leading zeros fall back to plain order.
bool NumberAwareLess(const std::string& a, const std::string& b) {
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (!IsDigit(a[i]) || !IsDigit(b[j])) {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i, ++j;
      continue;
    }
    size_t end_a = i, end_b = j;
    while (end_a < a.size() && IsDigit(a[end_a])) ++end_a;
    while (end_b < b.size() && IsDigit(b[end_b])) ++end_b;
    while (i + 1 < end_a && a[i] == '0') ++i;
    while (j + 1 < end_b && b[j] == '0') ++j;
    const std::string_view number_a(a.data() + i, end_a - i), number_b(b.data() + j, end_b - j);
    if (number_a.size() != number_b.size()) return number_a.size() < number_b.size();
    if (number_a != number_b) return number_a < number_b;
    i = end_a, j = end_b;
  }
  if (i == a.size() && j == b.size()) return a < b;
  return i == a.size();
}

// Image files of a folder, in NumberAwareLess order of their names.
std::vector<fs::path> ImageFiles(const fs::path& folder, const std::string& suffix = "") {
  std::vector<fs::path> files;
  if (!fs::is_directory(folder)) return files;
  for (const auto& entry : fs::directory_iterator(folder)) {
    std::string extension = entry.path().extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(), ::tolower);
    const bool image = extension == ".png" || extension == ".jpg" || extension == ".jpeg" || extension == ".bmp" ||
                       extension == ".tif" || extension == ".tiff";
    const std::string stem = entry.path().stem().string();
    const bool matches = suffix.empty() || (stem.size() > suffix.size() && stem.compare(stem.size() - suffix.size(), suffix.size(), suffix) == 0);
    if (entry.is_regular_file() && image && matches) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end(), [](const fs::path& a, const fs::path& b) {
    return NumberAwareLess(a.filename().string(), b.filename().string());
  });
  return files;
}

// The image files of `folders` whose stems end in `suffix`, by the frame number in their names
// (FrameNumberOf); files without one are left out, and two files of one frame are refused.
std::map<int, fs::path> FilesByFrame(const ImportOptions& options, const std::vector<fs::path>& folders,
                                     const std::string& suffix = "") {
  std::map<int, fs::path> of_frame;
  for (const fs::path& folder : folders) {
    for (const fs::path& file : ImageFiles(folder, suffix)) {
      const std::optional<int> number = FrameNumberOf(file.stem().string());
      if (!number) continue;
      if (const auto [kept, added] = of_frame.emplace(*number, file); !added) {
        Fail(options, "two images of frame " + std::to_string(*number) + ": " + kept->second.string() + " and " +
                          file.string());
      }
    }
  }
  return of_frame;
}

std::vector<double> Numbers(const std::string& line) {
  std::string spaced = line;
  std::replace(spaced.begin(), spaced.end(), ',', ' ');
  std::replace(spaced.begin(), spaced.end(), ';', ' ');
  std::istringstream stream(spaced);
  std::vector<double> numbers;
  std::string token;
  while (stream >> token) {
    char* end = nullptr;
    const double value = std::strtod(token.c_str(), &end);
    if (end == token.c_str() || *end != '\0') return {};  // not a line of numbers
    numbers.push_back(value);
  }
  return numbers;
}

// A ground-truth file needs a pose for every frame; extra poses (a longer recording) are cut.
void KeepOnePosePerFrame(const ImportOptions& options, const std::string& file, FrameSource* source) {
  if (static_cast<int>(source->world_from_camera.size()) < source->count) {
    Fail(options, file + " has " + std::to_string(source->world_from_camera.size()) + " poses for " +
                      std::to_string(source->count) + " frames");
  }
  source->world_from_camera.resize(source->count);
}

Camera LoadCalibration(const ImportOptions& options) {
  try {
    return ReadCameraFile(options.calibration);
  } catch (const Error& e) {
    Fail(options, e.what());
  }
}

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
  std::ifstream trajectory = OpenText(options, "trajectory.csv");
  std::string line;
  for (int row = 1; std::getline(trajectory, line); ++row) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::vector<double> v = Numbers(line);
    if (row == 1 && v.empty()) continue;  // the header, when there is one: skipping a pose would shift them all
    if (v.size() < 7) Fail(options, "trajectory.csv line " + std::to_string(row) + ": expected tX;tY;tZ;rX;rY;rZ;rW;time");
    const Rigid3 camera_from_world(Eigen::Quaterniond(v[6], v[3], v[4], v[5]),
                                   Eigen::Vector3d(v[0], v[1], v[2]) * options.scene_unit_mm);
    source.world_from_camera.push_back(camera_from_world.Inverse());
  }
  KeepOnePosePerFrame(options, "trajectory.csv", &source);
  return source;
}

// What a Hamlyn intrinsics.txt gives: the rectified pinhole and, when it has one, the baseline.
struct HamlynIntrinsics {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  double baseline_mm = 0;  // 0: not given
};

// K as three rows of 3 numbers, or of 4 (a 3×4 projection matrix, whose last column says
// nothing of K), or four rows of 4 (a homogeneous 4×4, last row 0 0 0 1); then, optionally,
// one line holding the baseline in mm. Read by rows: taken as one list of numbers, a 3×4 put
// 0 where fy is.
HamlynIntrinsics ReadHamlynIntrinsics(const ImportOptions& options) {
  std::ifstream file = OpenText(options, "intrinsics.txt");
  std::vector<std::vector<double>> rows;
  std::string line;
  for (int number = 1; std::getline(file, line); ++number) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    rows.push_back(Numbers(line));
    if (rows.back().empty()) Fail(options, "intrinsics.txt line " + std::to_string(number) + " is not a row of numbers");
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
  if (rows.size() == 4) {
    const std::vector<double>& last = rows[3];
    if (last.size() == 1) {
      if (last[0] == 0) Fail(options, "intrinsics.txt: the baseline (after K) is 0 mm");
      intrinsics.baseline_mm = std::abs(last[0]);
    } else if (last != std::vector<double>{0, 0, 0, 1}) {
      Fail(options, expected + " (the 4th line holds " + std::to_string(last.size()) + " numbers)");
    }
  }
  return intrinsics;
}

// Hamlyn in either of its published layouts: the rectified release (image01/ left, image02/
// right, depth01/) or Endo-Depth-and-Motion's tracking data (color/, depth/), both with depth
// as 16-bit mm. Frames are paired across the folders by the number in their names.
FrameSource Hamlyn(const ImportOptions& options) {
  const bool edam_layout = !fs::is_directory(options.input / "image01") && fs::is_directory(options.input / "color");
  const std::string left_folder = edam_layout ? "color" : "image01", depth_folder = edam_layout ? "depth" : "depth01";
  FrameSource source;
  const std::vector<fs::path> left = ImageFiles(options.input / left_folder);
  if (!fs::is_directory(options.input)) Fail(options, "is not a folder");
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
  std::vector<fs::path> right, depth;
  for (const fs::path& file : left) {
    const std::optional<int> number = FrameNumberOf(file.stem().string());
    if (!number) Fail(options, left_folder + "/" + file.filename().string() + " has no frame number in its name");
    const auto pair_with = [&](const std::map<int, fs::path>& of_frame, const std::string& folder, std::vector<fs::path>* paired) {
      if (of_frame.empty()) return;
      const auto found = of_frame.find(*number);
      if (found == of_frame.end()) {
        Fail(options, folder + "/ has no image of frame " + std::to_string(*number) + " (" + left_folder + "/" +
                          file.filename().string() + ")");
      }
      paired->push_back(found->second);
    };
    pair_with(right_of_frame, "image02", &right);
    pair_with(depth_of_frame, depth_folder, &depth);
  }
  source.count = static_cast<int>(left.size());
  const cv::Mat first = ReadImage(options, left[0], cv::IMREAD_COLOR);
  // With a calibration file, intrinsics.txt (if there) gives only the baseline.
  const bool has_intrinsics = options.calibration.empty() || fs::exists(options.input / "intrinsics.txt");
  const HamlynIntrinsics intrinsics = has_intrinsics ? ReadHamlynIntrinsics(options) : HamlynIntrinsics();
  source.camera = options.calibration.empty()
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
  const std::map<int, fs::path> depth_of_frame = FilesByFrame(options, {options.input, options.input / "depth"}, "_depth");
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
  std::ifstream poses = OpenText(options, "pose.txt");
  std::string line;
  for (int row = 1; std::getline(poses, line); ++row) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::vector<double> v = Numbers(line);
    if (v.size() != 16) Fail(options, "pose.txt line " + std::to_string(row) + ": expected 16 numbers (a 4x4 matrix)");
    // Row-major keeps the translation in entries 3, 7, 11; column-major in 12, 13, 14.
    const bool column_major = std::abs(v[12]) + std::abs(v[13]) + std::abs(v[14]) > std::abs(v[3]) + std::abs(v[7]) + std::abs(v[11]);
    Eigen::Matrix4d matrix;
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) matrix(r, c) = column_major ? v[c * 4 + r] : v[r * 4 + c];
    }
    const Eigen::Matrix3d rotation = matrix.topLeftCorner<3, 3>();
    if (!IsRotation(rotation)) {
      Fail(options, "pose.txt line " + std::to_string(row) + ": not a rotation");
    }
    source.world_from_camera.emplace_back(Eigen::Quaterniond(rotation), matrix.topRightCorner<3, 1>());
  }
  KeepOnePosePerFrame(options, "pose.txt", &source);
  return source;
}

// FFmpeg, where OpenCV has it, rather than every backend in turn: the others print their own
// failures (GStreamer an assertion and a stack of warnings) above ours for a file none can open.
cv::VideoCapture OpenVideo(const fs::path& file) {
  const int backend = cv::videoio_registry::hasBackend(cv::CAP_FFMPEG) ? cv::CAP_FFMPEG : cv::CAP_ANY;
  return cv::VideoCapture(file.string(), backend);
}

// The frames of an image folder (sorted by name) or a video file: their count and a reader,
// which for a video only goes forward (frames skipped over are grabbed, not decoded).
struct FrameStream {
  int count = 0;
  std::function<cv::Mat(int)> read;  // BGR
};

FrameStream OpenFrames(const ImportOptions& options, const fs::path& input) {
  FrameStream stream;
  if (fs::is_directory(input)) {
    const std::vector<fs::path> files = ImageFiles(input);
    if (files.empty()) Fail(options, "no image files in " + input.string());
    stream.count = static_cast<int>(files.size());
    stream.read = [&options, files](int i) { return ReadImage(options, files[i], cv::IMREAD_COLOR); };
    return stream;
  }
  // A video: count the frames first (grab without decoding), then decode them in order.
  if (!fs::exists(input)) Fail(options, input.string() + " does not exist");
  cv::VideoCapture counter = OpenVideo(input);
  if (!counter.isOpened()) Fail(options, "cannot open " + input.string() + " as an image folder or a video");
  while (counter.grab()) ++stream.count;
  if (stream.count == 0) Fail(options, "the video " + input.string() + " has no frames");
  auto video = std::make_shared<cv::VideoCapture>(OpenVideo(input));
  auto next = std::make_shared<int>(0);  // the frame the video decodes next
  stream.read = [&options, video, next, input](int i) {
    if (i < *next) {
      Fail(options,
           "frame " + std::to_string(i) + " of " + input.string() + " asked for after frame " + std::to_string(*next));
    }
    cv::Mat frame;
    while (*next < i && video->grab()) ++*next;  // frames skipped (--frame-step) are not decoded
    if (*next != i || !video->read(frame)) {
      Fail(options, "cannot decode frame " + std::to_string(i) + " of " + input.string());
    }
    ++*next;
    return frame;
  };
  return stream;
}

FrameSource Images(const ImportOptions& options) {
  if (options.calibration.empty()) Fail(options, "needs --calibration (a camera JSON)");
  FrameSource source;
  source.camera = LoadCalibration(options);
  const FrameStream frames = OpenFrames(options, options.input);
  source.count = frames.count;
  source.rgb = frames.read;
  return source;
}

// A raw stereo recording: the left and right images as two streams, or one stream whose images
// hold both (side by side, or the left above the right), rectified with the pair's calibration.
FrameSource Stereo(const ImportOptions& options) {
  if (options.calibration.empty()) {
    Fail(options,
         "needs --calibration: the pair's stereo calibration (OpenCV's M1 D1 M2 D2 R T, Kalibr's camchain, or "
         "the left camera's ROS camera_info with the right one's as --second-calibration)");
  }
  const bool packed = !options.stereo_layout.empty();
  if (packed == !options.right.empty()) {
    Fail(options, "needs either --right (the right camera's images) or --stereo-layout (both in one image)");
  }
  const FrameStream left = OpenFrames(options, options.input);
  const FrameStream right = packed ? left : OpenFrames(options, options.right);
  if (right.count != left.count) {
    Fail(options,
         "the right camera has " + std::to_string(right.count) + " frames, the left " + std::to_string(left.count));
  }
  // One image holding both views splits in halves; the calibration is of one view.
  const bool side_by_side = options.stereo_layout == "side-by-side";
  const auto half = [&options, side_by_side](const cv::Mat& both, int index, int i) {
    const int width = side_by_side ? both.cols / 2 : both.cols, height = side_by_side ? both.rows : both.rows / 2;
    if ((side_by_side ? both.cols : both.rows) % 2 != 0) {
      Fail(options, "frame " + std::to_string(i) + " is " + std::to_string(both.cols) + "x" +
                        std::to_string(both.rows) + ", which does not split into two equal views");
    }
    const cv::Rect view =
        side_by_side ? cv::Rect(index * width, 0, width, height) : cv::Rect(0, index * height, width, height);
    return both(view);  // a view into the decoded frame, which stays alive while it is used
  };
  // The left stream's last decoded frame: a video decodes in order, and a packed frame holds
  // the right view too.
  auto decoded = std::make_shared<std::pair<int, cv::Mat>>(0, left.read(0));
  const auto left_frame = [left, decoded](int i) -> const cv::Mat& {
    if (decoded->first != i) *decoded = {i, left.read(i)};
    return decoded->second;
  };
  const cv::Mat first = packed ? half(decoded->second, 0, 0) : decoded->second;
  std::vector<fs::path> calibration_files = {options.calibration};
  if (!options.second_calibration.empty()) calibration_files.push_back(options.second_calibration);
  StereoCalibration calibration;
  try {
    calibration =
        ReadStereoCalibration(calibration_files, std::make_pair(first.cols, first.rows), options.stereo_unit_mm);
  } catch (const Error& e) {
    Fail(options, e.what());
  }
  if (first.cols != calibration.left.width() || first.rows != calibration.left.height()) {
    Fail(options, "left frame 0 is " + std::to_string(first.cols) + "x" + std::to_string(first.rows) +
                      " but the calibration is " + std::to_string(calibration.left.width()) + "x" +
                      std::to_string(calibration.left.height()));
  }
  StereoRectificationOptions rectification;
  rectification.width = options.rectified_width;
  rectification.height = options.rectified_height;
  rectification.alpha = options.rectify_alpha;
  std::shared_ptr<const StereoRectifier> rectifier;
  try {
    rectifier = std::make_shared<const StereoRectifier>(calibration, rectification);
  } catch (const Error& e) {
    Fail(options, e.what());
  }
  FrameSource source;
  source.count = left.count;
  source.camera = rectifier->camera();
  source.baseline_mm = rectifier->baseline_mm();
  std::vector<std::string> files;
  for (const fs::path& file : calibration_files) files.push_back(fs::absolute(file).string());
  const Eigen::Matrix3d& r1 = rectifier->rectified_from_left();
  source.provenance["rectification"] = {
      {"calibration", files},
      {"alpha", options.rectify_alpha},
      {"raw_left_camera", calibration.left},
      {"raw_right_camera", calibration.right},
      {"rectified_from_raw_left",
       {{r1(0, 0), r1(0, 1), r1(0, 2)}, {r1(1, 0), r1(1, 1), r1(1, 2)}, {r1(2, 0), r1(2, 1), r1(2, 2)}}}};
  const auto raw = [=, &options](bool right_view, int i) {
    const cv::Mat image = packed       ? half(left_frame(i), right_view ? 1 : 0, i)
                          : right_view ? right.read(i)
                                       : left_frame(i);
    if (image.cols != calibration.left.width() || image.rows != calibration.left.height()) {
      Fail(options, std::string(right_view ? "right" : "left") + " frame " + std::to_string(i) + " is " +
                        std::to_string(image.cols) + "x" + std::to_string(image.rows) + " but the " +
                        (right_view ? "left frames and the " : "") + "calibration " + (right_view ? "are " : "is ") +
                        std::to_string(calibration.left.width()) + "x" + std::to_string(calibration.left.height()));
    }
    return image;
  };
  source.rgb = [raw, rectifier](int i) { return rectifier->Left(raw(false, i)); };
  source.right = [raw, rectifier](int i) { return rectifier->Right(raw(true, i)); };
  return source;
}

// An image as written: at `size` (area-averaged down, bilinear up; a depth map by nearest pixel).
cv::Mat Resized(const cv::Mat& image, const cv::Size& size, bool depth) {
  if (image.size() == size) return image;
  cv::Mat resized;
  const int interpolation = depth ? cv::INTER_NEAREST : size.width < image.cols ? cv::INTER_AREA : cv::INTER_LINEAR;
  cv::resize(image, resized, size, 0, 0, interpolation);
  return resized;
}

// Every frame of `source` up to `count`, and its poses, into `writer`, the images resized to
// `written` (the size of the written sequence's camera).
void WriteFrames(const ImportOptions& options, const FrameSource& source, int count, const cv::Size& written,
                 const SequenceWriter& writer) {
  const cv::Size size(source.camera.width(), source.camera.height());
  for (int i = 0; i < count; ++i) {
    const int from = i * options.frame_step;  // the dataset's frame that becomes frame i
    const cv::Mat rgb = source.rgb(from);
    if (rgb.size() != size) {
      Fail(options, "frame " + std::to_string(from) + " is " + std::to_string(rgb.cols) + "x" +
                        std::to_string(rgb.rows) + " but the camera is " + std::to_string(size.width) + "x" +
                        std::to_string(size.height));
    }
    writer.WriteRgb(i, Resized(rgb, written, false));
    const cv::Mat right = source.right ? source.right(from) : cv::Mat();
    if (!right.empty()) writer.WriteRight(i, Resized(right, written, false));
    if (source.depth_mm || options.stereo_depth) {
      // Stereo depth is matched at the source's size, before any --scale: ground truth as fine as
      // the recording gives (halved first, the test's plane came out 2.3× less accurate).
      const cv::Mat depth =
          source.depth_mm ? source.depth_mm(from)
                          : StereoDepthMm(rgb, right, source.camera.fx(), source.baseline_mm, options.stereo_depth_options);
      if (depth.size() != size) {
        Fail(options, "depth of frame " + std::to_string(from) + " has another size than the image");
      }
      writer.WriteDepthMm(i, Resized(depth, written, true));
    }
  }
  if (!source.world_from_camera.empty()) {
    std::vector<StampedPose> poses;
    for (int i = 0; i < count; ++i) {
      const int from = i * options.frame_step;
      poses.push_back({from / options.fps, source.world_from_camera[static_cast<size_t>(from)]});
    }
    writer.WriteGroundtruth(poses);
  }
}

}  // namespace

void ImportOptions::Check() const {
  const std::vector<std::string> formats = ImportFormats();
  if (std::find(formats.begin(), formats.end(), format) == formats.end()) {
    std::string known;
    for (const std::string& name : formats) known += (known.empty() ? "" : ", ") + name;
    throw Error("unknown dataset format '" + format + "' (known: " + known + ")");
  }
  if (!fs::exists(input)) throw Error(format + " dataset: " + input.string() + " does not exist");
  if (frame_step < 1) throw Error("import options: frame_step must be >= 1, got " + std::to_string(frame_step));
  if (!(fps > 0) || max_frames < 0 || !(depth_unit_mm > 0) || !(near > 0) || !(far > near) || !(scene_unit_mm > 0)) {
    throw Error("import options: need fps > 0, max_frames >= 0, depth_unit_mm > 0, 0 < near < far, scene_unit_mm > 0");
  }
  if (!(scale > 0 && scale <= 4)) throw Error("import options: scale must be in (0, 4], got " + std::to_string(scale));
  const bool stereo_option = !right.empty() || !second_calibration.empty() || !stereo_layout.empty() ||
                             rectified_width != 0 || rectified_height != 0 || rectify_alpha != 0.0 ||
                             stereo_unit_mm != 0.0;
  if (stereo_option && format != "stereo") {
    throw Error(
        "import options: the right images, stereo layout, second calibration and rectification apply to --format "
        "stereo only");
  }
  if (!stereo_layout.empty() && stereo_layout != "side-by-side" && stereo_layout != "top-bottom") {
    throw Error("import options: stereo layout must be side-by-side or top-bottom, got '" + stereo_layout + "'");
  }
  if (stereo_unit_mm < 0) {
    throw Error("import options: stereo_unit_mm must be > 0 (or 0: the calibration format's own)");
  }
  StereoRectificationOptions{rectified_width, rectified_height, rectify_alpha}.Check();
  stereo_depth_options.Check();
}

std::vector<std::string> ImportFormats() { return {"endomapper-sim", "hamlyn", "c3vd", "images", "stereo"}; }

SequenceInfo ImportDataset(const ImportOptions& options, const fs::path& out) {
  options.Check();
  // OpenCV 4.6 reads EXR only when asked to (CVE hardening); the Endomapper depth is EXR.
  setenv("OPENCV_IO_ENABLE_OPENEXR", "1", 0);
  FrameSource source = options.format == "endomapper-sim" ? EndomapperSim(options)
                       : options.format == "hamlyn"       ? Hamlyn(options)
                       : options.format == "c3vd"         ? C3vd(options)
                       : options.format == "stereo"       ? Stereo(options)
                                                          : Images(options);
  const int kept = (source.count + options.frame_step - 1) / options.frame_step;
  const int count = options.max_frames > 0 ? std::min(options.max_frames, kept) : kept;
  SequenceInfo info;
  info.camera = options.scale == 1.0
                    ? source.camera
                    : source.camera.Resized(std::max(1, static_cast<int>(std::lround(source.camera.width() * options.scale))),
                                            std::max(1, static_cast<int>(std::lround(source.camera.height() * options.scale))));
  info.fps = options.fps / options.frame_step;
  info.frame_count = count;
  info.depth_unit_mm = options.depth_unit_mm;
  if (source.right) info.stereo = StereoInfo{source.baseline_mm, info.camera};
  info.provenance = {{"generator", std::string("nrslam_import ") + NRSLAM_VERSION},
                     {"code", SequenceCodeFingerprint()},
                     {"format", options.format},
                     {"source", fs::absolute(options.input).string()}};
  info.provenance.update(source.provenance);
  if (options.frame_step != 1) info.provenance["frame_step"] = options.frame_step;  // frame i was the dataset's i·step
  if (options.scale != 1.0) {
    info.provenance["scale"] = options.scale;
    info.provenance["source_camera"] = source.camera;
  }
  cv::Mat mask;
  if (!options.mask.empty()) {
    mask = ReadImage(options, options.mask, cv::IMREAD_GRAYSCALE);
    if (mask.cols != source.camera.width() || mask.rows != source.camera.height()) {
      Fail(options, "the mask " + options.mask.string() + " is " + std::to_string(mask.cols) + "x" +
                        std::to_string(mask.rows) + " but the images are " + std::to_string(source.camera.width()) +
                        "x" + std::to_string(source.camera.height()));
    }
    mask = Resized(mask, cv::Size(info.camera.width(), info.camera.height()), true) > 0;
    if (cv::countNonZero(mask) == 0) Fail(options, "the mask " + options.mask.string() + " leaves no pixel usable");
    info.mask = "mask.png";
  }
  if (options.stereo_depth) {
    if (!source.right) Fail(options, "--stereo-depth needs the right camera's images");
    if (source.depth_mm) Fail(options, "--stereo-depth: the dataset has depth of its own");
    info.provenance["depth"] = {{"generator", std::string("nrslam_import --stereo-depth ") + NRSLAM_VERSION},
                                {"options", nlohmann::json(options.stereo_depth_options)}};
  }
  const SequenceWriter writer(out, info, source.depth_mm || options.stereo_depth);
  try {
    if (!mask.empty()) writer.WriteFixedMask(mask);
    WriteFrames(options, source, count, cv::Size(info.camera.width(), info.camera.height()), writer);
  } catch (...) {
    // Half a sequence would pass for a whole one until its missing frames are read: a failed
    // import leaves none.
    try {
      RemoveSequence(out);
    } catch (const Error&) {
      // The import's own error says more than a failed clean-up.
    }
    throw;
  }
  return info;
}

}  // namespace nrslam
