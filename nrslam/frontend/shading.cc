#include "nrslam/frontend/shading.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "nrslam/util/median.h"

namespace nrslam {

std::vector<double> LinearBrightness(const cv::Mat& grey, const cv::Mat& valid, const std::vector<cv::Point2f>& pixels,
                                     const ShadingOptions& options) {
  std::vector<double> brightness;
  brightness.reserve(pixels.size());
  // One power per grey level rather than per pixel of every box (the same values).
  std::array<double, 256> linear;
  for (int level = 0; level < 256; ++level) linear[level] = std::pow(level / 255.0, options.gamma);
  const int half = options.patch_px;
  for (const cv::Point2f& pixel : pixels) {
    const int x = cvRound(pixel.x), y = cvRound(pixel.y);
    double sum = 0;
    int count = 0;
    for (int v = std::max(0, y - half); v <= std::min(grey.rows - 1, y + half); ++v) {
      for (int u = std::max(0, x - half); u <= std::min(grey.cols - 1, x + half); ++u) {
        if (valid.at<uint8_t>(v, u) == 0) continue;
        sum += linear[grey.at<uint8_t>(v, u)];
        ++count;
      }
    }
    brightness.push_back(count > 0 ? sum / count : 0.0);
  }
  return brightness;
}

std::vector<double> BlendWithShading(const ShadedPoints& calibration, const ShadedPoints& targets, double weight) {
  std::vector<double> log_factors;
  for (size_t i = 0; i < calibration.distances.size(); ++i) {
    if (calibration.brightness[i] > 0 && calibration.distances[i] > 0) {
      log_factors.push_back(std::log(calibration.distances[i]) + 0.5 * std::log(calibration.brightness[i]));
    }
  }
  std::vector<double> blended = targets.distances;
  if (log_factors.empty()) return blended;
  const double log_factor = Median(log_factors);
  for (size_t i = 0; i < blended.size(); ++i) {
    if (targets.brightness[i] <= 0 || !(blended[i] > 0)) continue;
    const double log_shading = log_factor - 0.5 * std::log(targets.brightness[i]);
    blended[i] = std::exp(weight * log_shading + (1 - weight) * std::log(blended[i]));
  }
  return blended;
}

}  // namespace nrslam
