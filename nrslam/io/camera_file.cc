#include "nrslam/io/camera_file.h"

#include <fstream>
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

}  // namespace

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
    if (first != 0 && first != '{') {
      // Not a JSON object: OCamCalib's text format.
      std::ifstream stream(file);
      std::ostringstream text;
      text << stream.rdbuf();
      return ParseOcamCalibResults(text.str());
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
