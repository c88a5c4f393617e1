#include "nrslam/io/camera_file.h"

#include <opencv2/core.hpp>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>
#include <vector>

#include "nrslam/util/json_options.h"
#include "nrslam/util/text_file.h"

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
    if (!std::isfinite(numbers.back())) throw Error("'" + key + "' holds a value that is not finite (nan or inf)");
  }
  return numbers;
}

// The first of `keys` the file has: its key and node; an empty key when none is there.
std::pair<std::string, cv::FileNode> FirstEntry(const cv::FileNode& map, std::initializer_list<const char*> keys) {
  for (const char* key : keys) {
    const cv::FileNode node = map[key];
    if (!node.empty() && !node.isNone()) return {key, node};
  }
  return {"", cv::FileNode()};
}

std::string Lowercase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
  return text;
}

bool IsOpenCvCalibration(const std::filesystem::path& file, char first) {
  const std::string extension = Lowercase(file.extension().string());
  return first == '%' || first == '<' || extension == ".yml" || extension == ".yaml" || extension == ".xml";
}

// YAML text with every block sequence indented deeper than its key. YAML lets the items of
// "key:" sit at the key's own indentation (Kalibr writes T_cn_cnm1 so); OpenCV's reader does not.
std::string WithIndentedSequences(const std::string& yaml) {
  std::istringstream lines(yaml);
  std::string line, result;
  size_t key_indent = std::string::npos;  // indentation of the "key:" line whose items may follow
  while (std::getline(lines, line)) {
    const size_t indent = line.find_first_not_of(' ');
    const bool item = indent != std::string::npos && line.compare(indent, 2, "- ") == 0;
    if (item && indent == key_indent) {
      line.insert(0, "  ");
    } else {
      const size_t end = line.find_last_not_of(" \t\r");
      key_indent = end != std::string::npos && line[end] == ':' ? indent : std::string::npos;
    }
    result += line + '\n';
  }
  return result;
}

