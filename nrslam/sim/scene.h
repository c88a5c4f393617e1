// sim: a deformable scene — parametric surface patches, their motion over time, their
// texture, and the camera trajectory through them.
//
// A patch is a surface (u, v) → world position (mm). Each frame the ray caster tessellates
// every patch on the grid the scene asks for, so a scene can mesh finely near the camera and
// coarsely far from it.
#pragma once

#include <Eigen/Core>

#include <memory>
#include <vector>

#include "nrslam/geometry/rigid3.h"
#include "nrslam/sim/mucosa_texture.h"
#include "nrslam/sim/sim_options.h"

namespace nrslam {

struct SurfaceGrid {
  std::vector<double> u;   // tessellation samples along u
  std::vector<double> v;   // along v; with periodic_v the last sample joins the first
  bool periodic_v = false;
};

class Scene {
 public:
  virtual ~Scene() = default;
  virtual int patch_count() const = 0;
  virtual SurfaceGrid Grid(int patch, double time_s) const = 0;
  // Rest (undeformed) surface point of the patch, world mm.
  virtual Eigen::Vector3d RestPosition(int patch, double u, double v) const = 0;
  // Surface point at time t: the rest point moved by the scene's deformation law.
  virtual Eigen::Vector3d Position(int patch, double u, double v, double time_s) const = 0;
  // Position() for a whole row of the grid (fixed u); scenes override it to share the work
  // that depends on u alone.
  virtual void RowPositions(int patch, double u, const std::vector<double>& v, double time_s,
                            Eigen::Vector3d* out) const {
    for (size_t j = 0; j < v.size(); ++j) out[j] = Position(patch, u, v[j], time_s);
  }
  virtual Eigen::Vector2d TextureCoords(int patch, double u, double v) const = 0;  // mm
  virtual const MucosaTexture& Texture(int patch) const = 0;
  virtual Rigid3 WorldFromCamera(double time_s) const = 0;
};

// The paper's wave: V_y(t) = V⁰_y + A·sin(ω t + (V⁰_x + V⁰_y + V⁰_z)/λ).
inline Eigen::Vector3d ApplyWaveDeformation(const Eigen::Vector3d& rest, const DeformationOptions& law, double time_s) {
  Eigen::Vector3d moved = rest;
  moved.y() += law.amplitude_mm * std::sin(law.omega_rad_s * time_s + rest.sum() / law.lambda_mm);
  return moved;
}

// Builds the scene named by options.scene ("colon" or "lobes").
std::unique_ptr<Scene> MakeScene(const SimOptions& options);

}  // namespace nrslam
