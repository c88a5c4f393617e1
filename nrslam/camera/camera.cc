#include "nrslam/camera/camera.h"

#include <ceres/jet.h>

#include <cmath>
#include <sstream>

#include "nrslam/util/error.h"

namespace nrslam {

Camera Camera::Pinhole(int width, int height, double fx, double fy, double cx, double cy) {
  Camera camera;
  camera.model_ = CameraModelId::kPinhole;
  camera.width_ = width;
  camera.height_ = height;
  camera.params_ = {fx, fy, cx, cy};
  camera.ComputeMaxTheta();
  return camera;
}

Camera Camera::KannalaBrandt(int width, int height, double fx, double fy, double cx, double cy,
                             const Eigen::Vector4d& k) {
  Camera camera;
  camera.model_ = CameraModelId::kKannalaBrandt;
  camera.width_ = width;
  camera.height_ = height;
  camera.params_ = {fx, fy, cx, cy, k[0], k[1], k[2], k[3]};
  camera.ComputeMaxTheta();
  return camera;
}

std::string Camera::model_name() const {
  return VisitCameraModel(model_, [](auto model) { return std::string(decltype(model)::kName); });
}

void Camera::ComputeMaxTheta() {
  if (model_ == CameraModelId::kPinhole || params_.size() != KannalaBrandtModel::kNumParams) {
    max_theta_ = M_PI / 2;
    return;
  }
  // Walk r(θ) until it stops increasing: beyond that two angles share a pixel.
  constexpr double kStep = 1e-3;
  double previous = 0.0;
  max_theta_ = M_PI;
  for (double theta = kStep; theta <= M_PI; theta += kStep) {
    const double r = KannalaBrandtModel::Distort(params_.data(), theta);
    if (r <= previous) {
      max_theta_ = theta - kStep;
      return;
    }
    previous = r;
  }
}

std::optional<Eigen::Vector2d> Camera::Project(const Eigen::Vector3d& point) const {
  if (std::atan2(point.head<2>().norm(), point.z()) > max_theta_) return std::nullopt;
  Eigen::Vector2d pixel;
  const bool ok = VisitCameraModel(
      model_, [&](auto model) { return decltype(model)::Project(params_.data(), point.data(), pixel.data()); });
  if (!ok) return std::nullopt;
  return pixel;
}

Eigen::Vector3d Camera::Unproject(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector3d bearing = VisitCameraModel(
      model_, [&](auto model) { return decltype(model)::Unproject(params_.data(), pixel.x(), pixel.y()); });
  if (model_ == CameraModelId::kPinhole) return bearing;
  // Pixels beyond the image circle (past the largest r(θ) the lens reaches) have no ray;
  // give them the ray at the edge of the field of view in their direction.
  const double mx = (pixel.x() - cx()) / fx(), my = (pixel.y() - cy()) / fy();
  const double radius = std::hypot(mx, my);
  if (radius <= KannalaBrandtModel::Distort(params_.data(), max_theta_)) return bearing;
  return Eigen::Vector3d(std::sin(max_theta_) * mx / radius, std::sin(max_theta_) * my / radius, std::cos(max_theta_));
}

Eigen::Matrix<double, 2, 3> Camera::ProjectionJacobian(const Eigen::Vector3d& point) const {
  using Jet = ceres::Jet<double, 3>;
  const Jet point_jet[3] = {Jet(point.x(), 0), Jet(point.y(), 1), Jet(point.z(), 2)};
  std::vector<Jet> params_jet(params_.begin(), params_.end());
  Jet pixel_jet[2];
  VisitCameraModel(model_, [&](auto model) {
    return decltype(model)::Project(params_jet.data(), point_jet, pixel_jet);
  });
  Eigen::Matrix<double, 2, 3> jacobian;
  jacobian.row(0) = pixel_jet[0].v.transpose();
  jacobian.row(1) = pixel_jet[1].v.transpose();
  return jacobian;
}

void Camera::Check() const {
  auto fail = [](const std::string& what) { throw Error("camera: " + what); };
  std::ostringstream text;
  if (width_ <= 0 || height_ <= 0) {
    text << "image size must be positive, got " << width_ << "x" << height_;
    fail(text.str());
  }
  const size_t expected = model_ == CameraModelId::kPinhole ? 4 : 8;
  if (params_.size() != expected) {
    text << model_name() << " needs " << expected << " parameters, got " << params_.size();
    fail(text.str());
  }
  for (double p : params_) {
    if (!std::isfinite(p)) fail("parameters must be finite numbers");
  }
  if (fx() <= 0 || fy() <= 0) {
    text << "negative or zero focal length: fx=" << fx() << ", fy=" << fy()
         << " (must be > 0 px)";
    fail(text.str());
  }
  if (cx() < 0 || cx() > width_ - 1 || cy() < 0 || cy() > height_ - 1) {
    text << "principal point (" << cx() << ", " << cy() << ") lies outside the " << width_ << "x"
         << height_ << " image";
    fail(text.str());
  }
  if (model_ == CameraModelId::kKannalaBrandt && max_theta_ < 0.35) {
    text << "Kannala-Brandt coefficients make r(theta) fold back at " << max_theta_
         << " rad; the calibration is wrong";
    fail(text.str());
  }
}

void to_json(nlohmann::json& j, const Camera& camera) {
  j = nlohmann::json{{"model", camera.model_name()}, {"width", camera.width()}, {"height", camera.height()},
                     {"fx", camera.fx()}, {"fy", camera.fy()}, {"cx", camera.cx()}, {"cy", camera.cy()}};
  if (camera.model() == CameraModelId::kKannalaBrandt) {
    const auto& p = camera.params();
    j["k"] = {p[4], p[5], p[6], p[7]};
  }
}

void from_json(const nlohmann::json& j, Camera& camera) {
  if (!j.is_object()) throw Error("camera: expected a JSON object");
  for (const char* key : {"model", "width", "height", "fx", "fy", "cx", "cy"}) {
    if (!j.contains(key)) throw Error(std::string("camera: missing field '") + key + "'");
  }
  try {
    const std::string model = j.at("model").get<std::string>();
    const int width = j.at("width").get<int>();
    const int height = j.at("height").get<int>();
    const double fx = j.at("fx").get<double>(), fy = j.at("fy").get<double>();
    const double cx = j.at("cx").get<double>(), cy = j.at("cy").get<double>();
    if (model == PinholeModel::kName) {
      camera = Camera::Pinhole(width, height, fx, fy, cx, cy);
    } else if (model == KannalaBrandtModel::kName) {
      if (!j.contains("k") || !j.at("k").is_array() || j.at("k").size() != 4) {
        throw Error("camera: kannala_brandt needs 'k' with 4 coefficients");
      }
      const auto k = j.at("k").get<std::vector<double>>();
      camera = Camera::KannalaBrandt(width, height, fx, fy, cx, cy, Eigen::Vector4d(k[0], k[1], k[2], k[3]));
    } else {
      throw Error("camera: unknown camera model '" + model + "' (known: pinhole, kannala_brandt)");
    }
  } catch (const nlohmann::json::exception& e) {
    throw Error(std::string("camera: malformed field: ") + e.what());
  }
  camera.Check();
}

}  // namespace nrslam
