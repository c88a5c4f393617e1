// sim: procedural mucosa albedo — multi-octave value noise in a pink-red palette, branching
// vessel trees, and regions of faint texture, as real tissue has. Generated once per scene
// in material coordinates (mm), so it moves with the deforming surface, and mip-mapped so
// distant walls are filtered instead of aliased.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

#include "nrslam/sim/sim_options.h"

namespace nrslam {

class MucosaTexture {
 public:
  // A width_mm × height_mm texture; wraps along v (height) when periodic_v.
  MucosaTexture(double width_mm, double height_mm, bool periodic_v, const AppearanceOptions& options,
                uint64_t seed, const Eigen::Vector3f& base_colour);

  // Linear RGB albedo in [0, 1] at (u, v) mm, filtered over a footprint of `footprint_mm`.
  Eigen::Vector3f Sample(double u_mm, double v_mm, double footprint_mm) const;

  double width_mm() const { return width_mm_; }
  double height_mm() const { return height_mm_; }

 private:
  double texel_mm_;
  double width_mm_;
  double height_mm_;
  bool periodic_v_;
  std::vector<cv::Mat> levels_;  // CV_8UC3 linear RGB, level k has texel size texel_mm·2^k

  Eigen::Vector3f SampleLevel(int level, double u_mm, double v_mm) const;
};

}  // namespace nrslam
