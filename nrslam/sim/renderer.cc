#include "nrslam/sim/renderer.h"

#include <omp.h>

#include <algorithm>
#include <cmath>

#include "nrslam/io/camera_file.h"
#include "nrslam/util/error.h"
#include "nrslam/util/random.h"

namespace nrslam {
namespace {
// The gamma curve, tabulated: three pow() per pixel were a third of the shading time.
constexpr int kDisplayTableSize = 4096;
}  // namespace

Camera MakeSimCamera(const SimCameraOptions& options) {
  if (!options.calibration.empty()) return ReadCameraFile(options.calibration);
  const double cx = 0.5 * (options.width - 1), cy = 0.5 * (options.height - 1);
  if (options.model == "pinhole") {
    const double f = 0.5 * options.width / std::tan(0.5 * options.fov_deg * M_PI / 180.0);
    return Camera::Pinhole(options.width, options.height, f, f, cx, cy);
  }
  // The image circle (the edge of the FOV) touches the left and right borders: the whole
  // field of view spans the width and the corners are cut, like a colonoscope's image.
  const Eigen::Vector4d k(options.fisheye_k0, options.fisheye_k1, 0.0, 0.0);
  const double theta_max = 0.5 * options.fisheye_fov_deg * M_PI / 180.0;
  const double unit_params[8] = {1, 1, 0, 0, k[0], k[1], k[2], k[3]};
  const double circle_radius = 0.5 * (options.width - 1);
  const double f = circle_radius / KannalaBrandtModel::Distort(unit_params, theta_max);
  return Camera::KannalaBrandt(options.width, options.height, f, f, cx, cy, k);
}

Renderer::Renderer(const SimOptions& options)
    : options_(options),
      camera_(MakeSimCamera(options.camera)),
      scene_(MakeScene(options)),
      caster_(options.threads),
      threads_(options.threads > 0 ? options.threads : omp_get_max_threads()) {
  camera_.Check();
  const int width = camera_.width(), height = camera_.height();
  const bool fisheye = camera_.model() != CameraModelId::kPinhole;
  if (options.camera.stereo && fisheye) {
    throw Error("sim camera: stereo needs a pinhole camera (a rectified pair); the calibration is " +
                camera_.model_name());
  }
  // The simulator's own fisheye ends at its image circle; a calibration wherever its model does.
  const double fov_limit = !fisheye                             ? M_PI / 2
                           : options.camera.calibration.empty() ? 0.5 * options.camera.fisheye_fov_deg * M_PI / 180.0
                                                                : camera_.max_theta();
  bearings_.resize(static_cast<size_t>(width) * height);
  vignetting_.resize(bearings_.size());
  double widest = 0.0;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const Eigen::Vector3d bearing = camera_.Unproject(Eigen::Vector2d(x, y));
      bearings_[static_cast<size_t>(y) * width + x] = bearing;
      const double theta = std::acos(std::clamp(bearing.z(), -1.0, 1.0));
      if (theta <= fov_limit) widest = std::max(widest, theta);
    }
  }
  display_levels_.resize(kDisplayTableSize);
  for (int i = 0; i < kDisplayTableSize; ++i) {
    display_levels_[i] = static_cast<float>(255.0 * std::pow(i / (kDisplayTableSize - 1.0), 1.0 / options.appearance.gamma));
  }
  if (fisheye) validity_mask_ = cv::Mat::zeros(height, width, CV_8UC1);
  for (size_t k = 0; k < bearings_.size(); ++k) {
    const double theta = std::acos(std::clamp(bearings_[k].z(), -1.0, 1.0));
    const bool inside = theta <= fov_limit;
    const double relative = theta / widest;
    vignetting_[k] = inside ? static_cast<float>(1.0 - options.appearance.vignetting * relative * relative) : 0.f;
    if (fisheye && inside) validity_mask_.at<uint8_t>(static_cast<int>(k / width), static_cast<int>(k % width)) = 255;
  }
}

double Renderer::DisplayLevel(double radiance) const {
  const double position = std::clamp(radiance, 0.0, 1.0) * (kDisplayTableSize - 1);
  const int index = std::min(static_cast<int>(position), kDisplayTableSize - 2);
  const double fraction = position - index;
  return display_levels_[index] + fraction * (display_levels_[index + 1] - display_levels_[index]);
}

