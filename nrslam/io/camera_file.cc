#include "nrslam/io/camera_file.h"

#include <opencv2/core.hpp>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <optional>
#include <sstream>
#include <vector>

#include "nrslam/util/json_options.h"

namespace nrslam {
namespace {

// The numbers of one line; Error when something in it is not a number.
std::vector<double> Numbers(const std::string& line, const std::string& part) {
  std::istringstream stream(line);
  std::vector<double> numbers;
  double value;
  while (stream >> value) numbers.push_back(value);
  if (!stream.eof()) throw Error("OCamCalib " + part + ": not a list of numbers: '" + line + "'");
  return numbers;
}

// A polynomial written as its coefficient count, then the coefficients.
std::vector<double> Polynomial(const std::string& line, const std::string& part) {
  std::vector<double> numbers = Numbers(line, part);
  if (numbers.empty() || numbers[0] != static_cast<int>(numbers[0]) ||
      static_cast<size_t>(numbers[0]) + 1 != numbers.size()) {
    throw Error("OCamCalib " + part + ": the first number must count the coefficients after it: '" + line + "'");
  }
  return std::vector<double>(numbers.begin() + 1, numbers.end());
}

std::vector<double> Exactly(size_t count, const std::string& line, const std::string& part) {
  std::vector<double> numbers = Numbers(line, part);
  if (numbers.size() != count) {
    throw Error("OCamCalib " + part + ": expected " + std::to_string(count) + " numbers, got '" + line + "'");
  }
  return numbers;
}

// The numbers of an OpenCV calibration entry: a list, or a map holding them under "data" (an
// opencv-matrix, ROS's {rows, cols, data}).
std::vector<double> EntryNumbers(const cv::FileNode& node, const std::string& key) {
  if (node.isReal() || node.isInt()) return {static_cast<double>(node)};
  const cv::FileNode list = node.isMap() ? node["data"] : node;
  if (!list.isSeq()) throw Error("'" + key + "' is neither a list of numbers nor a matrix with 'data'");
  std::vector<double> numbers;
  for (const cv::FileNode& item : list) {
    if (!item.isReal() && !item.isInt()) throw Error("'" + key + "' holds something that is not a number");
    numbers.push_back(static_cast<double>(item));
  }
  return numbers;
}

// The first of `keys` the file has: its key and node; an empty key when none is there.
std::pair<std::string, cv::FileNode> FirstEntry(const cv::FileStorage& storage, std::initializer_list<const char*> keys) {
  for (const char* key : keys) {
    const cv::FileNode node = storage[key];
    if (!node.empty() && !node.isNone()) return {key, node};
  }
  return {"", cv::FileNode()};
}

std::string Lowercase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
  return text;
}

std::string FileText(const std::filesystem::path& file) {
  std::ifstream stream(file);
  std::ostringstream text;
  text << stream.rdbuf();
  return text.str();
}

bool IsOpenCvCalibration(const std::filesystem::path& file, char first) {
  const std::string extension = Lowercase(file.extension().string());
  return first == '%' || first == '<' || extension == ".yml" || extension == ".yaml" || extension == ".xml";
}

// The file opened by cv::FileStorage from its text. OpenCV's YAML reader wants the version
// directive its writer puts first; ROS leaves it out, so it is added when missing.
cv::FileStorage OpenCalibrationStorage(const std::filesystem::path& file) {
  std::string contents = FileText(file);
  const size_t first = contents.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && contents[first] != '%' && contents[first] != '<') {
    contents = "%YAML:1.0\n---\n" + contents;
  }
  cv::FileStorage storage;
  try {
    storage.open(contents, cv::FileStorage::READ | cv::FileStorage::MEMORY);
  } catch (const cv::Exception& e) {
    throw Error("not a calibration OpenCV can read (YAML or XML): " + e.err);
  }
  if (!storage.isOpened()) throw Error("OpenCV cannot open it as a calibration (YAML or XML)");
  return storage;
}

std::string KeyList(std::initializer_list<const char*> keys) {
  std::string list;
  for (const char* key : keys) list += std::string(list.empty() ? "" : ", ") + key;
  return list;
}