// The file opened by cv::FileStorage from its text. OpenCV's YAML reader wants the version
// directive its writer puts first; ROS and Kalibr leave it out, so it is added when missing.
cv::FileStorage OpenCalibrationStorage(const std::filesystem::path& file) {
  std::string contents = FileText(file);
  const size_t first = contents.find_first_not_of(" \t\r\n");
  const char lead = first == std::string::npos ? '\0' : contents[first];
  if (lead != '\0' && lead != '<') {  // YAML
    contents = WithIndentedSequences(contents);
    if (lead != '%') contents = "%YAML:1.0\n---\n" + contents;
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
std::pair<int, int> CalibrationImageSize(const cv::FileNode& map, std::optional<std::pair<int, int>> fallback) {
  const auto [size_key, size_node] = FirstEntry(map, {"image_size", "imageSize", "resolution"});
  if (!map["image_width"].empty() && !map["image_height"].empty()) {
    return {static_cast<int>(map["image_width"]), static_cast<int>(map["image_height"])};
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
Camera ReadOpenCvCamera(const cv::FileNode& map, std::initializer_list<const char*> matrix_keys,
                        std::initializer_list<const char*> distortion_keys, std::pair<int, int> size) {
  const auto [matrix_key, matrix_node] = FirstEntry(map, matrix_keys);
  if (matrix_key.empty()) throw Error("no camera matrix (" + KeyList(matrix_keys) + ")");
  const std::vector<double> k = EntryNumbers(matrix_node, matrix_key);
  if (k.size() != 9) throw Error("'" + matrix_key + "' must be 3x3, has " + std::to_string(k.size()) + " numbers");
  if (k[1] != 0.0 || k[3] != 0.0 || k[6] != 0.0 || k[7] != 0.0 || k[8] != 1.0) {
    throw Error("'" + matrix_key + "' must be [fx 0 cx; 0 fy cy; 0 0 1] (no skew)");
  }
  const auto [width, height] = size;

  const auto [distortion_key, distortion_node] = FirstEntry(map, distortion_keys);
  std::vector<double> distortion =
      distortion_key.empty() ? std::vector<double>() : EntryNumbers(distortion_node, distortion_key);
  const cv::FileNode model_node = map["distortion_model"];
  const std::string model = model_node.isString() ? Lowercase(static_cast<std::string>(model_node)) : "";
  const std::optional<CameraModelId> named =
      model == KannalaBrandtModel::kName ? CameraModelId::kKannalaBrandt : CameraModelOfToolName(model);
  const bool fisheye = named == CameraModelId::kKannalaBrandt;
  if (!model.empty() && !named) {
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
  return ReadOpenCvCamera(storage.root(), {"camera_matrix", "cameraMatrix", "K", "M1"},
                          {"distortion_coefficients", "dist_coeffs", "distCoeffs", "D", "D1"},
                          CalibrationImageSize(storage.root(), std::nullopt));
}

namespace {

Eigen::Matrix3d Rotation(const std::vector<double>& row_major, const std::string& key) {
  if (row_major.size() != 9) {
    throw Error("'" + key + "' must be a 3x3 rotation, has " + std::to_string(row_major.size()) + " numbers");
  }
  const Eigen::Matrix3d rotation = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(row_major.data());
  if (!IsRotation(rotation)) {
    throw Error("'" + key + "' is not a rotation");
  }
  return rotation;
}

// The rotation stored under `key` of a map.
Eigen::Matrix3d RotationEntry(const cv::FileNode& map, const std::string& key) {
  return Rotation(EntryNumbers(map[key], key), key);
}

// OpenCV's names, from whichever file has each: OpenCV's stereo_calib sample writes the
// intrinsics (M1 D1 M2 D2) and the extrinsics (R T) to two files.
StereoCalibration OpenCvStereo(const std::vector<cv::FileStorage>& storages,
                               std::optional<std::pair<int, int>> image_size, double translation_unit_mm) {
  const auto holding = [&](const char* key) -> cv::FileNode {
    for (const cv::FileStorage& storage : storages) {
      if (!FirstEntry(storage.root(), {key}).first.empty()) return storage.root();
    }
    throw Error(std::string("no '") + key + "'");
  };
  const std::pair<int, int> size = CalibrationImageSize(holding("M1"), image_size);
  StereoCalibration stereo;
  stereo.left = ReadOpenCvCamera(holding("M1"), {"M1"}, {"D1"}, size);
  stereo.right = ReadOpenCvCamera(holding("M2"), {"M2"}, {"D2"}, size);
  const Eigen::Matrix3d rotation = RotationEntry(holding("R"), "R");
  const std::vector<double> t = EntryNumbers(holding("T")["T"], "T");
  if (t.size() != 3) throw Error("'T' must be 3 numbers, has " + std::to_string(t.size()));
  stereo.right_from_left =
      Rigid3(Eigen::Quaterniond(rotation), Eigen::Vector3d(t[0], t[1], t[2]) * translation_unit_mm);
  return stereo;
}

// One camera of Kalibr's camchain: pinhole with radtan (OpenCV's k1 k2 p1 p2), equidistant
// (Kannala–Brandt) or no distortion.
Camera KalibrCamera(const cv::FileNode& node, const std::string& name) {
  const std::string model = node["camera_model"].isString() ? static_cast<std::string>(node["camera_model"]) : "";
  if (model != "pinhole") throw Error(name + ": camera_model '" + model + "' (only Kalibr's pinhole model is read)");
  const std::vector<double> intrinsics = EntryNumbers(node["intrinsics"], name + ".intrinsics");
  if (intrinsics.size() != 4) throw Error(name + ".intrinsics must be [fu, fv, pu, pv]");
  const std::pair<int, int> size = CalibrationImageSize(node, std::nullopt);
  const std::string distortion =
      node["distortion_model"].isString() ? static_cast<std::string>(node["distortion_model"]) : "none";
  const std::vector<double> k = node["distortion_coeffs"].empty()
                                    ? std::vector<double>()
                                    : EntryNumbers(node["distortion_coeffs"], name + ".distortion_coeffs");
  const auto [fx, fy, cx, cy] = std::array<double, 4>{intrinsics[0], intrinsics[1], intrinsics[2], intrinsics[3]};
  const bool undistorted = std::all_of(k.begin(), k.end(), [](double d) { return d == 0.0; });
  if (distortion == "none" || undistorted) return Camera::Pinhole(size.first, size.second, fx, fy, cx, cy);
  if (k.size() != 4) throw Error(name + ".distortion_coeffs must hold 4 numbers");
  if (distortion == "radtan") return Camera::OpenCv(size.first, size.second, fx, fy, cx, cy, k);
  if (distortion == "equidistant") {
    return Camera::KannalaBrandt(size.first, size.second, fx, fy, cx, cy, Eigen::Vector4d(k[0], k[1], k[2], k[3]));
  }
  throw Error(name + ": distortion_model '" + distortion + "' (known: radtan, equidistant, none)");
}

// Kalibr's camchain: cam0 and cam1, with cam1's T_cn_cnm1 taking cam0's coordinates to its own.
StereoCalibration KalibrStereo(const cv::FileStorage& storage, double translation_unit_mm) {
  StereoCalibration stereo;
  stereo.left = KalibrCamera(storage["cam0"], "cam0");
  stereo.right = KalibrCamera(storage["cam1"], "cam1");
  std::vector<double> matrix;
  for (const cv::FileNode& row : storage["cam1"]["T_cn_cnm1"]) {
    const std::vector<double> numbers = EntryNumbers(row, "cam1.T_cn_cnm1");
    matrix.insert(matrix.end(), numbers.begin(), numbers.end());
  }
  if (matrix.size() != 16) throw Error("cam1.T_cn_cnm1 must be a 4x4 matrix");
  const std::vector<double> rotation = {matrix[0], matrix[1], matrix[2], matrix[4], matrix[5],
                                        matrix[6], matrix[8], matrix[9], matrix[10]};
  stereo.right_from_left = Rigid3(Eigen::Quaterniond(Rotation(rotation, "cam1.T_cn_cnm1")),
                                  Eigen::Vector3d(matrix[3], matrix[7], matrix[11]) * translation_unit_mm);
  return stereo;
}

// A ROS camera_info pair, already rectified by ROS's stereo calibrator: each camera's raw lens,
// its rectifying rotation R_i and projection P_i. Rectified coordinates differ by the baseline
// along x (P_right's Tx = −f·B), so x_right = R_r^T (R_l x_left + (Tx/f, Ty/f, 0)).
StereoCalibration RosStereo(const cv::FileStorage& left, const cv::FileStorage& right, double translation_unit_mm) {
  const auto camera = [](const cv::FileStorage& storage) {
    return ReadOpenCvCamera(storage.root(), {"camera_matrix"}, {"distortion_coefficients"},
                            CalibrationImageSize(storage.root(), std::nullopt));
  };
  StereoCalibration stereo;
  stereo.left = camera(left);
  stereo.right = camera(right);
  const Eigen::Matrix3d r_left = RotationEntry(left.root(), "rectification_matrix");
  const Eigen::Matrix3d r_right = RotationEntry(right.root(), "rectification_matrix");
  const std::vector<double> p = EntryNumbers(right["projection_matrix"], "projection_matrix");
  if (p.size() != 12) throw Error("the right camera's projection_matrix must be 3x4");
  const Eigen::Vector3d offset(p[3] / p[0], p[7] / p[5], 0.0);
  stereo.right_from_left =
      Rigid3(Eigen::Quaterniond(r_right.transpose() * r_left), r_right.transpose() * offset * translation_unit_mm);
  return stereo;
}

}  // namespace

StereoCalibration ReadStereoCalibration(const std::vector<std::filesystem::path>& files,
                                        std::optional<std::pair<int, int>> image_size, double translation_unit_mm) {
  std::string names;
  for (const std::filesystem::path& file : files) names += (names.empty() ? "" : ", ") + file.string();
  try {
    if (files.empty()) throw Error("no file given");
    if (translation_unit_mm < 0) throw Error("the unit of the translation must be > 0 mm (0: the format's own)");
    std::vector<cv::FileStorage> storages;
    for (const std::filesystem::path& file : files) storages.push_back(OpenCalibrationStorage(file));
    const auto has = [](const cv::FileStorage& storage, const char* key) {
      return !FirstEntry(storage.root(), {key}).first.empty();
    };
    const bool opencv =
        std::any_of(storages.begin(), storages.end(), [&](const cv::FileStorage& s) { return has(s, "M1"); });
    const bool kalibr = has(storages[0], "cam0") && has(storages[0], "cam1");
    const bool ros =
        storages.size() == 2 && has(storages[0], "projection_matrix") && has(storages[1], "projection_matrix");
    // The formats' own units: OpenCV's files carry the unit their calibration target was
    // measured in (mm for SCARED); Kalibr and ROS use metres.
    const double unit = translation_unit_mm > 0 ? translation_unit_mm : opencv ? 1.0 : 1000.0;
    StereoCalibration stereo;
    if (opencv) {
      stereo = OpenCvStereo(storages, image_size, unit);
    } else if (kalibr) {
      stereo = KalibrStereo(storages[0], unit);
    } else if (ros) {
      stereo = RosStereo(storages[0], storages[1], unit);
    } else {
      throw Error(
          "not a stereo calibration: expected OpenCV's M1 D1 M2 D2 R T, Kalibr's camchain (cam0, cam1) or two "
          "ROS camera_info files (left, right)");
    }
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