std::optional<StereoInfo> Renderer::stereo() const {
  if (!options_.camera.stereo) return std::nullopt;
  return StereoInfo{options_.camera.baseline_mm, camera_};
}

RenderedFrame Renderer::Render(int frame_index) {
  const double time = TimeOf(frame_index);
  RenderedFrame frame;
  frame.world_from_camera = scene_->WorldFromCamera(time);
  caster_.Build(*scene_, time, frame.world_from_camera.translation);
  frame.left = RenderView(frame.world_from_camera, frame_index, 0);
  if (options_.camera.stereo) {
    const Rigid3 right_from_left(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-options_.camera.baseline_mm, 0, 0));
    frame.right = RenderView(frame.world_from_camera * right_from_left.Inverse(), frame_index, 1);
  }
  return frame;
}

RenderedView Renderer::RenderView(const Rigid3& world_from_camera, int frame_index, int view) {
  const int width = camera_.width(), height = camera_.height();
  const AppearanceOptions& look = options_.appearance;
  const Eigen::Matrix3d rotation = world_from_camera.rotation.toRotationMatrix();
  const Eigen::Vector3d centre = world_from_camera.translation;
  const double inverse_focal = 1.0 / camera_.MeanFocal();
  const uint64_t noise_seed = HashCoordinates(options_.seed, static_cast<uint64_t>(frame_index), static_cast<uint64_t>(view));
  RenderedView out{cv::Mat::zeros(height, width, CV_8UC3), cv::Mat::zeros(height, width, CV_32F)};

  constexpr int kPacket = RayCaster::kPacket;
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads_)
  for (int y = 0; y < height; ++y) {
    cv::Vec3b* colour_row = out.bgr.ptr<cv::Vec3b>(y);
    float* depth_row = out.depth_mm.ptr<float>(y);
    for (int x0 = 0; x0 < width; x0 += kPacket) {
      Eigen::Vector3d directions[kPacket];
      bool active[kPacket];
      SurfaceHit hits[kPacket];
      for (int i = 0; i < kPacket; ++i) {
        const size_t k = static_cast<size_t>(y) * width + x0 + i;
        active[i] = x0 + i < width && vignetting_[k] > 0.f;  // outside the lens's image circle: black
        directions[i] = active[i] ? (rotation * bearings_[k]).eval() : Eigen::Vector3d::UnitZ();
      }
      caster_.Cast8(centre, directions, active, hits);
      for (int i = 0; i < kPacket && x0 + i < width; ++i) {
        if (!active[i]) continue;
        const int x = x0 + i;
        const size_t k = static_cast<size_t>(y) * width + x;
        const SurfaceHit& hit = hits[i];
        Eigen::Vector3d radiance = Eigen::Vector3d::Zero();
        if (hit.valid && hit.distance > 0) {
          // A ray 90° or more off the axis (a calibrated fisheye) has no z-depth: 0, none.
          depth_row[x] = static_cast<float>(std::max(0.0, hit.distance * bearings_[k].z()));
          const double cos_incidence = std::abs(hit.normal.dot(directions[i]));
          const double irradiance = look.light_power / (hit.distance * hit.distance);
          const double footprint = hit.distance * inverse_focal / std::max(cos_incidence, 0.3);
          const Eigen::Vector2d uv = scene_->TextureCoords(hit.patch, hit.material.x(), hit.material.y());
          const Eigen::Vector3d albedo = scene_->Texture(hit.patch).Sample(uv.x(), uv.y(), footprint).cast<double>();
          const double highlight = look.specular_strength * std::pow(cos_incidence, look.shininess);
          radiance = irradiance * vignetting_[k] * (cos_incidence * albedo + Eigen::Vector3d::Constant(highlight));
        }
        const double levels[3] = {DisplayLevel(radiance[0]), DisplayLevel(radiance[1]), DisplayLevel(radiance[2])};
        // Shot noise grows with the signal; one sigma per pixel from its mean level.
        const double sigma = look.noise_sigma * std::sqrt(0.3 + (levels[0] + levels[1] + levels[2]) / (3 * 255.0));
        for (int c = 0; c < 3; ++c) {
          const double noisy =
              levels[c] + sigma * FastNormalFromHash(HashCoordinates(noise_seed, k, static_cast<uint64_t>(c)));
          colour_row[x][2 - c] = cv::saturate_cast<uint8_t>(noisy);  // radiance is RGB, OpenCV stores BGR
        }
      }
    }
  }
  return out;
}

}  // namespace nrslam
