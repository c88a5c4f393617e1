#include "nrslam/camera/camera.h"

#include <ceres/jet.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iterator>
#include <limits>
#include <map>
#include <set>
#include <utility>
#include <sstream>

#include "nrslam/util/error.h"
#include "nrslam/util/json_options.h"
#include "nrslam/util/text_table.h"

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

Camera Camera::OpenCv(int width, int height, double fx, double fy, double cx, double cy,
                      const std::vector<double>& distortion) {
  const size_t count = distortion.size();
  if (count != 4 && count != 5 && count != 8) {
    std::ostringstream text;
    text << "camera: opencv needs 4, 5 or 8 distortion coefficients (OpenCV's order: k1 k2 p1 p2 [k3 [k4 k5 k6]]), got "
         << count;
    if (count == 12 || count == 14) text << " (the thin-prism and tilted models are not supported)";
    throw Error(text.str());
  }
  Camera camera;
  camera.model_ = CameraModelId::kOpenCv;
  camera.width_ = width;
  camera.height_ = height;
  camera.params_ = {fx, fy, cx, cy};
  camera.params_.insert(camera.params_.end(), distortion.begin(), distortion.end());
  camera.params_.resize(OpenCvModel::kNumParams, 0.0);
  camera.ComputeMaxTheta();
  return camera;
}

namespace {

// A polynomial's coefficients from params, without the unused trailing zeros.
std::vector<double> Coefficients(const std::vector<double>& params, int offset, int count) {
  auto end = params.begin() + offset + count;
  while (end > params.begin() + offset + 1 && *(end - 1) == 0.0) --end;
  return std::vector<double>(params.begin() + offset, end);
}

// The first angle (rad, in steps of 1e-3 up to `end`) past which radius(θ) stops growing: beyond
// it two angles would share a pixel.
template <typename Radius>
double MonotonicLimit(Radius radius, double end) {
  constexpr double kStep = 1e-3;
  double previous = 0.0;
  for (double theta = kStep; theta < end; theta += kStep) {
    const double r = radius(theta);
    if (!(r > previous)) return theta - kStep;
    previous = r;
  }
  return end;
}

// What OCamCalib's findinvpoly does for a calibration that gives only ss: the inverse
// polynomial least-squares fitted to the direct one's rays out to the image's farthest corner,
// its degree raised until it is within kFitPx everywhere there (or as close as kMaxInverse
// terms get; Check() then judges the result). `params` holds the affine part and ss.
std::vector<double> FitInversePolynomial(const std::vector<double>& params, int width, int height) {
  constexpr double kFitPx = 0.01;
  constexpr int kSamples = 1000;
  double farthest = 0.0;
  for (const auto& [u, v] : {std::pair(0.0, 0.0), std::pair(width - 1.0, 0.0), std::pair(0.0, height - 1.0),
                             std::pair(width - 1.0, height - 1.0)}) {
    farthest = std::max(farthest, OcamModel::Unaffine(params.data(), u, v).norm());
  }
  // Samples of (s, ρ), s = t / (π/2) ∈ [-1, ...) keeping the powers of the basis near 1.
  std::vector<double> scaled_angle, radius;
  for (int i = 0; i <= kSamples; ++i) {
    const double rho = farthest * i / kSamples;
    scaled_angle.push_back((std::atan2(rho, -OcamModel::Direct(params.data(), rho)) - M_PI / 2) / (M_PI / 2));
    radius.push_back(rho);
  }
  const Eigen::Map<const Eigen::VectorXd> target(radius.data(), static_cast<Eigen::Index>(radius.size()));
  std::vector<double> best;
  double best_error = std::numeric_limits<double>::infinity();
  for (int terms = 3; terms <= OcamModel::kMaxInverse; ++terms) {
    Eigen::MatrixXd basis(static_cast<Eigen::Index>(radius.size()), terms);
    for (Eigen::Index row = 0; row < basis.rows(); ++row) {
      for (int k = 0; k < terms; ++k) basis(row, k) = std::pow(scaled_angle[row], k);
    }
    const Eigen::VectorXd scaled = basis.colPivHouseholderQr().solve(target);
    const double error = (basis * scaled - target).cwiseAbs().maxCoeff();
    if (!(error < best_error)) continue;
    best_error = error;
    best.resize(terms);
    for (int k = 0; k < terms; ++k) best[k] = scaled[k] / std::pow(M_PI / 2, k);
    if (error < kFitPx) break;
  }
  return best;
}

}  // namespace

