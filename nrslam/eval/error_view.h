// eval: one frame's points drawn over its image, coloured by their depth error. One RMSE per
// frame hides where the error sits (a tilt across the image, the far end of the tube, the
// points near a fold); a picture shows it at a glance.
#pragma once

#include <opencv2/core.hpp>

#include "nrslam/eval/common_points.h"
#include "nrslam/eval/depth_evaluation.h"

namespace nrslam {

struct ErrorViewOptions {
  double near_mm = 10.0;               // depth drawn red, mm
  double far_mm = 120.0;               // depth drawn blue, mm
  // Relative depth error drawn at full colour (0.25 = 25 %); 0: three times the frame's rms
  // relative error (at least 0.5 %), for runs whose errors are all a few per cent.
  double full_scale_error = 0.25;
  int point_radius_px = 3;             // disc radius, pixels of the input image
  void Check() const;
};

// Depth in false colour, CV_8UC3: near_mm red through far_mm blue, no depth black.
cv::Mat ColourDepth(const cv::Mat& depth_mm, double near_mm, double far_mm);

struct ErrorView {
  cv::Mat image;               // CV_8UC3: the colour panel, then the depth panel if there is depth
  FrameEvaluation evaluation;  // the frame as the evaluator scores it
  double full_scale_error = 0; // the relative error drawn at full colour
};

// Colour panel: `bgr` with each point as a disc coloured by its relative depth error after the
// frame's evaluator scale s, (s·z_est − z_gt) / z_gt: blue too shallow, white right, red too
// deep. A point the evaluator cannot score (no ground truth under it, or too few points in the
// frame for a scale) is a grey ring that leaves the pixel under it visible.
// Depth panel (only when `depth_mm` is not empty): the ground truth in false colour with each
// scored point filled in the colour of its own scaled depth, so a right point melts into the
// background and a wrong one stands out.
ErrorView DrawErrorView(const cv::Mat& bgr, const cv::Mat& depth_mm, const FramePoints& points,
                        const EvaluationOptions& evaluation, const ErrorViewOptions& options);

}  // namespace nrslam
