#include "nrslam/eval/error_view.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "nrslam/util/error.h"
#include "nrslam/util/json_options.h"

namespace nrslam {
namespace {

constexpr int kSubpixelBits = 4;  // cv::circle takes fixed-point centres: sub-pixel positions stay sub-pixel
const cv::Scalar kOutline(0, 0, 0);
const cv::Scalar kUnscored(160, 160, 160);
constexpr double kNotScored = std::numeric_limits<double>::quiet_NaN();

cv::Point FixedPoint(const cv::Point2d& pixel) {
  constexpr double kOne = 1 << kSubpixelBits;
  return cv::Point(static_cast<int>(std::lround(pixel.x * kOne)), static_cast<int>(std::lround(pixel.y * kOne)));
}

void DrawDisc(cv::Mat& image, const cv::Point2d& pixel, int radius, const cv::Scalar& fill) {
  const int fixed_radius = radius << kSubpixelBits;
  cv::circle(image, FixedPoint(pixel), fixed_radius + (1 << kSubpixelBits), kOutline, cv::FILLED, cv::LINE_AA,
             kSubpixelBits);
  cv::circle(image, FixedPoint(pixel), fixed_radius, fill, cv::FILLED, cv::LINE_AA, kSubpixelBits);
}

void DrawRing(cv::Mat& image, const cv::Point2d& pixel, int radius) {
  cv::circle(image, FixedPoint(pixel), radius << kSubpixelBits, kUnscored, 1, cv::LINE_AA, kSubpixelBits);
}

// White at no error, towards red (too deep) or blue (too shallow), saturated at ±full_scale.
cv::Scalar ErrorColour(double relative_error, double full_scale) {
  const double level = std::clamp(relative_error / full_scale, -1.0, 1.0);
  const double fade = 255.0 * (1.0 - std::abs(level));
  return level >= 0 ? cv::Scalar(fade, fade, 255) : cv::Scalar(255, fade, fade);
}

}  // namespace

void ErrorViewOptions::Check() const {
  CheckOption(near_mm >= 0 && far_mm > near_mm, "error view", "need 0 <= near_mm < far_mm");
  CheckOption(full_scale_error >= 0, "error view", "full_scale_error must be >= 0 (0: from the frame's errors)");
  CheckOption(point_radius_px >= 1, "error view", "point_radius_px must be >= 1");
}

cv::Mat ColourDepth(const cv::Mat& depth_mm, double near_mm, double far_mm) {
  if (depth_mm.type() != CV_32F) throw Error("ColourDepth: expected a CV_32F depth map");
  cv::Mat level;
  depth_mm.convertTo(level, CV_8U, -255.0 / (far_mm - near_mm), 255.0 * far_mm / (far_mm - near_mm));
  cv::Mat coloured;
  cv::applyColorMap(level, coloured, cv::COLORMAP_TURBO);
  const cv::Mat none = ~(depth_mm > 0);  // zero, negative or NaN: no depth
  coloured.setTo(cv::Scalar::all(0), none);
  return coloured;
}

ErrorView DrawErrorView(const cv::Mat& bgr, const cv::Mat& depth_mm, const FramePoints& points,
                        const EvaluationOptions& evaluation, const ErrorViewOptions& options) {
  options.Check();
  if (bgr.type() != CV_8UC3) throw Error("DrawErrorView: expected a CV_8UC3 colour image");
  const bool has_depth = !depth_mm.empty();
  if (has_depth && depth_mm.size() != bgr.size()) throw Error("DrawErrorView: depth and colour differ in size");

  ErrorView view;
  if (has_depth) {
    std::vector<DepthPoint> frame_points;
    for (const auto& [id, point] : points) frame_points.push_back(point);
    view.evaluation = EvaluateFrame(frame_points, depth_mm, evaluation);
  }
  // Each point's relative error, NaN where it is not scored. Without a scale nothing is, and a
  // frame with a scale has depth to sample.
  std::vector<double> relative_errors;
  double squared_sum = 0;
  int scored = 0;
  for (const auto& [id, point] : points) {
    const double truth = view.evaluation.evaluated ? SampleDepth(depth_mm, point.pixel).value_or(kNotScored) : kNotScored;
    const double error = (view.evaluation.scale * point.depth - truth) / truth;
    relative_errors.push_back(std::isfinite(error) ? error : kNotScored);  // no truth, or no finite estimate
    if (std::isnan(relative_errors.back())) continue;
    squared_sum += relative_errors.back() * relative_errors.back();
    ++scored;
  }
  constexpr double kLeastAutomaticScale = 0.005;
  view.full_scale_error = options.full_scale_error > 0 ? options.full_scale_error
                          : scored > 0 ? std::max(kLeastAutomaticScale, 3 * std::sqrt(squared_sum / scored))
                                       : kLeastAutomaticScale;
  cv::Mat colour_panel = bgr.clone();
  cv::Mat depth_panel = has_depth ? ColourDepth(depth_mm, options.near_mm, options.far_mm) : cv::Mat();
  // Every point's scaled depth in the depth panel's colours, in one pass of the colour map.
  cv::Mat scaled_depths(1, static_cast<int>(points.size()), CV_32F);
  int index = 0;
  for (const auto& [id, point] : points) scaled_depths.at<float>(0, index++) = view.evaluation.scale * point.depth;
  const cv::Mat depth_colours = points.empty() ? cv::Mat() : ColourDepth(scaled_depths, options.near_mm, options.far_mm);
  index = 0;
  for (const auto& [id, point] : points) {
    const double error = relative_errors[index];
    const cv::Vec3b depth_colour = depth_colours.at<cv::Vec3b>(0, index++);
    if (std::isnan(error)) {
      DrawRing(colour_panel, point.pixel, options.point_radius_px);
      continue;
    }
    DrawDisc(colour_panel, point.pixel, options.point_radius_px, ErrorColour(error, view.full_scale_error));
    DrawDisc(depth_panel, point.pixel, options.point_radius_px, cv::Scalar(depth_colour[0], depth_colour[1], depth_colour[2]));
  }
  if (has_depth) {
    cv::hconcat(colour_panel, depth_panel, view.image);
  } else {
    view.image = colour_panel;
  }
  return view;
}

}  // namespace nrslam
