#include "nrslam/sim/colon_scene.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

#include "nrslam/util/random.h"

namespace nrslam {
namespace {
constexpr double kTwoPi = 2.0 * M_PI;
constexpr double kMaxFoldTilt = 3.0;  // mm
}  // namespace

ColonScene::ColonScene(const SimOptions& options) : options_(options) {
  const ColonOptions& colon = options.colon;
  length_mm_ = colon.start_mm + colon.speed_mm_per_frame * options.frames + colon.view_ahead_mm + 20.0;
  Rng rng(SplitMix64(options.seed ^ 0xc010ULL));
  for (double& phase : phases_) phase = rng.Uniform(0, kTwoPi);
  for (double& phase : wobble_phases_) phase = rng.Uniform(0, kTwoPi);
  if (!colon.straight) {
    for (double s = -40.0 + rng.Uniform(0, colon.fold_spacing_max_mm); s < length_mm_ + 40.0;
         s += rng.Uniform(colon.fold_spacing_min_mm, colon.fold_spacing_max_mm)) {
      Fold fold{s, rng.Uniform(colon.fold_height_min_mm, colon.fold_height_max_mm), rng.Uniform(1.0, kMaxFoldTilt),
                rng.Uniform(0, kTwoPi), 0.0, 0.0};
      fold.cos_phase = std::cos(fold.phase);
      fold.sin_phase = std::sin(fold.phase);
      folds_.push_back(fold);
    }
  }
  for (int j = 0; j < colon.angular_steps; ++j) {
    const double theta = kTwoPi * j / colon.angular_steps;
    tables_.cos1.push_back(std::cos(theta));
    tables_.sin1.push_back(std::sin(theta));
    tables_.cos3.push_back(std::cos(3 * theta));
    tables_.sin3.push_back(std::sin(3 * theta));
  }
  texture_ = std::make_unique<MucosaTexture>(length_mm_, kTwoPi * colon.radius_mean_mm, true, options.appearance,
                                             SplitMix64(options.seed ^ 0x7e47ULL),
                                             Eigen::Vector3f(0.85f, 0.30f, 0.22f));
}

Eigen::Vector3d ColonScene::Centreline(double s) const {
  const ColonOptions& colon = options_.colon;
  if (colon.straight) return Eigen::Vector3d(0, 0, s);
  const double b = colon.bend_amplitude_mm / 1.5, l = colon.bend_wavelength_mm;
  auto lateral = [&](double at) {
    return Eigen::Vector2d(
        b * (std::sin(kTwoPi * at / l + phases_[0]) + 0.5 * std::sin(kTwoPi * at / (0.61 * l) + phases_[1])),
        b * (std::sin(kTwoPi * at / (1.13 * l) + phases_[2]) + 0.5 * std::sin(kTwoPi * at / (0.53 * l) + phases_[3])));
  };
  const Eigen::Vector2d offset = lateral(s) - lateral(0.0);  // the tube starts on the world z axis
  return Eigen::Vector3d(offset.x(), offset.y(), s);
}

ColonScene::Frame ColonScene::CentrelineFrame(double s) const {
  constexpr double kStep = 0.05;  // mm; the centreline bends over tens of mm
  Frame frame;
  frame.tangent = (Centreline(s + kStep) - Centreline(s - kStep)).normalized();
  frame.normal = (Eigen::Vector3d::UnitX() - frame.tangent.x() * frame.tangent).normalized();
  frame.binormal = frame.tangent.cross(frame.normal);
  return frame;
}

ColonScene::Ring ColonScene::RingAt(double s) const {
  const ColonOptions& colon = options_.colon;
  Ring ring;
  ring.s = s;
  if (colon.straight) {
    ring.radius = colon.radius_mean_mm;
    return ring;
  }
  const double l = colon.radius_wavelength_mm;
  ring.radius = colon.radius_mean_mm + colon.radius_variation_mm * (0.7 * std::sin(kTwoPi * s / l + phases_[4]) +
                                                                    0.3 * std::sin(kTwoPi * s / (0.37 * l) + phases_[5]));
  const double reach = 4.0 * colon.fold_width_mm + kMaxFoldTilt;
  ring.first_fold = std::lower_bound(folds_.begin(), folds_.end(), s - reach,
                                     [](const Fold& fold, double value) { return fold.s < value; }) - folds_.begin();
  ring.end_fold = ring.first_fold;
  while (ring.end_fold < folds_.size() && folds_[ring.end_fold].s <= s + reach) ++ring.end_fold;
  return ring;
}

double ColonScene::RingRadius(const Ring& ring, double theta) const {
  return RingRadius(ring, std::cos(theta), std::sin(theta), std::cos(3 * theta), std::sin(3 * theta));
}

double ColonScene::RingRadius(const Ring& ring, double cos1, double sin1, double cos3, double sin3) const {
  const double width = options_.colon.fold_width_mm;
  double radius = ring.radius;
  for (size_t k = ring.first_fold; k < ring.end_fold; ++k) {
    const Fold& fold = folds_[k];
    // sin(θ + φ) and cos(3θ + φ) by angle addition.
    const double offset = ring.s - (fold.s + fold.tilt * (sin1 * fold.cos_phase + cos1 * fold.sin_phase));
    const double lobing = 0.65 + 0.35 * (cos3 * fold.cos_phase - sin3 * fold.sin_phase);
    radius -= fold.height * lobing * std::exp(-offset * offset / (2.0 * width * width));
  }
  return radius;
}

double ColonScene::Radius(double s, double theta) const { return RingRadius(RingAt(s), theta); }

Eigen::Vector3d ColonScene::RestPosition(int, double s, double theta) const {
  const Frame frame = CentrelineFrame(s);
  return Centreline(s) + Radius(s, theta) * (std::cos(theta) * frame.normal + std::sin(theta) * frame.binormal);
}

Eigen::Vector3d ColonScene::Position(int patch, double s, double theta, double time_s) const {
  return ApplyWaveDeformation(RestPosition(patch, s, theta), options_.deformation, time_s);
}

void ColonScene::RowPositions(int, double s, const std::vector<double>& thetas, double time_s,
                              Eigen::Vector3d* out) const {
  const Frame frame = CentrelineFrame(s);
  const Eigen::Vector3d centre = Centreline(s);
  const Ring ring = RingAt(s);
  const bool standard_grid = thetas.size() == tables_.cos1.size();
  for (size_t j = 0; j < thetas.size(); ++j) {
    const double theta = thetas[j];
    const double cos1 = standard_grid ? tables_.cos1[j] : std::cos(theta);
    const double sin1 = standard_grid ? tables_.sin1[j] : std::sin(theta);
    const double cos3 = standard_grid ? tables_.cos3[j] : std::cos(3 * theta);
    const double sin3 = standard_grid ? tables_.sin3[j] : std::sin(3 * theta);
    const Eigen::Vector3d rest =
        centre + RingRadius(ring, cos1, sin1, cos3, sin3) * (cos1 * frame.normal + sin1 * frame.binormal);
    out[j] = ApplyWaveDeformation(rest, options_.deformation, time_s);
  }
}

Eigen::Vector2d ColonScene::TextureCoords(int, double s, double theta) const {
  return Eigen::Vector2d(s, theta * options_.colon.radius_mean_mm);
}

double ColonScene::CameraArc(double time_s) const {
  return options_.colon.start_mm + options_.colon.speed_mm_per_frame * options_.fps * time_s;
}

SurfaceGrid ColonScene::Grid(int, double time_s) const {
  const ColonOptions& colon = options_.colon;
  const double arc = CameraArc(time_s);
  SurfaceGrid grid;
  grid.periodic_v = true;
  // Rings sit at fixed offsets from the camera, finest at the camera and coarsening ahead
  // (2 % per mm): the mesh keeps its topology from frame to frame, so the ray caster can
  // refit its BVH instead of rebuilding it. The tube exists for s < 0 too; only its texture
  // clamps there.
  for (double offset = -12.0; offset < colon.view_ahead_mm; offset += colon.ring_spacing_mm * (1.0 + 0.02 * std::abs(offset))) {
    grid.u.push_back(arc + offset);
  }
  grid.u.push_back(arc + colon.view_ahead_mm);
  grid.v.resize(colon.angular_steps);
  for (int j = 0; j < colon.angular_steps; ++j) grid.v[j] = kTwoPi * j / colon.angular_steps;
  return grid;
}

Rigid3 ColonScene::WorldFromCamera(double time_s) const {
  const ColonOptions& colon = options_.colon;
  const double arc = CameraArc(time_s);
  const Frame frame = CentrelineFrame(arc);
  const double* w = wobble_phases_;
  const double lateral_a = colon.wobble_lateral_mm * std::sin(kTwoPi * time_s / 3.1 + w[0]);
  const double lateral_b = colon.wobble_lateral_mm * std::sin(kTwoPi * time_s / 4.3 + w[1]);
  // The tip rides with the tissue around it, as an endoscope in a moving colon does;
  // a camera fixed in space would have a 10 mm wave push the wall through the lens.
  const Eigen::Vector3d centre = ApplyWaveDeformation(Centreline(arc), options_.deformation, time_s);
  const Eigen::Vector3d position = centre + lateral_a * frame.normal + lateral_b * frame.binormal;

  Eigen::Matrix3d base;
  base << frame.normal, frame.binormal, frame.tangent;  // camera x, y, z in world
  const double amplitude = colon.wobble_rotation_deg * M_PI / 180.0;
  const Eigen::Quaterniond wobble =
      Eigen::AngleAxisd(amplitude * std::sin(kTwoPi * time_s / 2.7 + w[2]), Eigen::Vector3d::UnitX()) *
      Eigen::AngleAxisd(amplitude * std::sin(kTwoPi * time_s / 3.9 + w[3]), Eigen::Vector3d::UnitY()) *
      Eigen::AngleAxisd(0.5 * amplitude * std::sin(kTwoPi * time_s / 5.3 + w[4]), Eigen::Vector3d::UnitZ());
  return Rigid3(Eigen::Quaterniond(base) * wobble, position);
}

}  // namespace nrslam
