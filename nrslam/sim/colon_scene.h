// sim: a colon — a tube around a smooth curved centreline, with a slowly varying radius and
// haustral folds (inward ridges, partly tilted and lobed, that hide what lies behind them),
// deformed by the wave law, seen by a camera advancing along the centreline.
//
// Material coordinates: u = s, the centreline parameter (mm, equal to world z at rest),
// v = θ, the angle around the lumen (rad).
#pragma once

#include <memory>
#include <vector>

#include "nrslam/sim/scene.h"

namespace nrslam {

class ColonScene : public Scene {
 public:
  explicit ColonScene(const SimOptions& options);

  int patch_count() const override { return 1; }
  SurfaceGrid Grid(int patch, double time_s) const override;
  Eigen::Vector3d RestPosition(int patch, double s, double theta) const override;
  Eigen::Vector3d Position(int patch, double s, double theta, double time_s) const override;
  void RowPositions(int patch, double s, const std::vector<double>& thetas, double time_s,
                    Eigen::Vector3d* out) const override;
  Eigen::Vector2d TextureCoords(int patch, double s, double theta) const override;
  const MucosaTexture& Texture(int) const override { return *texture_; }
  Rigid3 WorldFromCamera(double time_s) const override;

  double length_mm() const { return length_mm_; }
  // Lumen radius at (s, θ) at rest, folds included, mm.
  double Radius(double s, double theta) const;
  Eigen::Vector3d Centreline(double s) const;

 private:
  struct Fold {
    double s;       // centre along the centreline, mm
    double height;  // mm
    double tilt;    // the ridge wanders ±tilt mm along s around the lumen
    double phase;   // of the lobing and the tilt, rad
    double cos_phase, sin_phase;
  };
  // sin/cos of θ and 3θ on the standard angular grid (Grid()'s v), so tessellation does no
  // trigonometry per vertex but the wave's.
  struct AngularTables {
    std::vector<double> cos1, sin1, cos3, sin3;
  };
  // What a ring of the tube at s shares: its base radius and the folds that reach it.
  struct Ring {
    double s = 0.0;
    double radius = 0.0;
    size_t first_fold = 0, end_fold = 0;
  };
  struct Frame {
    Eigen::Vector3d tangent, normal, binormal;
  };

  SimOptions options_;
  double length_mm_;
  double phases_[8];
  std::vector<Fold> folds_;  // sorted by s
  double wobble_phases_[5];
  std::unique_ptr<MucosaTexture> texture_;

  Frame CentrelineFrame(double s) const;
  Ring RingAt(double s) const;
  double RingRadius(const Ring& ring, double theta) const;
  double RingRadius(const Ring& ring, double cos1, double sin1, double cos3, double sin3) const;
  AngularTables tables_;
  double CameraArc(double time_s) const;
};

}  // namespace nrslam