// The image size the file states (image_width and image_height, or image_size / imageSize as
// [width, height]); `fallback` when it states none and the caller knows it, else Error.
std::pair<int, int> CalibrationImageSize(const cv::FileStorage& storage, std::optional<std::pair<int, int>> fallback) {
  const auto [size_key, size_node] = FirstEntry(storage, {"image_size", "imageSize"});
  if (!storage["image_width"].empty() && !storage["image_height"].empty()) {
    return {static_cast<int>(storage["image_width"]), static_cast<int>(storage["image_height"])};
  }
  if (!size_key.empty()) {
    const std::vector<double> size = EntryNumbers(size_node, size_key);
    if (size.size() != 2) throw Error("'" + size_key + "' must be [width, height]");
    return {static_cast<int>(size[0]), static_cast<int>(size[1])};
  }
  if (fallback) return *fallback;
  throw Error("no image size (image_width and image_height, or image_size): add the size the calibration was made at");
}

// One camera of the file: its matrix under the first of `matrix_keys` it has, its distortion
// under the first of `distortion_keys` (none = pinhole), its model from distortion_model.
Camera ReadOpenCvCamera(const cv::FileStorage& storage, std::initializer_list<const char*> matrix_keys,
                        std::initializer_list<const char*> distortion_keys, std::pair<int, int> size) {
  const auto [matrix_key, matrix_node] = FirstEntry(storage, matrix_keys);
  if (matrix_key.empty()) throw Error("no camera matrix (" + KeyList(matrix_keys) + ")");
  const std::vector<double> k = EntryNumbers(matrix_node, matrix_key);
  if (k.size() != 9) throw Error("'" + matrix_key + "' must be 3x3, has " + std::to_string(k.size()) + " numbers");
  if (k[1] != 0.0 || k[3] != 0.0 || k[6] != 0.0 || k[7] != 0.0 || k[8] != 1.0) {
    throw Error("'" + matrix_key + "' must be [fx 0 cx; 0 fy cy; 0 0 1] (no skew)");
  }
  const auto [width, height] = size;

  const auto [distortion_key, distortion_node] = FirstEntry(storage, distortion_keys);
  std::vector<double> distortion =
      distortion_key.empty() ? std::vector<double>() : EntryNumbers(distortion_node, distortion_key);
  const cv::FileNode model_node = storage["distortion_model"];
  const std::string model = model_node.isString() ? Lowercase(static_cast<std::string>(model_node)) : "";
  const bool fisheye = model == "equidistant" || model == "fisheye" || model == "kannala_brandt";
  if (!model.empty() && !fisheye && model != "plumb_bob" && model != "radtan" && model != "rational_polynomial") {
    throw Error("unknown distortion_model '" + model +
                "' (known: plumb_bob, radtan, rational_polynomial, equidistant, fisheye, kannala_brandt)");
  }
  // ROS writes an empty list for an undistorted camera; 5 zeros are the same camera.
  const bool undistorted = std::all_of(distortion.begin(), distortion.end(), [](double d) { return d == 0.0; });
  const double fx = k[0], fy = k[4], cx = k[2], cy = k[5];
  if (fisheye) {
    if (distortion.size() != 4) {
      throw Error("the fisheye (equidistant) model needs 4 distortion coefficients, got " +
                  std::to_string(distortion.size()) + (distortion_key.empty() ? "" : " in '" + distortion_key + "'"));
    }
    return Camera::KannalaBrandt(width, height, fx, fy, cx, cy,
                                 Eigen::Vector4d(distortion[0], distortion[1], distortion[2], distortion[3]));
  }
  if (model.empty() && distortion.size() == 4) {
    throw Error("4 distortion coefficients could be OpenCV's k1 k2 p1 p2 or its fisheye model's k1 k2 k3 k4: say "
                "which with distortion_model: plumb_bob or distortion_model: equidistant");
  }
  if (undistorted) return Camera::Pinhole(width, height, fx, fy, cx, cy);
  return Camera::OpenCv(width, height, fx, fy, cx, cy, distortion);
}

}  // namespace

Camera ReadOpenCvCalibration(const std::filesystem::path& file) {
  const cv::FileStorage storage = OpenCalibrationStorage(file);
  return ReadOpenCvCamera(storage, {"camera_matrix", "cameraMatrix", "K", "M1"},
                          {"distortion_coefficients", "dist_coeffs", "distCoeffs", "D", "D1"},
                          CalibrationImageSize(storage, std::nullopt));
}

