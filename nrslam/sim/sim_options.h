// sim: every parameter of a simulated sequence, with units, defaults and validation.
//
// Presets (sim_presets.h) are these options with a few fields changed. All fields can be
// set from the command line (`nrslam_simulate --set deformation.amplitude_mm=5`), and the
// resolved options are stored in the sequence's provenance.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace nrslam {

struct SimCameraOptions {
  std::string model = "pinhole";  // "pinhole" or "fisheye" (Kannala–Brandt)
  int width = 640;                // px
  int height = 480;               // px
  double fov_deg = 90.0;          // pinhole: horizontal field of view, deg
  double fisheye_fov_deg = 170.0; // fisheye: full field of view of the image circle, deg
  double fisheye_k0 = -0.02;      // Kannala–Brandt coefficients of the fisheye lens
  double fisheye_k1 = 0.002;
  bool stereo = false;            // also render a rectified right camera (pinhole only)
  double baseline_mm = 5.0;       // stereo baseline, mm
  // A calibration file to render with instead of the model above (a camera JSON, a
  // sequence.json, OCamCalib's calib_results.txt or an OpenCV / ROS calibration): your own lens. Its image size
  // replaces width and height; every pixel whose ray the model defines is rendered.
  std::string calibration;
  void Check() const;
};

// Deformation law (paper, Endomapper simulations), applied to every rest surface point V⁰:
//   V_y(t) = V⁰_y + A·sin(ω·t + (V⁰_x + V⁰_y + V⁰_z)/λ)
// The lobes scene uses A and ω as its breathing amplitude and rate instead.
struct DeformationOptions {
  double amplitude_mm = 0.0;  // A, mm
  double omega_rad_s = 0.0;   // ω, rad/s
  double lambda_mm = 40.0;    // λ, mm: spatial scale of the wave; 40 mm puts ~2 rad of phase
                              // across what a colonoscope sees, so nearby points move alike
                              // while distant ones do not
  void Check() const;
};

struct ColonOptions {
  double radius_mean_mm = 22.0;         // mean lumen radius, mm
  double radius_variation_mm = 5.0;     // slow radius change (keeps it within 15–30 mm), mm
  double radius_wavelength_mm = 110.0;  // length scale of the radius change, mm
  double bend_amplitude_mm = 12.0;      // lateral excursion of the centreline, mm
  double bend_wavelength_mm = 180.0;    // length scale of the centreline bends, mm
  double fold_spacing_min_mm = 25.0;    // haustral fold spacing range, mm
  double fold_spacing_max_mm = 40.0;
  double fold_height_min_mm = 3.0;      // fold height range (inward ridge), mm
  double fold_height_max_mm = 6.0;
  double fold_width_mm = 2.2;           // Gaussian half-width of a fold ridge, mm
  double speed_mm_per_frame = 0.5;      // camera advance along the centreline, mm/frame
  double start_mm = 20.0;               // where the camera starts along the centreline, mm
  double wobble_lateral_mm = 1.5;       // smooth lateral wobble of the tip, mm
  double wobble_rotation_deg = 3.0;     // smooth rotational wobble of the tip, deg
  double view_ahead_mm = 220.0;         // colon length meshed ahead of the camera, mm
  double ring_spacing_mm = 0.4;         // mesh ring spacing at the camera, grows 2 % per mm ahead
  int angular_steps = 400;              // mesh vertices around the lumen
  bool straight = false;                // straight cylinder of radius_mean_mm, no folds (tests)
  void Check() const;
};

struct LobesOptions {
  double distance_mm = 70.0;         // camera to the lobe tops, mm (lobes span 50–120 mm)
  double lobe_width_mm = 60.0;       // extent of each lobe across the image, mm
  double lobe_height_mm = 80.0;      // extent along the seam, mm
  double dome_height_mm = 14.0;      // how far a lobe bulges towards the camera, mm
  double phase_offset_rad = 2.6;     // breathing phase of lobe B relative to lobe A, rad
  double camera_drift_mm = 4.0;      // slow circular drift of the laparoscope, mm
  int grid_steps = 300;              // mesh vertices along each side of a lobe
  void Check() const;
};

struct AppearanceOptions {
  double light_power = 650.0;       // irradiance scale: intensity at distance r is power/r², mm²
  double specular_strength = 0.35;  // wet-mucosa highlight strength, 0–1
  double shininess = 70.0;          // Phong exponent of the highlights
  double vignetting = 0.35;         // intensity lost at the image edge, 0–1
  double gamma = 2.2;               // display gamma
  double noise_sigma = 2.0;         // sensor noise, 8-bit grey levels
  double texel_mm = 0.1;            // texture resolution, mm per texel
  double vessel_density = 1.0;      // vessel trees per 100 mm² (0 = none)
  double weak_texture = 0.5;        // 0–1: how much of the surface has faint texture
  void Check() const;
};

struct SimOptions {
  std::string scene = "colon";  // "colon" or "lobes"
  int frames = 120;
  double fps = 30.0;            // frames per second (sets t = index / fps)
  uint64_t seed = 1;            // everything random derives from it
  double depth_unit_mm = 0.01;  // ground-truth depth PNG unit, mm
  int threads = 0;              // render threads, 0 = all cores
  SimCameraOptions camera;
  DeformationOptions deformation;
  ColonOptions colon;
  LobesOptions lobes;
  AppearanceOptions appearance;
  void Check() const;
};

NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(SimCameraOptions, model, width, height, fov_deg, fisheye_fov_deg, fisheye_k0,
                                                fisheye_k1, stereo, baseline_mm, calibration)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(DeformationOptions, amplitude_mm, omega_rad_s, lambda_mm)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(ColonOptions, radius_mean_mm, radius_variation_mm,
                                                radius_wavelength_mm, bend_amplitude_mm, bend_wavelength_mm,
                                                fold_spacing_min_mm, fold_spacing_max_mm, fold_height_min_mm,
                                                fold_height_max_mm, fold_width_mm, speed_mm_per_frame, start_mm,
                                                wobble_lateral_mm, wobble_rotation_deg, view_ahead_mm,
                                                ring_spacing_mm, angular_steps, straight)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(LobesOptions, distance_mm, lobe_width_mm, lobe_height_mm,
                                                dome_height_mm, phase_offset_rad, camera_drift_mm, grid_steps)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(AppearanceOptions, light_power, specular_strength, shininess,
                                                vignetting, gamma, noise_sigma, texel_mm, vessel_density,
                                                weak_texture)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(SimOptions, scene, frames, fps, seed, depth_unit_mm, threads, camera,
                                                deformation, colon, lobes, appearance)

// Named presets: "sim-0" … "sim-6" (the paper's (A, ω) table) and "lap-lobes".
std::vector<std::string> SimPresetNames();
// Throws Error for an unknown name, listing the known ones.
SimOptions SimPreset(const std::string& name);

}  // namespace nrslam