Camera Camera::Ocam(int width, int height, double cx, double cy, double c, double d, double e,
                    const std::vector<double>& direct, const std::vector<double>& inverse) {
  Camera camera;
  camera.model_ = CameraModelId::kOcam;
  camera.width_ = width;
  camera.height_ = height;
  if (direct.empty() || direct.size() > OcamModel::kMaxDirect || inverse.size() == 1 ||
      inverse.size() > OcamModel::kMaxInverse) {
    std::ostringstream text;
    text << "camera: ocam needs 1 to " << OcamModel::kMaxDirect << " direct (ss) and 2 to " << OcamModel::kMaxInverse
         << " inverse (invpol) coefficients (or none, to fit them), got " << direct.size() << " and " << inverse.size();
    throw Error(text.str());
  }
  camera.params_.assign(OcamModel::kNumParams, 0.0);
  std::copy(direct.begin(), direct.end(), camera.params_.begin() + OcamModel::kDirectOffset);
  const double affine[] = {cx, cy, c, d, e};
  std::copy(std::begin(affine), std::end(affine), camera.params_.begin() + 2);
  const std::vector<double> fitted = inverse.empty() ? FitInversePolynomial(camera.params_, width, height) : inverse;
  std::copy(fitted.begin(), fitted.end(), camera.params_.begin() + OcamModel::kInverseOffset);
  // fx, fy in the other models' places: ρ'(0) along the columns and the rows.
  camera.params_[0] = OcamModel::InverseDerivative(camera.params_.data(), -M_PI / 2);
  camera.params_[1] = camera.params_[0] * c;
  camera.ComputeMaxTheta();
  return camera;
}

Camera Camera::Resized(int width, int height) const {
  if (width <= 0 || height <= 0) {
    throw Error("camera: cannot resize to " + std::to_string(width) + "x" + std::to_string(height));
  }
  const double sx = static_cast<double>(width) / width_, sy = static_cast<double>(height) / height_;
  const double cx_resized = (cx() + 0.5) * sx - 0.5, cy_resized = (cy() + 0.5) * sy - 0.5;
  if (model_ == CameraModelId::kOcam) {
    // Scaling OCamCalib's (a, b) plane by sx keeps each pixel's ray if ss and invpol scale with
    // it (ss_i·sx^(1−i), invpol_i·sx); the affine part takes the rows' extra sy / sx.
    const std::vector<double>& p = params_;
    std::vector<double> direct = Coefficients(p, OcamModel::kDirectOffset, OcamModel::kMaxDirect);
    std::vector<double> inverse = Coefficients(p, OcamModel::kInverseOffset, OcamModel::kMaxInverse);
    for (size_t i = 0; i < direct.size(); ++i) direct[i] *= std::pow(sx, 1.0 - static_cast<double>(i));
    for (double& coefficient : inverse) coefficient *= sx;
    return Ocam(width, height, cx_resized, cy_resized, p[4] * sy / sx, p[5] * sy / sx, p[6], direct, inverse);
  }
  Camera camera = *this;
  camera.width_ = width;
  camera.height_ = height;
  camera.params_[0] *= sx;
  camera.params_[1] *= sy;
  camera.params_[2] = cx_resized;
  camera.params_[3] = cy_resized;
  camera.ComputeMaxTheta();
  return camera;
}

std::string CameraModelName(CameraModelId model) {
  return VisitCameraModel(model, [](auto visited) { return std::string(decltype(visited)::kName); });
}

std::string Camera::model_name() const { return CameraModelName(model_); }

