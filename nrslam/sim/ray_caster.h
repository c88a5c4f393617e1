// sim: ray casting of a Scene with Embree.
//
// Each frame every patch is tessellated at the frame's time into a triangle mesh, stored
// relative to a local origin (the camera) so Embree's float BVH loses no precision. Embree
// finds which triangle a ray hits; the hit is then recomputed in double precision against
// that triangle, so the depth is exact for the rendered surface.
#pragma once

#include <embree3/rtcore.h>

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

#include "nrslam/sim/scene.h"

namespace nrslam {

struct SurfaceHit {
  bool valid = false;
  int patch = -1;
  double distance = 0.0;           // along the unit ray, mm
  Eigen::Vector3d position;        // world, mm
  Eigen::Vector3d normal;          // world, unit, smooth (interpolated), not oriented
  Eigen::Vector2d material;        // (u, v) of the patch
};

class RayCaster {
 public:
  explicit RayCaster(int threads);
  ~RayCaster();
  RayCaster(const RayCaster&) = delete;
  RayCaster& operator=(const RayCaster&) = delete;

  // Tessellates `scene` at `time_s`; rays will be cast from near `origin` (world, mm).
  // When the tessellation keeps its topology the BVH is refitted, and rebuilt from scratch
  // every kRebuildPeriod builds so its quality cannot drift.
  static constexpr int kRebuildPeriod = 30;
  void Build(const Scene& scene, double time_s, const Eigen::Vector3d& origin);
  // Thread-safe once built.
  SurfaceHit Cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& unit_direction) const;
  // Eight rays from one origin at once (Embree ray packets: neighbouring pixels share most
  // of their traversal). Lanes with active[i] == false are skipped and left invalid.
  static constexpr int kPacket = 8;
  void Cast8(const Eigen::Vector3d& origin, const Eigen::Vector3d* unit_directions, const bool* active,
             SurfaceHit* hits) const;
  size_t triangle_count() const;

 private:
  struct PatchMesh {
    std::vector<Eigen::Vector3d> vertices;  // relative to origin_
    std::vector<Eigen::Vector3f> normals;
    std::vector<Eigen::Vector2d> material;
    std::vector<std::array<uint32_t, 3>> triangles;
    double period_v = 0.0;                  // material v wraps with this period (0 = none)
  };
  RTCDevice device_ = nullptr;
  RTCScene rtc_scene_ = nullptr;
  std::vector<RTCGeometry> geometries_;  // one per patch, owned by rtc_scene_
  int builds_since_rebuild_ = 0;
  std::vector<PatchMesh> meshes_;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  int threads_;

  void Tessellate(const Scene& scene, int patch, double time_s, PatchMesh* mesh) const;
  // The exact hit of a ray on a triangle Embree reported.
  SurfaceHit Refine(unsigned patch, unsigned triangle_index, const Eigen::Vector3d& origin,
                    const Eigen::Vector3d& unit_direction) const;
};

}  // namespace nrslam