StereoCalibration ReadStereoCalibration(const std::vector<std::filesystem::path>& files,
                                        std::optional<std::pair<int, int>> image_size, double translation_unit_mm) {
  std::string names;
  for (const std::filesystem::path& file : files) names += (names.empty() ? "" : ", ") + file.string();
  try {
    if (files.empty()) throw Error("no file given");
    if (!(translation_unit_mm > 0)) throw Error("the unit of T must be > 0 mm");
    std::vector<cv::FileStorage> storages;
    for (const std::filesystem::path& file : files) storages.push_back(OpenCalibrationStorage(file));
    // Each entry comes from the first file that has it: OpenCV's stereo_calib sample writes the
    // intrinsics (M1 D1 M2 D2) and the extrinsics (R T) to two files.
    const auto holding = [&](const char* key) -> const cv::FileStorage& {
      for (const cv::FileStorage& storage : storages) {
        if (!FirstEntry(storage, {key}).first.empty()) return storage;
      }
      throw Error(std::string("no '") + key + "'");
    };
    const std::pair<int, int> size = CalibrationImageSize(holding("M1"), image_size);
    StereoCalibration stereo;
    stereo.left = ReadOpenCvCamera(holding("M1"), {"M1"}, {"D1"}, size);
    stereo.right = ReadOpenCvCamera(holding("M2"), {"M2"}, {"D2"}, size);
    const std::vector<double> r = EntryNumbers(holding("R")["R"], "R");
    const std::vector<double> t = EntryNumbers(holding("T")["T"], "T");
    if (r.size() != 9) throw Error("'R' must be a 3x3 rotation, has " + std::to_string(r.size()) + " numbers");
    if (t.size() != 3) throw Error("'T' must be 3 numbers, has " + std::to_string(t.size()));
    const Eigen::Matrix3d rotation = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(r.data());
    if ((rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).norm() > 1e-3 || rotation.determinant() < 0) {
      throw Error("'R' is not a rotation");
    }
    stereo.right_from_left = Rigid3(Eigen::Quaterniond(rotation), Eigen::Vector3d(t[0], t[1], t[2]) * translation_unit_mm);
    stereo.left.Check();
    stereo.right.Check();
    return stereo;
  } catch (const std::exception& e) {
    throw Error("stereo calibration " + names + ": " + e.what());
  }
}

Camera ParseOcamCalibResults(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream stream(text);
  std::string line;
  while (std::getline(stream, line)) {
    const size_t first = line.find_first_not_of(" \t\r");
    if (first != std::string::npos && line[first] != '#') lines.push_back(line);
  }
  if (lines.size() != 5) {
    throw Error("OCamCalib calib_results.txt: expected 5 lines of numbers (ss, invpol, centre, affine, size), got " +
                std::to_string(lines.size()));
  }
  const std::vector<double> direct = Polynomial(lines[0], "direct polynomial (ss)");
  const std::vector<double> inverse = Polynomial(lines[1], "inverse polynomial (invpol)");
  const std::vector<double> centre = Exactly(2, lines[2], "centre (row, column)");
  const std::vector<double> affine = Exactly(3, lines[3], "affine part (c, d, e)");
  const std::vector<double> size = Exactly(2, lines[4], "image size (height, width)");
  if (size[0] != static_cast<int>(size[0]) || size[1] != static_cast<int>(size[1])) {
    throw Error("OCamCalib image size (height, width): not whole numbers: '" + lines[4] + "'");
  }
  Camera camera = Camera::Ocam(static_cast<int>(size[1]), static_cast<int>(size[0]), centre[1], centre[0], affine[0],
                               affine[1], affine[2], direct, inverse);
  camera.Check();
  return camera;
}

Camera ReadCameraFile(const std::filesystem::path& file) {
  try {
    char first = 0;
    if (!std::filesystem::is_directory(file)) std::ifstream(file) >> first;
    if (first != 0 && IsOpenCvCalibration(file, first)) {
      Camera camera = ReadOpenCvCalibration(file);
      camera.Check();
      return camera;
    }
    if (first != 0 && first != '{') {
      // Not a JSON object: OCamCalib's text format.
      return ParseOcamCalibResults(FileText(file));
    }
    const Json json = ReadJsonFile(file);
    // A sequence.json holds the camera under "camera"; taking it saves users cutting it out.
    const bool sequence_file = json.is_object() && json.contains("camera") && json.at("camera").is_object();
    Camera camera = (sequence_file ? json.at("camera") : json).get<Camera>();
    camera.Check();
    return camera;
  } catch (const std::exception& e) {
    throw Error("camera file " + file.string() + ": " + e.what());
  }
}

}  // namespace nrslam
