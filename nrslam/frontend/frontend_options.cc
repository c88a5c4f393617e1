#include "nrslam/frontend/frontend_options.h"

#include "nrslam/util/json_options.h"

namespace nrslam {

void MaskOptions::Check() const {
  CheckOption(border_px >= 0 && bright_margin_px >= 0 && erosion_px >= 0, "masks", "sizes must be >= 0");
  CheckOption(bright_threshold >= 0 && bright_threshold <= 255, "masks", "bright_threshold must be in [0, 255]");
  CheckOption(static_frames == 0 || static_frames >= kMinStaticFrames, "masks",
              "static_frames must be 0 (off) or >= " + std::to_string(kMinStaticFrames));
  CheckOption(static_max_change >= 0 && static_max_change <= 255, "masks", "static_max_change must be in [0, 255]");
  CheckOption(static_min_area_px >= 0 && static_margin_px >= 0, "masks", "static sizes must be >= 0");
  CheckOption(static_min_edge >= 0, "masks", "static_min_edge must be >= 0");
  CheckOption(static_min_seconds >= 0, "masks", "static_min_seconds must be >= 0");
  CheckOption(static_window_seconds >= static_min_seconds && static_window_seconds > 0, "masks",
              "static_window_seconds must be > 0 and >= static_min_seconds");
  CheckOption(static_max_fraction >= 0 && static_max_fraction <= 1, "masks", "static_max_fraction must be in [0, 1]");
}

void FeatureOptions::Check() const {
  CheckOption(min_eigenvalue > 0, "features", "min_eigenvalue must be > 0");
  CheckOption(nms_radius_px >= 1 && exclusion_radius_px >= 0, "features", "radii must be >= 1 / >= 0");
  CheckOption(max_features >= 1, "features", "max_features must be >= 1");
}

void ShadingOptions::Check() const {
  CheckOption(gamma > 0 && patch_px >= 0, "shading", "need gamma > 0 and patch_px >= 0");
}

void KltOptions::Check() const {
  CheckOption(window_px >= 5 && window_px % 2 == 1 && window_px <= 63, "klt", "window_px must be odd, 5..63");
  CheckOption(levels >= 1 && levels <= 8, "klt", "levels must be 1..8");
  CheckOption(max_iterations >= 1 && epsilon_px > 0 && min_eigenvalue >= 0, "klt",
              "max_iterations >= 1, epsilon_px > 0, min_eigenvalue >= 0");
  CheckOption(max_displacement_px > 0, "klt", "max_displacement_px must be > 0");
  CheckOption(affine_iterations >= 1, "klt", "affine_iterations must be >= 1");
  for (double ssim : {ssim_tracking, ssim_initialisation, ssim_reassociation}) {
    CheckOption(ssim >= -1 && ssim <= 1, "klt", "SSIM thresholds must be in [-1, 1]");
  }
  CheckOption(min_texture_correlation >= -1 && min_texture_correlation <= 1, "klt",
              "min_texture_correlation must be in [-1, 1] (-1: off)");
}

}  // namespace nrslam
