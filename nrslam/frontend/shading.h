// frontend: the shading prior's measurements — how bright the surface around a pixel is, and
// the distances that brightness implies.
//
// The endoscope's light sits at the camera, so the irradiance of a surface falls with the square
// of its distance r: linear brightness I ∝ ρ·cos θ / r², and r ∝ I^(−1/2) up to the albedo ρ and
// the incidence θ, which this model leaves as noise. The unknown factor (light power, exposure,
// the map's scale) is one per image: it is fitted to points whose distances are known. Neither
// the paper nor the reference uses this cue; it is off by default (docs/mapping.md).
#pragma once

#include <opencv2/core.hpp>

#include <vector>

#include "nrslam/frontend/frontend_options.h"

namespace nrslam {

// Per pixel: (grey / 255)^gamma averaged over the valid (non-zero in `valid`) pixels of the box
// of half side options.patch_px around it; 0 where the box holds no valid pixel.
std::vector<double> LinearBrightness(const cv::Mat& grey, const cv::Mat& valid, const std::vector<cv::Point2f>& pixels,
                                     const ShadingOptions& options);

// Points seen in one image, each with its distance from the camera and its linear brightness.
struct ShadedPoints {
  std::vector<double> distances;
  std::vector<double> brightness;  // 0: unknown
};

// The distances of `targets` moved toward what their brightness says: log r ← w·log r_shading +
// (1 − w)·log r, where r_shading = c·I^(−1/2) and log c is the median over `calibration`'s points
// (those with a brightness) of log r + ½ log I. A target without brightness, or every target
// when no calibration point has one, keeps its distance. `weight` in [0, 1].
std::vector<double> BlendWithShading(const ShadedPoints& calibration, const ShadedPoints& targets, double weight);

}  // namespace nrslam
