#include "nrslam/frontend/masks.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cstdlib>
#include <string>

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

cv::Mat FindStaticRegions(const std::vector<cv::Mat>& greys, const cv::Mat& sequence_mask, const MaskOptions& options) {
  if (greys.size() < static_cast<size_t>(MaskOptions::kMinStaticFrames)) {
    throw Error("FindStaticRegions: needs at least " + std::to_string(MaskOptions::kMinStaticFrames) + " frames, got " +
                std::to_string(greys.size()));
  }
  const cv::Size size = greys.front().size();
  for (const cv::Mat& grey : greys) {
    if (grey.type() != CV_8UC1 || grey.size() != size) {
      throw Error("FindStaticRegions: expected 8-bit grey frames of one size");
    }
  }
  if (!sequence_mask.empty() && sequence_mask.size() != size) {
    throw Error("FindStaticRegions: mask and image sizes differ");
  }
  const size_t frames = greys.size();
  const size_t allowed_strays = frames / 10;
  cv::Mat still(size, CV_8UC1, cv::Scalar(0)), median(size, CV_8UC1);
  std::vector<uint8_t> values(frames);
  std::vector<const uint8_t*> rows(frames);
  for (int row = 0; row < size.height; ++row) {
    for (size_t k = 0; k < frames; ++k) rows[k] = greys[k].ptr<uint8_t>(row);
    uint8_t* out = still.ptr<uint8_t>(row);
    uint8_t* middle = median.ptr<uint8_t>(row);
    for (int col = 0; col < size.width; ++col) {
      for (size_t k = 0; k < frames; ++k) values[k] = rows[k][col];
      std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(frames / 2), values.end());
      middle[col] = values[frames / 2];
      const auto strays = static_cast<size_t>(std::count_if(values.begin(), values.end(), [&](uint8_t value) {
        return std::abs(value - middle[col]) > options.static_max_change;
      }));
      if (strays <= allowed_strays) out[col] = 255;
    }
  }
  // Joins the strokes of a display's text (a few px apart) into one patch before patches are
  // judged by their area.
  constexpr int kStrokeGapPx = 7;
  cv::morphologyEx(still, still, cv::MORPH_CLOSE,
                   cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(kStrokeGapPx, kStrokeGapPx)));
  if (!sequence_mask.empty()) still.setTo(0, sequence_mask == 0);
  // A patch of still, flat tissue (a slow camera) holds no edge, and nothing to track either: a
  // display's text and a border's rim are edges that stay put. The edges of the median frame,
  // in grey levels per px (Sobel / 8), are looked for on the patch and the pixel around it.
  cv::Mat gx, gy, edges;
  cv::Sobel(median, gx, CV_32F, 1, 0);
  cv::Sobel(median, gy, CV_32F, 0, 1);
  cv::magnitude(gx, gy, edges);
  edges /= 8;
  cv::Mat labels, stats, centroids;
  const int patches = cv::connectedComponentsWithStats(still, labels, stats, centroids, 8, CV_32S);
  cv::Mat regions(size, CV_8UC1, cv::Scalar(0));
  bool any = false;
  for (int patch = 1; patch < patches; ++patch) {
    if (stats.at<int>(patch, cv::CC_STAT_AREA) < options.static_min_area_px) continue;
    const cv::Mat in_patch = labels == patch;
    cv::Mat around;
    cv::dilate(in_patch, around, cv::Mat());
    double strongest = 0;
    cv::minMaxLoc(edges, nullptr, &strongest, nullptr, nullptr, around);
    if (strongest < options.static_min_edge) continue;
    regions.setTo(255, in_patch);
    any = true;
  }
  if (!any) return {};
  if (options.static_margin_px > 0) {
    const int side = 2 * options.static_margin_px + 1;
    cv::dilate(regions, regions, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(side, side)));
  }
  return regions;
}

}  // namespace nrslam
