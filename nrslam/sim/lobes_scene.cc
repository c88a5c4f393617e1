#include "nrslam/sim/lobes_scene.h"

#include <Eigen/Geometry>

#include <cmath>

#include "nrslam/util/random.h"

namespace nrslam {
namespace {
constexpr double kTwoPi = 2.0 * M_PI;
constexpr double kBackgroundHalfExtent = 130.0;  // mm: fills a 70° view from 120 mm with drift to spare
}  // namespace

LobesScene::LobesScene(const SimOptions& options) : options_(options) {
  Rng rng(SplitMix64(options.seed ^ 0x10beULL));
  camera_phase_ = rng.Uniform(0, kTwoPi);
  const Eigen::Vector3f liver(0.55f, 0.20f, 0.16f), tissue(0.80f, 0.50f, 0.38f);
  AppearanceOptions background_appearance = options.appearance;
  background_appearance.texel_mm *= 2.0;  // seen from ~120 mm; finer texels would never show
  for (int patch = 0; patch < 3; ++patch) {
    textures_[patch] = std::make_unique<MucosaTexture>(
        2 * HalfExtentX(patch), 2 * HalfExtentY(patch), false,
        patch == kBackground ? background_appearance : options.appearance,
        SplitMix64(options.seed ^ (0x7e47ULL + static_cast<uint64_t>(patch))), patch == kBackground ? tissue : liver);
  }
}

double LobesScene::HalfExtentX(int patch) const {
  return patch == kBackground ? kBackgroundHalfExtent : 0.5 * options_.lobes.lobe_width_mm;
}
double LobesScene::HalfExtentY(int patch) const {
  return patch == kBackground ? kBackgroundHalfExtent : 0.5 * options_.lobes.lobe_height_mm;
}

Eigen::Vector3d LobesScene::RestPosition(int patch, double u, double v) const {
  const LobesOptions& lobes = options_.lobes;
  const double hx = HalfExtentX(patch), hy = HalfExtentY(patch);
  if (patch == kBackground) {
    const double x = hx * u, y = hy * v;
    const double z = lobes.distance_mm + lobes.dome_height_mm + 35.0 + 4.0 * std::sin(x / 15.0) * std::sin(y / 19.0);
    return Eigen::Vector3d(x, y, z);
  }
  // A dome whose rim curls away from the camera; lobe B sits a little deeper, so lobe A's rim
  // overlaps it along the seam.
  const double side = patch == kLobeA ? -1.0 : 1.0;
  const double centre_x = side * 0.42 * lobes.lobe_width_mm;
  const double depth = lobes.distance_mm + (patch == kLobeB ? 8.0 : 0.0);
  const double bulge = (1 - u * u) * (1 - v * v);
  const double curl_u = std::max(0.0, std::abs(u) - 0.7), curl_v = std::max(0.0, std::abs(v) - 0.7);
  const double z = depth + lobes.dome_height_mm * (1.0 - bulge) + 30.0 * (curl_u * curl_u + curl_v * curl_v);
  // Rounded outline: the lobe narrows towards its ends.
  return Eigen::Vector3d(centre_x + hx * u * (1.0 - 0.3 * v * v), hy * v * (1.0 - 0.2 * u * u) + side * 4.0, z);
}

Eigen::Vector3d LobesScene::LobeDisplacement(int patch, double time_s) const {
  if (patch == kBackground) return Eigen::Vector3d::Zero();
  const double phase = patch == kLobeA ? 0.0 : options_.lobes.phase_offset_rad;
  const Eigen::Vector3d direction =
      Eigen::Vector3d(patch == kLobeA ? 0.25 : -0.25, 1.0, 0.3).normalized();  // mostly along the seam
  return options_.deformation.amplitude_mm * std::sin(options_.deformation.omega_rad_s * time_s + phase) * direction;
}

Eigen::Vector3d LobesScene::Position(int patch, double u, double v, double time_s) const {
  Eigen::Vector3d position = RestPosition(patch, u, v);
  if (patch == kBackground) return position;
  // Rigid sliding plus a slight swelling of the dome towards the camera.
  const double phase = patch == kLobeA ? 0.0 : options_.lobes.phase_offset_rad;
  const double swell = 0.06 * options_.lobes.dome_height_mm * (1 - u * u) * (1 - v * v) *
                       std::sin(options_.deformation.omega_rad_s * time_s + phase);
  position.z() -= swell;
  return position + LobeDisplacement(patch, time_s);
}

Eigen::Vector2d LobesScene::TextureCoords(int patch, double u, double v) const {
  return Eigen::Vector2d(HalfExtentX(patch) * (u + 1.0), HalfExtentY(patch) * (v + 1.0));
}

SurfaceGrid LobesScene::Grid(int patch, double) const {
  const int steps = patch == kBackground ? 160 : options_.lobes.grid_steps;
  SurfaceGrid grid;
  for (int i = 0; i < steps; ++i) {
    grid.u.push_back(-1.0 + 2.0 * i / (steps - 1));
    grid.v.push_back(-1.0 + 2.0 * i / (steps - 1));
  }
  return grid;
}

Rigid3 LobesScene::WorldFromCamera(double time_s) const {
  const LobesOptions& lobes = options_.lobes;
  const double angle = kTwoPi * time_s / 7.0 + camera_phase_;
  const Eigen::Vector3d position(lobes.camera_drift_mm * std::cos(angle), 0.7 * lobes.camera_drift_mm * std::sin(angle),
                                 2.0 * std::sin(kTwoPi * time_s / 9.0));
  const Eigen::Vector3d target(0.0, 0.0, lobes.distance_mm + 0.5 * lobes.dome_height_mm);
  const Eigen::Vector3d z = (target - position).normalized();
  const Eigen::Vector3d x = (Eigen::Vector3d::UnitX() - z.x() * z).normalized();
  Eigen::Matrix3d rotation;
  rotation << x, z.cross(x), z;
  return Rigid3(Eigen::Quaterniond(rotation), position);
}


}  // namespace nrslam
