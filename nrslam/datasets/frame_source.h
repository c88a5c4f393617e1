// datasets, internal: what an importer reads from a dataset's layout (FrameSource), the one
// function per layout that reads it, and the helpers they share. ImportDataset
// (dataset_import.h) writes a FrameSource as a sequence; nothing outside datasets/ uses this.
#pragma once

#include <opencv2/core.hpp>

#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "nrslam/camera/camera.h"
#include "nrslam/datasets/dataset_import.h"
#include "nrslam/geometry/rigid3.h"

namespace nrslam::importer {

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

// One per --format (dataset_import.h lists what each reads). Each checks its layout before
// the first frame is written and throws Error (Fail) naming the file and what is wrong.
FrameSource EndomapperSim(const ImportOptions& options);
FrameSource Hamlyn(const ImportOptions& options);
FrameSource C3vd(const ImportOptions& options);
FrameSource Images(const ImportOptions& options);
FrameSource Stereo(const ImportOptions& options);

// Throws Error with `message` after the format and the dataset's path.
[[noreturn]] void Fail(const ImportOptions& options, const std::string& message);


// cv::imread, failing with the file's name when it is missing or cannot be decoded.
cv::Mat ReadImage(const ImportOptions& options, const std::filesystem::path& file, int flags);

// The image files of a folder (none when it is not one) whose stems end in `suffix`, in
// FrameNameLess order (io/sequence_info.h): "frame_2.png" before "frame_10.png".
std::vector<std::filesystem::path> ImageFiles(const std::filesystem::path& folder, const std::string& suffix = "");

// The image files of `folders` whose stems end in `suffix`, by the frame number in their names
// (FrameNumberOf); files without one are left out, and two files of one frame are refused.
std::map<int, std::filesystem::path> FilesByFrame(const ImportOptions& options,
                                                  const std::vector<std::filesystem::path>& folders,
                                                  const std::string& suffix = "");

// A line of a dataset's text file: its number (from 1) and its numbers, separated by spaces,
// commas or semicolons; none when any token is not a number (a header, a word).
struct NumberLine {
  int line = 0;
  std::vector<double> numbers;
};

// The lines of the dataset's text file `name` (poses, intrinsics) that are not blank. Fail when
// it is missing or a folder has its name.
std::vector<NumberLine> NumberLines(const ImportOptions& options, const std::string& name);

// A ground-truth file needs a pose for every frame; extra poses (a longer recording) are cut.
void KeepOnePosePerFrame(const ImportOptions& options, const std::string& file, FrameSource* source);

// The camera of options.calibration (io/camera_file.h), failing with the dataset's name.
Camera LoadCalibration(const ImportOptions& options);

}  // namespace nrslam::importer
