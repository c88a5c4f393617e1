// io: writes a sequence folder in the format SequenceReader reads.
#pragma once

#include <opencv2/core.hpp>

#include <filesystem>
#include <vector>

#include "nrslam/io/sequence_info.h"
#include "nrslam/io/tum.h"

namespace nrslam {

// Removes the sequence in `folder` (sequence.json, its mask image and kSequenceEntries),
// leaving any other file; nothing when the folder holds no sequence.json.
// Throws Error when something cannot be removed.
void RemoveSequence(const std::filesystem::path& folder);

class SequenceWriter {
 public:
  // A new sequence, or more of an existing one (e.g. its depth from stereo).
  enum class Target { kNewSequence, kExistingSequence };
  // Creates the folder layout and writes sequence.json; throws Error if the folder cannot be
  // written, or for a new sequence if it already holds one: written over, an earlier sequence
  // would leave its frames past this one's end, or its depth when this one has none, to be read
  // as this sequence's.
  SequenceWriter(const std::filesystem::path& folder, const SequenceInfo& info, bool with_depth,
                 Target target = Target::kNewSequence);

  void WriteRgb(int index, const cv::Mat& bgr) const;
  void WriteRight(int index, const cv::Mat& bgr) const;
  // Depth in mm (CV_32F, 0 or non-finite = none), stored in depth_unit_mm (EncodeDepthMm).
  void WriteDepthMm(int index, const cv::Mat& depth_mm) const;
  void WriteFixedMask(const cv::Mat& mask) const;
  void WriteGroundtruth(const std::vector<StampedPose>& poses) const;

 private:
  std::filesystem::path folder_;
  SequenceInfo info_;
  void WritePng(const std::filesystem::path& path, const cv::Mat& image) const;
};

}  // namespace nrslam
