// sim: renders frames of a Scene — colour with endoscope lighting and exact z-depth.
//
// Light model (the light sits on the tip, at the lens): irradiance power·cos(i)/r², Lambert
// diffuse on the mucosa albedo plus Phong highlights of the wet surface, vignetting, display
// gamma and sensor noise. The image therefore darkens down the lumen as real ones do.
#pragma once

#include <opencv2/core.hpp>

#include <memory>
#include <optional>
#include <vector>

#include "nrslam/camera/camera.h"
#include "nrslam/io/sequence_info.h"
#include "nrslam/sim/ray_caster.h"
#include "nrslam/sim/scene.h"

namespace nrslam {

struct RenderedView {
  cv::Mat bgr;       // CV_8UC3
  cv::Mat depth_mm;  // CV_32F z-depth along the optical axis, 0 = nothing hit / outside the lens
};

struct RenderedFrame {
  RenderedView left;
  std::optional<RenderedView> right;
  Rigid3 world_from_camera;  // of the left camera
};

// The camera the options describe (pinhole from the horizontal FOV; fisheye with its image
// circle filling the width), or the one in their calibration file (throws Error if unreadable).
Camera MakeSimCamera(const SimCameraOptions& options);

class Renderer {
 public:
  explicit Renderer(const SimOptions& options);

  const Camera& camera() const { return camera_; }
  std::optional<StereoInfo> stereo() const;
  // Pixels inside the lens's image circle (255) — empty for pinhole cameras.
  const cv::Mat& validity_mask() const { return validity_mask_; }
  const Scene& scene() const { return *scene_; }
  const RayCaster& caster() const { return caster_; }
  double TimeOf(int frame_index) const { return frame_index / options_.fps; }

  RenderedFrame Render(int frame_index);

 private:
  SimOptions options_;
  Camera camera_;
  std::unique_ptr<Scene> scene_;
  RayCaster caster_;
  std::vector<Eigen::Vector3d> bearings_;  // per pixel, camera frame
  std::vector<float> vignetting_;          // per pixel gain; 0 outside the image circle
  cv::Mat validity_mask_;
  std::vector<float> display_levels_;      // linear radiance → 8-bit level through the gamma curve
  int threads_;

  double DisplayLevel(double radiance) const;

  RenderedView RenderView(const Rigid3& world_from_camera, int frame_index, int view);
};

}  // namespace nrslam
