// io: reads a sequence folder (format in docs/data.md), validating all of it up front.
//
// The constructor checks every file the sequence promises (existence, PNG header, size,
// bit depth, ground-truth line count) before the first frame is read, and throws one Error
// that lists every problem found. Frame reads throw Error naming the file if a PNG turns
// out to be corrupt after all.
#pragma once

#include <opencv2/core.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "nrslam/io/sequence_info.h"
#include "nrslam/io/tum.h"

namespace nrslam {

class SequenceReader {
 public:
  explicit SequenceReader(const std::filesystem::path& folder);

  const std::filesystem::path& folder() const { return folder_; }
  const SequenceInfo& info() const { return info_; }
  int frame_count() const { return info_.frame_count; }
  bool has_depth() const { return has_depth_; }
  bool has_right() const { return has_right_; }
  bool has_frame_masks() const { return has_frame_masks_; }
  bool has_groundtruth() const { return !groundtruth_.empty(); }

  cv::Mat ReadRgb(int index) const;      // CV_8UC3, BGR
  cv::Mat ReadDepthMm(int index) const;  // CV_32F millimetres, 0 = no ground truth
  // The same for scoring, where one damaged ground-truth file should cost its frame's score and
  // not the run: an empty matrix, with `*problem` saying why, when the file cannot be read.
  cv::Mat TryReadDepthMm(int index, std::string* problem) const;
  cv::Mat ReadRight(int index) const;    // CV_8UC3
  // Validity mask for a frame: the fixed mask AND the frame's mask; empty if neither exists.
  cv::Mat ReadMask(int index) const;
  // The sequence's fixed mask (mask.png); empty if it has none.
  const cv::Mat& fixed_mask() const { return fixed_mask_; }
  const std::vector<StampedPose>& groundtruth() const { return groundtruth_; }

 private:
  std::filesystem::path folder_;
  SequenceInfo info_;
  bool has_depth_ = false;
  bool has_right_ = false;
  bool has_frame_masks_ = false;
  cv::Mat fixed_mask_;
  std::vector<StampedPose> groundtruth_;

  cv::Mat ReadImage(const std::string& subfolder, int index, int flags, int expected_type) const;
};

}  // namespace nrslam