void Camera::ComputeMaxTheta() {
  if (model_ == CameraModelId::kOcam) {
    // Beyond the image the polynomials extrapolate; the border's widest ray bounds what is seen.
    max_theta_ = 0.0;
    const auto widen = [&](double u, double v) {
      const Eigen::Vector3d ray = OcamModel::Unproject(params_.data(), u, v);
      max_theta_ = std::max(max_theta_, std::atan2(ray.head<2>().norm(), ray.z()));
    };
    for (int x = 0; x < width_; ++x) {
      widen(x, 0);
      widen(x, height_ - 1);
    }
    for (int y = 0; y < height_; ++y) {
      widen(0, y);
      widen(width_ - 1, y);
    }
    if (!std::isfinite(max_theta_)) max_theta_ = 0.0;
    return;
  }
  if (model_ == CameraModelId::kPinhole || params_.size() != VisitCameraModel(model_, [](auto model) {
        return size_t{decltype(model)::kNumParams};
      })) {
    max_theta_ = M_PI / 2;
    return;
  }
  if (model_ == CameraModelId::kOpenCv) {
    max_theta_ = MonotonicLimit(
        [&](double theta) { return OpenCvModel::RadialDistort(params_.data(), std::tan(theta)); }, M_PI / 2);
    return;
  }
  max_theta_ =
      MonotonicLimit([&](double theta) { return KannalaBrandtModel::Distort(params_.data(), theta); }, M_PI);
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
  // Pinhole rays cover the plane; OCam's max_theta() is the image border's widest ray.
  if (model_ == CameraModelId::kPinhole || model_ == CameraModelId::kOcam) return bearing;
  // Pixels beyond the largest distorted radius the lens reaches have no ray; give them the ray at
  // the edge of the field of view in their direction.
  const double mx = (pixel.x() - cx()) / fx(), my = (pixel.y() - cy()) / fy();
  const double radius = std::hypot(mx, my);
  if (model_ == CameraModelId::kKannalaBrandt) {
    if (radius <= KannalaBrandtModel::Distort(params_.data(), max_theta_)) return KannalaBrandtRay(mx, my, bearing);
  } else {
    // The tangential terms move the reach off a circle: trust Newton's ray if it lands on the pixel.
    const std::optional<Eigen::Vector2d> back = Project(bearing);
    if (back && (*back - pixel).norm() < 1e-6) return bearing;
  }
  return Eigen::Vector3d(std::sin(max_theta_) * mx / radius, std::sin(max_theta_) * my / radius, std::cos(max_theta_));
}

Eigen::Vector3d Camera::KannalaBrandtRay(double mx, double my, const Eigen::Vector3d& newton_ray) const {
  // Strong coefficients can send Newton past the fold of r(θ); r grows on [0, max_theta], so
  // bisect there instead.
  const double radius = std::hypot(mx, my);
  const auto misfit = [&](double theta) { return KannalaBrandtModel::Distort(params_.data(), theta) - radius; };
  const double newton_theta = std::atan2(newton_ray.head<2>().norm(), newton_ray.z());
  if (newton_theta <= max_theta_ && std::abs(misfit(newton_theta)) <= 1e-9 * std::max(1.0, radius)) return newton_ray;
  double low = 0.0, high = max_theta_;
  for (int halving = 0; halving < 60; ++halving) {
    const double middle = 0.5 * (low + high);
    (misfit(middle) < 0 ? low : high) = middle;
  }
  const double theta = 0.5 * (low + high);
  return Eigen::Vector3d(std::sin(theta) * mx / radius, std::sin(theta) * my / radius, std::cos(theta));
}

