// Test fixtures shared by the front-end tests: a rendered mucosa frame, known warps and
// illumination changes applied to it.
#pragma once

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "nrslam/sim/renderer.h"

namespace nrslam {

inline cv::Mat RenderedGrey(const std::string& preset, int frame) {
  Renderer renderer(SimPreset(preset));
  cv::Mat grey;
  cv::cvtColor(renderer.Render(frame).left.bgr, grey, cv::COLOR_BGR2GRAY);
  return grey;
}

struct Illumination {
  std::string name;
  bool local;       // smooth per-pixel gain/bias instead of one for the whole image
  double gain, bias;
};

// I' = α(x, y)·I + β(x, y); the local version sweeps α over [0.6, 1.5] and β over
// [-30, 30] across the image, changing within a patch as real endoscope light does.
inline cv::Mat Illuminate(const cv::Mat& grey, const Illumination& light) {
  cv::Mat out(grey.size(), CV_8UC1);
  for (int y = 0; y < grey.rows; ++y) {
    for (int x = 0; x < grey.cols; ++x) {
      double gain = light.gain, bias = light.bias;
      if (light.local) {
        gain = 1.05 + 0.45 * std::sin(x / 70.0) * std::cos(y / 55.0);
        bias = 30.0 * std::sin(y / 60.0 + 0.5) * std::cos(x / 80.0);
      }
      out.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(gain * grey.at<uint8_t>(y, x) + bias);
    }
  }
  return out;
}

struct Warp {
  std::string name;
  cv::Mat affine;  // 2x3, maps reference pixels to current pixels
};

inline std::vector<Warp> KnownWarps(const cv::Size& size) {
  const cv::Point2f centre(0.5f * (size.width - 1), 0.5f * (size.height - 1));
  auto translation = [](double dx, double dy) -> cv::Mat { return cv::Mat((cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, dy)); };
  return {{"translate(20,-12)", translation(20, -12)},
          {"translate(-14,20)", translation(-14, 20)},
          {"rotate 5deg", cv::getRotationMatrix2D(centre, 5.0, 1.0)},
          {"scale +5%", cv::getRotationMatrix2D(centre, 0.0, 1.05)},
          {"scale -5%", cv::getRotationMatrix2D(centre, 0.0, 0.95)}};
}

inline cv::Point2f Apply(const cv::Mat& affine, const cv::Point2f& p) {
  return cv::Point2f(static_cast<float>(affine.at<double>(0, 0) * p.x + affine.at<double>(0, 1) * p.y + affine.at<double>(0, 2)),
                     static_cast<float>(affine.at<double>(1, 0) * p.x + affine.at<double>(1, 1) * p.y + affine.at<double>(1, 2)));
}

}  // namespace nrslam
