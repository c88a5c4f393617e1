#include "nrslam/frontend/masks.h"

#include <opencv2/imgproc.hpp>

#include "nrslam/util/error.h"

namespace nrslam {

cv::Mat ToGrey(const cv::Mat& bgr) {
  cv::Mat grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  return grey;
}

cv::Mat BuildValidityMask(const cv::Mat& grey, const cv::Mat& sequence_mask, const MaskOptions& options) {
  if (grey.type() != CV_8UC1) throw Error("BuildValidityMask: expected an 8-bit grey image");
  if (!sequence_mask.empty() && sequence_mask.size() != grey.size()) {
    throw Error("BuildValidityMask: mask and image sizes differ");
  }
  cv::Mat valid(grey.size(), CV_8UC1, cv::Scalar(255));
  if (options.bright_threshold < 255) {
    cv::Mat highlights = grey > options.bright_threshold;
    if (options.bright_margin_px > 0) {
      const int side = 2 * options.bright_margin_px + 1;
      cv::dilate(highlights, highlights, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(side, side)));
    }
    valid.setTo(0, highlights);
  }
  if (!sequence_mask.empty()) valid.setTo(0, sequence_mask == 0);
  if (options.erosion_px > 0) {
    const int side = 2 * options.erosion_px + 1;
    cv::erode(valid, valid, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(side, side)), cv::Point(-1, -1), 1,
              cv::BORDER_CONSTANT, cv::Scalar(255));
  }
  const int border = std::min({options.border_px, grey.cols / 2, grey.rows / 2});
  if (border > 0) {
    valid.rowRange(0, border) = 0;
    valid.rowRange(grey.rows - border, grey.rows) = 0;
    valid.colRange(0, border) = 0;
    valid.colRange(grey.cols - border, grey.cols) = 0;
  }
  return valid;
}

}  // namespace nrslam
