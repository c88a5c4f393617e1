#include "nrslam/io/depth_encoding.h"

namespace nrslam {

cv::Mat EncodeDepthMm(const cv::Mat& depth_mm, double unit_mm) {
  CV_Assert(depth_mm.type() == CV_32F && unit_mm > 0);
  cv::Mat encoded(depth_mm.size(), CV_16UC1);
  const double inverse_unit = 1.0 / unit_mm;
  for (int y = 0; y < depth_mm.rows; ++y) {
    const float* in = depth_mm.ptr<float>(y);
    uint16_t* out = encoded.ptr<uint16_t>(y);
    for (int x = 0; x < depth_mm.cols; ++x) out[x] = DepthUnitsOrNone(in[x] * inverse_unit);
  }
  return encoded;
}

cv::Mat DecodeDepthMm(const cv::Mat& encoded, double unit_mm) {
  CV_Assert(encoded.type() == CV_16UC1 && unit_mm > 0);
  cv::Mat depth_mm;
  encoded.convertTo(depth_mm, CV_32F, unit_mm);
  return depth_mm;
}

}  // namespace nrslam
