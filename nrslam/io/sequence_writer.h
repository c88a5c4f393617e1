// io: writes a sequence folder in the format SequenceReader reads.
#pragma once

#include <opencv2/core.hpp>

#include <filesystem>
#include <vector>

#include "nrslam/io/sequence_info.h"
#include "nrslam/io/tum.h"

namespace nrslam {

class SequenceWriter {
 public:
  // Creates the folder layout; throws Error if the folder cannot be written.
  SequenceWriter(const std::filesystem::path& folder, const SequenceInfo& info, bool with_depth);

  void WriteRgb(int index, const cv::Mat& bgr) const;
  void WriteRight(int index, const cv::Mat& bgr) const;
  // Depth in mm (CV_32F, 0 or non-finite = none), stored as 16-bit multiples of depth_unit_mm;
  // depths beyond the 16-bit range are stored as 0 (none) rather than clipped to a wrong value.
  void WriteDepthMm(int index, const cv::Mat& depth_mm) const;
  void WriteFixedMask(const cv::Mat& mask) const;
  void WriteGroundtruth(const std::vector<StampedPose>& poses) const;

 private:
  std::filesystem::path folder_;
  SequenceInfo info_;
  void WritePng(const std::filesystem::path& path, const cv::Mat& image) const;
};

}  // namespace nrslam
