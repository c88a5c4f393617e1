#include "nrslam/frontend/image_pyramid.h"

#include <opencv2/imgproc.hpp>

#include "nrslam/util/error.h"

namespace nrslam {

ImagePyramid::ImagePyramid(const cv::Mat& grey, int levels) {
  if (grey.type() != CV_8UC1) throw Error("ImagePyramid: expected an 8-bit grey image");
  cv::Mat current;
  grey.convertTo(current, CV_32F);
  while (true) {
    cv::Mat bordered;
    cv::copyMakeBorder(current, bordered, border(), border(), border(), border(), cv::BORDER_REFLECT_101);
    bordered_.push_back(bordered);
    levels_.push_back(bordered(cv::Rect(border(), border(), current.cols, current.rows)));
    if (static_cast<int>(levels_.size()) >= levels || std::min(current.cols, current.rows) < 16) break;
    cv::Mat smaller;
    cv::pyrDown(current, smaller);
    current = smaller;
  }
}

}  // namespace nrslam
