#include "nrslam/io/sequence_writer.h"

#include <opencv2/imgcodecs.hpp>

#include "nrslam/io/depth_encoding.h"
#include "nrslam/util/error.h"
#include "nrslam/util/folder.h"
#include "nrslam/util/json_options.h"
#include "nrslam/util/text_file.h"

namespace nrslam {
namespace fs = std::filesystem;

void RemoveSequence(const fs::path& folder) {
  if (!fs::exists(folder / "sequence.json")) return;
  std::vector<fs::path> entries(kSequenceEntries.begin(), kSequenceEntries.end());
  try {
    const std::string mask = ReadJsonFile(folder / "sequence.json").value("mask", "");
    // Only a mask inside the folder: the file names no other place to delete.
    if (!mask.empty() && fs::path(mask).is_relative() && mask.find("..") == std::string::npos) entries.push_back(mask);
  } catch (const std::exception&) {
    // An unreadable sequence.json names no mask; the rest goes all the same.
  }
  entries.push_back("sequence.json");  // last: until then the folder still says what it holds
  for (const fs::path& entry : entries) {
    std::error_code error;
    fs::remove_all(folder / entry, error);
    if (error) throw Error("cannot remove " + (folder / entry).string() + ": " + error.message());
  }
}

SequenceWriter::SequenceWriter(const fs::path& folder, const SequenceInfo& info, bool with_depth, Target target)
    : folder_(folder), info_(info) {
  info_.Check();
  if (target == Target::kNewSequence && fs::exists(folder / "sequence.json")) {
    throw Error(folder.string() + " already holds a sequence (sequence.json); remove it or write to another folder");
  }
  CreateFolder(folder / "rgb");
  if (with_depth) CreateFolder(folder / "depth");
  if (info.stereo) CreateFolder(folder / "right");
  WriteTextFile(folder / "sequence.json", nlohmann::json(info_).dump(2) + '\n');
}

void SequenceWriter::WritePng(const fs::path& path, const cv::Mat& image) const {
  // Fast compression: the simulator writes tens of thousands of frames; size matters less.
  if (!cv::imwrite(path.string(), image, {cv::IMWRITE_PNG_COMPRESSION, 1})) {
    throw Error("cannot write " + path.string());
  }
}

void SequenceWriter::WriteRgb(int index, const cv::Mat& bgr) const {
  WritePng(folder_ / "rgb" / FrameFileName(index), bgr);
}

void SequenceWriter::WriteRight(int index, const cv::Mat& bgr) const {
  WritePng(folder_ / "right" / FrameFileName(index), bgr);
}

void SequenceWriter::WriteDepthMm(int index, const cv::Mat& depth_mm) const {
  WritePng(folder_ / "depth" / FrameFileName(index), EncodeDepthMm(depth_mm, info_.depth_unit_mm));
}

void SequenceWriter::WriteFixedMask(const cv::Mat& mask) const {
  if (info_.mask.empty()) throw Error("sequence.json names no mask file");
  WritePng(folder_ / info_.mask, mask);
}

void SequenceWriter::WriteGroundtruth(const std::vector<StampedPose>& poses) const {
  WriteTum(folder_ / "groundtruth.tum", poses);
}

}  // namespace nrslam
