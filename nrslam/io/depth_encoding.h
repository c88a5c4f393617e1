// io: the 16-bit encoding of a sequence's depth maps (depth/NNNNNN.png), shared by the
// writer, the reader, and anything that must see depth exactly as a run reads it back.
#pragma once

#include <opencv2/core.hpp>

#include <cmath>
#include <cstdint>

namespace nrslam {

// A depth already in units of unit_mm as its 16-bit value: rounded to the nearest, and 0
// (none) when it is not positive, not finite or beyond 16 bits, rather than clipped to a
// wrong depth. The one rule for every 16-bit depth map written (sequences' and runs').
inline uint16_t DepthUnitsOrNone(double units) {
  const double value = std::round(units);
  return (value > 0 && value <= 65535) ? static_cast<uint16_t>(value) : 0;
}

// Depth in mm (CV_32F, 0 or non-finite = none) as CV_16UC1 multiples of unit_mm, rounded to
// the nearest; a depth beyond the 16-bit range becomes 0 (none) rather than a clipped, wrong
// value.
cv::Mat EncodeDepthMm(const cv::Mat& depth_mm, double unit_mm);

// The inverse: CV_16UC1 multiples of unit_mm as CV_32F mm, 0 staying 0 (none).
cv::Mat DecodeDepthMm(const cv::Mat& encoded, double unit_mm);

}  // namespace nrslam
