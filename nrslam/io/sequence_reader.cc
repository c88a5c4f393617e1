#include "nrslam/io/sequence_reader.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <sstream>

#include "nrslam/io/depth_encoding.h"
#include "nrslam/io/png_header.h"
#include "nrslam/util/error.h"
#include "nrslam/util/json_options.h"

namespace nrslam {
namespace fs = std::filesystem;
namespace {

// "37" or "37-119": compact text for runs of missing frame indices.
std::string IndexRanges(const std::vector<int>& indices) {
  std::ostringstream text;
  for (size_t i = 0; i < indices.size();) {
    size_t j = i;
    while (j + 1 < indices.size() && indices[j + 1] == indices[j] + 1) ++j;
    text << (i ? ", " : "") << indices[i];
    if (j > i) text << "-" << indices[j];
    i = j + 1;
  }
  return text.str();
}

struct ImageRequirement {
  std::string subfolder;
  int bit_depth;
  bool single_channel;
};

std::string Describe(const PngHeader& header) {
  return std::to_string(header.bit_depth) + "-bit " + std::to_string(header.channels) + "-channel " +
         std::to_string(header.width) + "x" + std::to_string(header.height);
}

// The poses are matched to frames by their order, and written trajectories carry
// t = index / fps, so a pose off that clock (lines out of order, or another time base) would
// be scored against the wrong frame, or in evo against none.
std::string GroundtruthTimeProblem(const std::vector<StampedPose>& poses, double fps) {
  for (size_t index = 0; index < poses.size(); ++index) {
    const double expected = static_cast<double>(index) / fps;
    if (std::abs(poses[index].timestamp - expected) > 0.5 / fps) {
      std::ostringstream text;
      text << "groundtruth.tum: pose " << index + 1 << " has t = " << poses[index].timestamp << " s, but frame "
           << index << " is at " << index << " / " << fps << " fps = " << expected
           << " s (one pose per frame, in frame order, t = index / fps)";
      return text.str();
    }
  }
  return "";
}

void CheckFrames(const fs::path& folder, const ImageRequirement& requirement, const SequenceInfo& info,
                 std::vector<std::string>* problems) {
  std::vector<int> missing;
  int reported = 0;
  for (int index = 0; index < info.frame_count; ++index) {
    const std::string name = requirement.subfolder + "/" + FrameFileName(index);
    if (!fs::exists(folder / name)) {
      missing.push_back(index);
      continue;
    }
    const auto header = ReadPngHeader(folder / name);
    std::string problem;
    if (!header) {
      problem = name + " is not a readable PNG";
    } else if (header->width != info.camera.width() || header->height != info.camera.height()) {
      problem = name + " is " + std::to_string(header->width) + "x" + std::to_string(header->height) +
                " but the camera is " + std::to_string(info.camera.width()) + "x" +
                std::to_string(info.camera.height()) + " (size mismatch)";
    } else if (header->bit_depth != requirement.bit_depth || (requirement.single_channel && header->channels != 1)) {
      problem = name + " must be " + std::to_string(requirement.bit_depth) + "-bit" +
                (requirement.single_channel ? " single-channel" : "") + ", is " + Describe(*header);
    }
    if (!problem.empty() && reported++ < 5) problems->push_back(problem);
  }
  if (reported > 5) problems->push_back(std::to_string(reported - 5) + " more bad files in " + requirement.subfolder + "/");
  if (!missing.empty()) {
    problems->push_back(std::string(missing.size() == 1 ? "missing frame " : "missing frames ") + IndexRanges(missing) +
                        " in " + requirement.subfolder + "/ (expected " + std::to_string(info.frame_count) +
                        " frames named like " + FrameFileName(missing.front()) + ")");
  }
}

}  // namespace

SequenceReader::SequenceReader(const fs::path& folder) : folder_(folder) {
  if (!fs::is_directory(folder)) throw Error("sequence folder " + folder.string() + " does not exist");
  const fs::path json_path = folder / "sequence.json";
  if (!fs::exists(json_path)) throw Error("sequence " + folder.string() + ": missing sequence.json");
  try {
    info_ = ReadJsonFile(json_path).get<SequenceInfo>();
  } catch (const Error& e) {
    throw Error("sequence " + folder.string() + ": " + e.what());
  }

  std::vector<std::string> problems;
  if (!fs::is_directory(folder / "rgb")) {
    problems.push_back("missing rgb/ folder");
  } else {
    CheckFrames(folder, {"rgb", 8, false}, info_, &problems);
  }
  has_depth_ = fs::is_directory(folder / "depth");
  if (has_depth_) CheckFrames(folder, {"depth", 16, true}, info_, &problems);
  has_right_ = fs::is_directory(folder / "right");
  if (info_.stereo && !has_right_) problems.push_back("sequence.json declares stereo but right/ is missing");
  if (has_right_) CheckFrames(folder, {"right", 8, false}, info_, &problems);
  has_frame_masks_ = fs::is_directory(folder / "masks");
  if (has_frame_masks_) CheckFrames(folder, {"masks", 8, true}, info_, &problems);

  if (!info_.mask.empty()) {
    const auto header = ReadPngHeader(folder / info_.mask);
    if (!header) {
      problems.push_back("mask " + info_.mask + " named by sequence.json is missing or not a PNG");
    } else if (header->width != info_.camera.width() || header->height != info_.camera.height()) {
      problems.push_back("mask " + info_.mask + " is " + Describe(*header) + ", camera is " +
                         std::to_string(info_.camera.width()) + "x" + std::to_string(info_.camera.height()));
    } else {
      fixed_mask_ = cv::imread((folder / info_.mask).string(), cv::IMREAD_GRAYSCALE);
      if (fixed_mask_.empty()) {
        problems.push_back("mask " + info_.mask + " cannot be decoded");
      } else if (cv::countNonZero(fixed_mask_) == 0) {
        // Every frame would then have nothing to track, and the run would say only that.
        problems.push_back("mask " + info_.mask + " marks no pixel usable (all zero; non-zero = usable)");
      }
    }
  }

  const fs::path groundtruth_path = folder / "groundtruth.tum";
  if (fs::exists(groundtruth_path)) {
    try {
      groundtruth_ = ReadTum(groundtruth_path);
      if (static_cast<int>(groundtruth_.size()) != info_.frame_count) {
        problems.push_back("groundtruth.tum has " + std::to_string(groundtruth_.size()) + " poses, expected " +
                           std::to_string(info_.frame_count) + " (one per frame)");
        groundtruth_.clear();
      } else if (const std::string problem = GroundtruthTimeProblem(groundtruth_, info_.fps); !problem.empty()) {
        problems.push_back(problem);
        groundtruth_.clear();
      }
    } catch (const Error& e) {
      problems.push_back(e.what());
    }
  }

  if (!problems.empty()) {
    std::string message = "invalid sequence " + folder.string() + ":";
    for (const std::string& problem : problems) message += "\n  - " + problem;
    throw Error(message);
  }
}

cv::Mat SequenceReader::ReadImage(const std::string& subfolder, int index, int flags, int expected_type) const {
  if (index < 0 || index >= info_.frame_count) {
    throw Error("frame " + std::to_string(index) + " is outside the sequence (0.." +
                std::to_string(info_.frame_count - 1) + ")");
  }
  const fs::path path = folder_ / subfolder / FrameFileName(index);
  cv::Mat image = cv::imread(path.string(), flags);
  if (image.empty() || image.type() != expected_type || image.cols != info_.camera.width() ||
      image.rows != info_.camera.height()) {
    throw Error("cannot decode " + path.string() + " (corrupt or wrong format)");
  }
  return image;
}

cv::Mat SequenceReader::ReadRgb(int index) const { return ReadImage("rgb", index, cv::IMREAD_COLOR, CV_8UC3); }

cv::Mat SequenceReader::ReadRight(int index) const {
  if (!has_right_) throw Error("sequence " + folder_.string() + " has no right images");
  return ReadImage("right", index, cv::IMREAD_COLOR, CV_8UC3);
}

cv::Mat SequenceReader::ReadDepthMm(int index) const {
  if (!has_depth_) throw Error("sequence " + folder_.string() + " has no depth ground truth");
  return DecodeDepthMm(ReadImage("depth", index, cv::IMREAD_UNCHANGED, CV_16UC1), info_.depth_unit_mm);
}

cv::Mat SequenceReader::TryReadDepthMm(int index, std::string* problem) const {
  problem->clear();
  try {
    return ReadDepthMm(index);
  } catch (const Error& e) {
    *problem = e.what();
    return cv::Mat();
  }
}

cv::Mat SequenceReader::ReadMask(int index) const {
  cv::Mat mask = fixed_mask_.clone();
  if (has_frame_masks_) {
    cv::Mat frame_mask = ReadImage("masks", index, cv::IMREAD_GRAYSCALE, CV_8UC1);
    mask = mask.empty() ? frame_mask : (mask & frame_mask);
  }
  return mask;
}

}  // namespace nrslam
