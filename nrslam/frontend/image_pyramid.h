// frontend: a Gaussian image pyramid in float, level l at 1/2^l resolution, so that a point
// at x on level 0 is at x / 2^l on level l. Every level is stored inside a reflected border
// of border() px (as OpenCV's optical-flow pyramids are), so a tracking window may overhang
// the image on coarse levels, where a 21 px window covers much of the image.
#pragma once

#include <opencv2/core.hpp>

#include <vector>

namespace nrslam {

class ImagePyramid {
 public:
  ImagePyramid() = default;
  // From an 8-bit grey image; stops early if a level would be smaller than 8 px.
  ImagePyramid(const cv::Mat& grey, int levels);

  int levels() const { return static_cast<int>(levels_.size()); }
  // CV_32F, intensities 0..255; a view into the bordered image, so rows may be read up to
  // border() px beyond each edge.
  const cv::Mat& level(int index) const { return levels_[index]; }
  static constexpr int border() { return 34; }

 private:
  std::vector<cv::Mat> bordered_;
  std::vector<cv::Mat> levels_;
};

}  // namespace nrslam
