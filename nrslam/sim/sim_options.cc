#include "nrslam/sim/sim_options.h"

#include <cmath>

#include "nrslam/util/json_options.h"

namespace nrslam {

void SimCameraOptions::Check() const {
  const std::string context = "sim camera";
  CheckOption(model == "pinhole" || model == "fisheye", context, "model must be pinhole or fisheye, got '" + model + "'");
  CheckOption(width >= 32 && height >= 32 && width <= 8192 && height <= 8192, context, "image size must be 32..8192 px");
  CheckOption(fov_deg > 10 && fov_deg < 160, context, "fov_deg must be in (10, 160)");
  CheckOption(fisheye_fov_deg >= 100 && fisheye_fov_deg <= 200, context, "fisheye_fov_deg must be in [100, 200]");
  CheckOption(std::isfinite(fisheye_k0) && std::isfinite(fisheye_k1), context, "fisheye coefficients must be finite");
  CheckOption(!stereo || model == "pinhole", context, "stereo needs the pinhole model (rectified pair)");
  CheckOption(baseline_mm > 0, context, "baseline_mm must be > 0");
}

void DeformationOptions::Check() const {
  const std::string context = "sim deformation";
  CheckOption(amplitude_mm >= 0 && amplitude_mm <= 30, context, "amplitude_mm must be in [0, 30]");
  CheckOption(omega_rad_s >= 0 && omega_rad_s <= 50, context, "omega_rad_s must be in [0, 50]");
  CheckOption(lambda_mm > 0, context, "lambda_mm must be > 0");
}

void ColonOptions::Check() const {
  const std::string context = "sim colon";
  CheckOption(radius_mean_mm > 5 && radius_variation_mm >= 0 && radius_variation_mm < radius_mean_mm - 5, context,
              "radius_mean_mm must be > 5 and radius_variation_mm in [0, radius_mean_mm - 5)");
  CheckOption(radius_wavelength_mm > 0 && bend_wavelength_mm > 0, context, "wavelengths must be > 0");
  CheckOption(bend_amplitude_mm >= 0, context, "bend_amplitude_mm must be >= 0");
  CheckOption(fold_spacing_min_mm > 2 * fold_width_mm && fold_spacing_max_mm >= fold_spacing_min_mm, context,
              "fold spacing must exceed twice the fold width, max >= min");
  CheckOption(fold_height_min_mm >= 0 && fold_height_max_mm >= fold_height_min_mm &&
                  fold_height_max_mm < radius_mean_mm - radius_variation_mm - 3,
              context, "fold heights must be >= 0, max >= min, and leave a lumen");
  CheckOption(fold_width_mm > 0, context, "fold_width_mm must be > 0");
  CheckOption(speed_mm_per_frame >= 0 && start_mm >= 0, context, "speed_mm_per_frame and start_mm must be >= 0");
  CheckOption(wobble_lateral_mm >= 0 && wobble_rotation_deg >= 0, context, "wobble must be >= 0");
  CheckOption(view_ahead_mm >= 20, context, "view_ahead_mm must be >= 20");
  CheckOption(ring_spacing_mm > 0.01 && ring_spacing_mm < 5, context, "ring_spacing_mm must be in (0.01, 5)");
  CheckOption(angular_steps >= 16 && angular_steps <= 8192, context, "angular_steps must be in [16, 8192]");
}

void LobesOptions::Check() const {
  const std::string context = "sim lobes";
  CheckOption(distance_mm > 10, context, "distance_mm must be > 10");
  CheckOption(lobe_width_mm > 5 && lobe_height_mm > 5 && dome_height_mm >= 0, context, "lobe sizes must be positive");
  CheckOption(camera_drift_mm >= 0, context, "camera_drift_mm must be >= 0");
  CheckOption(grid_steps >= 8 && grid_steps <= 4096, context, "grid_steps must be in [8, 4096]");
}

void AppearanceOptions::Check() const {
  const std::string context = "sim appearance";
  CheckOption(light_power > 0, context, "light_power must be > 0");
  CheckOption(specular_strength >= 0 && specular_strength <= 1, context, "specular_strength must be in [0, 1]");
  CheckOption(shininess >= 1, context, "shininess must be >= 1");
  CheckOption(vignetting >= 0 && vignetting < 1, context, "vignetting must be in [0, 1)");
  CheckOption(gamma > 0.1 && gamma < 5, context, "gamma must be in (0.1, 5)");
  CheckOption(noise_sigma >= 0, context, "noise_sigma must be >= 0");
  CheckOption(texel_mm >= 0.02 && texel_mm <= 1, context, "texel_mm must be in [0.02, 1]");
  CheckOption(vessel_density >= 0 && weak_texture >= 0 && weak_texture <= 1, context,
              "vessel_density must be >= 0 and weak_texture in [0, 1]");
}

void SimOptions::Check() const {
  CheckOption(scene == "colon" || scene == "lobes", "sim", "scene must be colon or lobes, got '" + scene + "'");
  CheckOption(frames >= 1 && frames <= 100000, "sim", "frames must be in [1, 100000]");
  CheckOption(fps > 0, "sim", "fps must be > 0");
  CheckOption(depth_unit_mm > 0, "sim", "depth_unit_mm must be > 0");
  CheckOption(threads >= 0, "sim", "threads must be >= 0");
  camera.Check();
  deformation.Check();
  colon.Check();
  lobes.Check();
  appearance.Check();
}

std::vector<std::string> SimPresetNames() {
  return {"sim-0", "sim-1", "sim-2", "sim-3", "sim-4", "sim-5", "sim-6", "lap-lobes"};
}

SimOptions SimPreset(const std::string& name) {
  // (A mm, ω rad/s) of the paper's simulated colonoscopies.
  static const double kTable[7][2] = {{0, 0}, {2.5, 2.5}, {2.5, 5}, {5, 2.5}, {5, 5}, {10, 2.5}, {10, 5}};
  SimOptions options;
  for (int i = 0; i < 7; ++i) {
    if (name == "sim-" + std::to_string(i)) {
      options.deformation.amplitude_mm = kTable[i][0];
      options.deformation.omega_rad_s = kTable[i][1];
      return options;
    }
  }
  if (name == "lap-lobes") {
    options.scene = "lobes";
    options.camera.fov_deg = 70.0;
    options.deformation.amplitude_mm = 8.0;  // breathing excursion of each lobe
    options.deformation.omega_rad_s = 1.6;   // ~15 breaths per minute
    options.appearance.light_power = 6500.0; // a laparoscope lights 50-120 mm, not 10-60 mm
    return options;
  }
  std::string known;
  for (const std::string& preset : SimPresetNames()) known += (known.empty() ? "" : ", ") + preset;
  throw Error("unknown simulator preset '" + name + "' (known: " + known + ")");
}

}  // namespace nrslam
