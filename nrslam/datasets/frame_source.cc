#include "nrslam/datasets/frame_source.h"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <sstream>

#include "nrslam/io/camera_file.h"
#include "nrslam/io/sequence_info.h"
#include "nrslam/util/error.h"
#include "nrslam/util/text_file.h"

namespace nrslam::importer {
namespace fs = std::filesystem;

namespace {

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

// A text file of the dataset, opened to read; Fail when it is missing or a folder has its name.
std::ifstream OpenText(const ImportOptions& options, const std::string& name) {
  if (!fs::exists(options.input / name)) Fail(options, "missing " + name);
  try {
    return OpenToRead(options.input / name, "text file");
  } catch (const Error& e) {
    Fail(options, e.what());
  }
}

}  // namespace

[[noreturn]] void Fail(const ImportOptions& options, const std::string& message) {
  throw Error(options.format + " dataset " + options.input.string() + ": " + message);
}

cv::Mat ReadImage(const ImportOptions& options, const fs::path& file, int flags) {
  // Checked first: OpenCV would print a warning of its own before our message.
  if (!fs::is_regular_file(file)) Fail(options, file.string() + " does not exist");
  cv::Mat image = cv::imread(file.string(), flags);
  if (image.empty()) Fail(options, "cannot read " + file.string() + " (missing or corrupt)");
  return image;
}

std::vector<fs::path> ImageFiles(const fs::path& folder, const std::string& suffix) {
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
    return FrameNameLess(a.filename().string(), b.filename().string());
  });
  return files;
}

std::map<int, fs::path> FilesByFrame(const ImportOptions& options, const std::vector<fs::path>& folders,
                                     const std::string& suffix) {
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

std::vector<NumberLine> NumberLines(const ImportOptions& options, const std::string& name) {
  std::ifstream file = OpenText(options, name);
  std::vector<NumberLine> lines;
  std::string line;
  for (int number = 1; std::getline(file, line); ++number) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::vector<double> numbers = Numbers(line);
    // strtod reads "nan" and "inf": a pose or an intrinsic made of them would be written as read.
    if (!std::all_of(numbers.begin(), numbers.end(), [](double value) { return std::isfinite(value); })) {
      Fail(options, name + " line " + std::to_string(number) + " holds a value that is not finite (nan or inf)");
    }
    lines.push_back({number, std::move(numbers)});
  }
  return lines;
}

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

}  // namespace nrslam::importer