Eigen::Matrix<double, 2, 3> Camera::ProjectionJacobian(const Eigen::Vector3d& point) const {
  using Jet = ceres::Jet<double, 3>;
  const Jet point_jet[3] = {Jet(point.x(), 0), Jet(point.y(), 1), Jet(point.z(), 2)};
  Jet pixel_jet[2];
  VisitCameraModel(model_, [&](auto model) { return decltype(model)::Project(params_.data(), point_jet, pixel_jet); });
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
  const size_t expected = VisitCameraModel(model_, [](auto model) { return size_t{decltype(model)::kNumParams}; });
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
  // Beyond these, the intrinsics are almost surely of another image size or unit (an endoscope
  // sees 60-170 degrees; 50 image widths is a view of about 1 degree) or a mistyped number.
  // Interlaced fields have fy about half of fx. OCam's parameters are not focal lengths.
  constexpr double kMaxFocalInImageSizes = 50, kMaxPixelAspect = 4;
  const bool focal_lengths = model_ != CameraModelId::kOcam;
  if (focal_lengths && (fx() > kMaxFocalInImageSizes * width_ || fy() > kMaxFocalInImageSizes * height_)) {
    text << "focal length fx=" << fx() << ", fy=" << fy() << " px is over " << kMaxFocalInImageSizes
         << " times the " << width_ << "x" << height_ << " image (a view of about a degree): intrinsics of another "
         << "image size or unit?";
    fail(text.str());
  }
  // The other way: at a twentieth of the image's width, even an equidistant lens that sees all
  // around (f = width / 2π) would put the image's sides beyond its view. Focal lengths this small
  // are normalised by the image size, or in mm.
  constexpr double kMinFocalInImageSizes = 1.0 / 20;
  if (focal_lengths && (fx() < kMinFocalInImageSizes * width_ || fy() < kMinFocalInImageSizes * height_)) {
    text << "focal length fx=" << fx() << ", fy=" << fy() << " px is under 1/20 of the " << width_ << "x"
         << height_ << " image, a wider view than any lens gives: intrinsics normalised by the image size, or in "
         << "mm rather than px?";
    fail(text.str());
  }
  if (focal_lengths && std::max(fx() / fy(), fy() / fx()) > kMaxPixelAspect) {
    text << "fx=" << fx() << " and fy=" << fy() << " differ by more than " << kMaxPixelAspect << " times";
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
  if (model_ == CameraModelId::kOcam) CheckOcam();
  if (model_ == CameraModelId::kOpenCv) CheckOpenCv();
  CheckFieldOfView();
}

void Camera::CheckFieldOfView() const {
  // The focal-length bound above, for what the distortion does: lens coefficients that squeeze
  // the whole image into a sliver of a degree are wrong, or belong to another unit.
  constexpr double kMinViewDeg = 1.0;
  const auto angle = [&](double u0, double v0, double u1, double v1) {
    const Eigen::Vector3d a = Unproject({u0, v0}), b = Unproject({u1, v1});
    return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI;
  };
  const double across = angle(0, cy(), width_ - 1, cy()), down = angle(cx(), 0, cx(), height_ - 1);
  if (!(std::min(across, down) >= kMinViewDeg)) {
    std::ostringstream text;
    text << std::setprecision(3) << "camera: " << model_name() << ": the image spans " << across << " x " << down
         << " degrees of view (under " << kMinViewDeg
         << "): lens coefficients that are wrong, or of another unit or image size?";
    throw Error(text.str());
  }
}

void Camera::CheckOpenCv() const {
  // Every pixel of the image must have its own ray: the distortion must not fold back inside it.
  constexpr int kGrid = 8;
  const auto check = [&](int x, int y) {
    const Eigen::Vector2d pixel(x, y);
    const Eigen::Vector3d ray = Unproject(pixel);
    const std::optional<Eigen::Vector2d> back = Project(ray);
    if (!back || (*back - pixel).norm() > 1e-3 || std::acos(std::min(1.0, ray.z())) >= max_theta_ - 1e-9) {
      std::ostringstream text;
      text << "camera: opencv: the distortion folds back inside the image near pixel (" << x << ", " << y
           << "), so pixels there have no ray (coefficients in OpenCV's order k1 k2 p1 p2 k3 k4 k5 k6? for this "
              "image size?)";
      throw Error(text.str());
    }
  };
  for (int y = 0; y < height_; y += kGrid) {
    for (int x = 0; x < width_; x += kGrid) check(x, y);
    check(width_ - 1, y);
  }
  for (int x = 0; x < width_; x += kGrid) check(x, height_ - 1);
  check(width_ - 1, height_ - 1);
}

void Camera::CheckOcam() const {
  auto fail = [](const std::string& what) { throw Error("camera: ocam: " + what); };
  std::ostringstream text;
  const double* p = params_.data();
  if (p[OcamModel::kDirectOffset] >= 0) {
    fail("the direct polynomial's constant term (ss[0]) must be negative: OCamCalib's z points out of the lens");
  }
  if (std::abs(p[4] - p[5] * p[6]) < 0.5) fail("the affine part [c d; e 1] is (nearly) singular");
  const double on_axis = OcamModel::Inverse(p, -M_PI / 2);
  if (std::abs(on_axis) > 0.5) {
    text << "the inverse polynomial puts the optical axis " << on_axis << " px from the centre (at most 0.5)";
    fail(text.str());
  }
  // The radius must grow with the angle up to the widest ray of the image, or pixels would share a ray.
  constexpr double kStep = 1e-3;
  for (double phi = kStep; phi <= max_theta_; phi += kStep) {
    if (OcamModel::Radius(p, phi) <= OcamModel::Radius(p, phi - kStep)) {
      text << "the inverse polynomial folds back at " << phi << " rad, inside the image";
      fail(text.str());
    }
  }
  // Both polynomials come from one calibration: the direct polynomial's ray of a pixel, projected
  // with the inverse one, must land on that pixel.
  constexpr int kGrid = 8;
  constexpr double kMaxDisagreementPx = 0.5;
  for (int y = 0; y < height_; y += kGrid) {
    for (int x = 0; x < width_; x += kGrid) {
      Eigen::Vector2d pixel;
      const Eigen::Vector3d ray = OcamModel::DirectRay(p, x, y);
      if (!OcamModel::Project(p, ray.data(), pixel.data()) || (pixel - Eigen::Vector2d(x, y)).norm() > kMaxDisagreementPx) {
        text << "the direct (ss) and inverse (invpol) polynomials disagree at pixel (" << x << ", " << y
             << "): not one calibration, or the centre's row and column swapped";
        fail(text.str());
      }
    }
  }
}

std::optional<CameraModelId> CameraModelOfToolName(const std::string& name) {
  static const std::map<std::string, CameraModelId> models = {{"plumb_bob", CameraModelId::kOpenCv},
                                                              {"rational_polynomial", CameraModelId::kOpenCv},
                                                              {"radtan", CameraModelId::kOpenCv},
                                                              {"equidistant", CameraModelId::kKannalaBrandt},
                                                              {"fisheye", CameraModelId::kKannalaBrandt}};
  const auto found = models.find(name);
  if (found == models.end()) return std::nullopt;
  return found->second;
}

void to_json(nlohmann::json& j, const Camera& camera) {
  const auto& p = camera.params();
  j = nlohmann::json{{"model", camera.model_name()}, {"width", camera.width()}, {"height", camera.height()},
                     {"cx", camera.cx()}, {"cy", camera.cy()}};
  if (camera.model() == CameraModelId::kOcam) {
    j["c"] = p[4];
    j["d"] = p[5];
    j["e"] = p[6];
    j["ss"] = Coefficients(p, OcamModel::kDirectOffset, OcamModel::kMaxDirect);
    j["invpol"] = Coefficients(p, OcamModel::kInverseOffset, OcamModel::kMaxInverse);
    return;
  }
  j["fx"] = camera.fx();
  j["fy"] = camera.fy();
  if (camera.model() == CameraModelId::kKannalaBrandt) j["k"] = {p[4], p[5], p[6], p[7]};
  if (camera.model() == CameraModelId::kOpenCv) {
    const auto first = p.begin() + OpenCvModel::kDistortionOffset;
    const bool rational = p[9] != 0.0 || p[10] != 0.0 || p[11] != 0.0;
    j["distortion"] = std::vector<double>(first, first + (rational ? 8 : 5));
  }
}

namespace {

// Throws Error for a key the model does not read. A key another model reads is named as such:
// a pinhole camera given "distortion" would otherwise lose its lens model without a word.
void RejectKeysTheModelDoesNotRead(const nlohmann::json& j, const std::string& model) {
  const std::vector<std::string> common = {"model", "width", "height", "cx", "cy"};
  const std::vector<std::pair<std::string, std::vector<std::string>>> model_keys = {
      {PinholeModel::kName, {"fx", "fy"}},
      {KannalaBrandtModel::kName, {"fx", "fy", "k"}},
      {OpenCvModel::kName, {"fx", "fy", "distortion"}},
      {OcamModel::kName, {"c", "d", "e", "ss", "invpol"}}};
  std::vector<std::string> known = common, names;
  for (const auto& [name, keys] : model_keys) {
    names.push_back(name);
    if (name == model) known.insert(known.end(), keys.begin(), keys.end());
  }
  if (known.size() == common.size()) {
    const std::optional<CameraModelId> meant = CameraModelOfToolName(model);
    throw Error("camera: unknown camera model '" + model + "' (known: " + Join(names, ", ") + ")" +
                (meant ? "; " + model + " is " + CameraModelName(*meant) + " here" : ""));
  }
  // Lens coefficients one key each, as many calibration files write them.
  const std::set<std::string> coefficients = {"k1", "k2", "k3", "k4", "k5", "k6", "p1", "p2"};
  for (const auto& item : j.items()) {
    if (std::find(known.begin(), known.end(), item.key()) != known.end()) continue;
    if (coefficients.count(item.key()) > 0) {
      throw Error("camera: unknown key '" + item.key() + "': lens coefficients go in one list, \"distortion\": [k1, k2, "
                  "p1, p2, k3] with model opencv (OpenCV's order), or \"k\": [k0, k1, k2, k3] with model "
                  "kannala_brandt");
    }
    for (const auto& [name, keys] : model_keys) {
      if (std::find(keys.begin(), keys.end(), item.key()) != keys.end()) {
        throw Error("camera: model " + model + " takes no '" + item.key() + "'; model " + name +
                    " does (docs/data.md, \"Sequence format\")");
      }
    }
  }
  RejectUnknownKeys(j, known, "camera (model " + model + ")");
}

}  // namespace

void from_json(const nlohmann::json& j, Camera& camera) {
  if (!j.is_object()) throw Error("camera: expected a JSON object");
  const auto number = [&](const char* key) { return Field<double>(j, key, "camera"); };
  const auto numbers = [&](const char* key) { return Field<std::vector<double>>(j, key, "camera"); };
  const std::string model = Field<std::string>(j, "model", "camera");
  RejectKeysTheModelDoesNotRead(j, model);
  const int width = Field<int>(j, "width", "camera");
  const int height = Field<int>(j, "height", "camera");
  const double cx = number("cx"), cy = number("cy");
  if (model == OcamModel::kName) {
    // No affine part given: the identity, as OCamCalib starts from; no inverse polynomial: fitted to ss.
    camera = Camera::Ocam(width, height, cx, cy, Field(j, "c", "camera", 1.0), Field(j, "d", "camera", 0.0),
                          Field(j, "e", "camera", 0.0), numbers("ss"),
                          Field(j, "invpol", "camera", std::vector<double>()));
  } else if (model == PinholeModel::kName) {
    camera = Camera::Pinhole(width, height, number("fx"), number("fy"), cx, cy);
  } else if (model == KannalaBrandtModel::kName) {
    if (!j.contains("k") || !j.at("k").is_array() || j.at("k").size() != 4) {
      throw Error("camera: kannala_brandt needs 'k' with 4 coefficients");
    }
    const std::vector<double> k = numbers("k");
    camera = Camera::KannalaBrandt(width, height, number("fx"), number("fy"), cx, cy,
                                   Eigen::Vector4d(k[0], k[1], k[2], k[3]));
  } else if (model == OpenCvModel::kName) {
    if (!j.contains("distortion") || !j.at("distortion").is_array()) {
      throw Error("camera: opencv needs 'distortion': OpenCV's distCoeffs, k1 k2 p1 p2 [k3 [k4 k5 k6]]");
    }
    camera = Camera::OpenCv(width, height, number("fx"), number("fy"), cx, cy, numbers("distortion"));
  }
  camera.Check();
}

}  // namespace nrslam
