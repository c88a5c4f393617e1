// sim: a laparoscopic view of two liver-like lobes side by side, 50–120 mm from the camera,
// that breathe with different phases and so slide against each other along their seam, in
// front of a static background of other tissue.
//
// Patches: 0 = lobe A (left, nearer), 1 = lobe B (right), 2 = background. Material
// coordinates (u, v) ∈ [-1, 1]² on each.
#pragma once

#include <array>
#include <memory>

#include "nrslam/sim/scene.h"

namespace nrslam {

class LobesScene : public Scene {
 public:
  static constexpr int kLobeA = 0, kLobeB = 1, kBackground = 2;

  explicit LobesScene(const SimOptions& options);

  int patch_count() const override { return 3; }
  SurfaceGrid Grid(int patch, double time_s) const override;
  Eigen::Vector3d RestPosition(int patch, double u, double v) const override;
  Eigen::Vector3d Position(int patch, double u, double v, double time_s) const override;
  Eigen::Vector2d TextureCoords(int patch, double u, double v) const override;
  const MucosaTexture& Texture(int patch) const override { return *textures_[patch]; }
  Rigid3 WorldFromCamera(double time_s) const override;

  // Rigid breathing displacement of a lobe at time t (mm); the background does not move.
  Eigen::Vector3d LobeDisplacement(int patch, double time_s) const;

 private:
  SimOptions options_;
  std::array<std::unique_ptr<MucosaTexture>, 3> textures_;
  double camera_phase_;
  double HalfExtentX(int patch) const;
  double HalfExtentY(int patch) const;
};

}  // namespace nrslam
