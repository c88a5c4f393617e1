#include "nrslam/frontend/klt_tracker.h"

#include <omp.h>

#include <algorithm>
#include <cmath>

#include "nrslam/util/error.h"

namespace nrslam {
namespace {

// Whether a window of half-size `half` centred at (x, y) can be sampled bilinearly, letting
// it overhang the image by up to `overhang` px into the pyramid's reflected border.
bool WindowInside(const cv::Mat& image, float x, float y, int half, int overhang = 0) {
  return x - half >= -overhang && y - half >= -overhang && x + half + 1 < image.cols + overhang &&
         y + half + 1 < image.rows + overhang;
}

// On coarse levels the window may overhang as far as its centre, which stays in the image.
int CoarseOverhang(int level, int half) { return level > 0 ? std::min(half, ImagePyramid::border() - 2) : 0; }

// Bilinear sample at arbitrary (x, y) of a level image (inside its border).
inline float SampleAt(const cv::Mat& image, float x, float y) {
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const float ax = x - x0, ay = y - y0;
  const float* row0 = image.ptr<float>(y0) + x0;
  const float* row1 = image.ptr<float>(y0 + 1) + x0;
  return (1 - ay) * ((1 - ax) * row0[0] + ax * row0[1]) + ay * ((1 - ax) * row1[0] + ax * row1[1]);
}

// Solves the symmetric 6x6 system H x = b by Cholesky; false if H is not positive definite.
bool SolveSymmetric6(const double* h, const double* b, double* x) {
  double l[36] = {0};
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j <= i; ++j) {
      double sum = h[i * 6 + j];
      for (int k = 0; k < j; ++k) sum -= l[i * 6 + k] * l[j * 6 + k];
      if (i == j) {
        if (sum <= 1e-12) return false;
        l[i * 6 + i] = std::sqrt(sum);
      } else {
        l[i * 6 + j] = sum / l[j * 6 + j];
      }
    }
  }
  double y[6];
  for (int i = 0; i < 6; ++i) {
    double sum = b[i];
    for (int k = 0; k < i; ++k) sum -= l[i * 6 + k] * y[k];
    y[i] = sum / l[i * 6 + i];
  }
  for (int i = 5; i >= 0; --i) {
    double sum = y[i];
    for (int k = i + 1; k < 6; ++k) sum -= l[k * 6 + i] * x[k];
    x[i] = sum / l[i * 6 + i];
  }
  return true;
}

// Bilinear sample of the side×side window centred at (x, y). All taps share the same
// weights (a translation), so each row is a fixed blend of two image rows.
void SampleWindow(const cv::Mat& image, float x, float y, int side, float* out) {
  const float left = x - (side - 1) * 0.5f, top = y - (side - 1) * 0.5f;
  const int x0 = static_cast<int>(std::floor(left)), y0 = static_cast<int>(std::floor(top));
  const float ax = left - x0, ay = top - y0;
  const float w00 = (1 - ax) * (1 - ay), w01 = ax * (1 - ay), w10 = (1 - ax) * ay, w11 = ax * ay;
  for (int r = 0; r < side; ++r) {
    const float* row0 = image.ptr<float>(y0 + r) + x0;
    const float* row1 = image.ptr<float>(y0 + r + 1) + x0;
    float* o = out + r * side;
    for (int c = 0; c < side; ++c) o[c] = w00 * row0[c] + w01 * row0[c + 1] + w10 * row1[c] + w11 * row1[c + 1];
  }
}

// Standard SSIM over one window (means over N, (co)variances over N − 1), 8-bit constants.
float Ssim(const float* x, const float* y, int count) {
  constexpr double kC1 = (0.01 * 255) * (0.01 * 255), kC2 = (0.03 * 255) * (0.03 * 255);
  double mx = 0, my = 0;
  for (int i = 0; i < count; ++i) {
    mx += x[i];
    my += y[i];
  }
  mx /= count;
  my /= count;
  double vx = 0, vy = 0, cxy = 0;
  for (int i = 0; i < count; ++i) {
    const double dx = x[i] - mx, dy = y[i] - my;
    vx += dx * dx;
    vy += dy * dy;
    cxy += dx * dy;
  }
  vx /= count - 1;
  vy /= count - 1;
  cxy /= count - 1;
  return static_cast<float>((2 * mx * my + kC1) * (2 * cxy + kC2) / ((mx * mx + my * my + kC1) * (vx + vy + kC2)));
}

}  // namespace

// Photometric correction of a current window towards the reference: gain · J + a bias plane
// (β + β_u·u + β_v·v). The gain is the ratio of the de-trended deviations (robust even far
// from convergence); the plane is what remains of the two windows' linear trends. Endoscope
// light changes across a patch, not only between patches.
KltTracker::AppearanceBasis KltTracker::MakeAppearanceBasis(const float* patch) const {
  AppearanceBasis basis;
  basis.area = area_;
  basis.vectors.assign(4 * static_cast<size_t>(area_), 0.f);
  basis.count = 0;
  auto add = [&](std::vector<double> vector) {  // Gram–Schmidt against the vectors so far
    for (int k = 0; k < basis.count; ++k) {
      double dot = 0;
      for (int i = 0; i < area_; ++i) dot += vector[i] * basis.vectors[k * area_ + i];
      for (int i = 0; i < area_; ++i) vector[i] -= dot * basis.vectors[k * area_ + i];
    }
    double norm = 0;
    for (double value : vector) norm += value * value;
    if (norm < 1e-9) return;
    norm = std::sqrt(norm);
    for (int i = 0; i < area_; ++i) basis.vectors[basis.count * area_ + i] = static_cast<float>(vector[i] / norm);
    ++basis.count;
  };
  std::vector<double> ones(area_, 1.0), along_u(area_), along_v(area_), appearance(patch, patch + area_);
  for (int i = 0; i < area_; ++i) {
    along_u[i] = i % window_ - half_;
    along_v[i] = i / window_ - half_;
  }
  add(ones);
  add(along_u);
  add(along_v);
  add(appearance);
  return basis;
}

void KltTracker::AppearanceBasis::ProjectOut(float* image) const {
  for (int k = 0; k < count; ++k) {
    const float* basis_vector = &vectors[static_cast<size_t>(k) * area];
    double dot = 0;
    for (int i = 0; i < area; ++i) dot += image[i] * basis_vector[i];
    for (int i = 0; i < area; ++i) image[i] -= static_cast<float>(dot) * basis_vector[i];
  }
}

KltTracker::Trend KltTracker::WindowTrend(const float* window) const {
  double sum = 0, squares = 0, along_u = 0, along_v = 0;
  for (int r = 0; r < window_; ++r) {
    const double v = r - half_;
    for (int col = 0; col < window_; ++col) {
      const double value = window[r * window_ + col];
      sum += value;
      squares += value * value;
      along_u += value * (col - half_);
      along_v += value * v;
    }
  }
  Trend trend;
  trend.mean = sum / area_;
  trend.slope_u = along_u / moment_uu_;
  trend.slope_v = along_v / moment_uu_;
  trend.deviation = std::sqrt(std::max(
      0.0, (squares - area_ * trend.mean * trend.mean - along_u * trend.slope_u - along_v * trend.slope_v) / area_));
  return trend;
}

KltTracker::Photometric KltTracker::FitPhotometric(size_t slot, const float* window) const {
  const Trend current = WindowTrend(window);
  const Trend& reference = reference_trend_[slot];
  Photometric fit;
  fit.gain = current.deviation > 1e-3 ? std::clamp(static_cast<float>(reference.deviation / current.deviation), 0.2f, 5.f)
                                      : 1.f;
  fit.bias = static_cast<float>(reference.mean - fit.gain * current.mean);
  fit.slope_u = static_cast<float>(reference.slope_u - fit.gain * current.slope_u);
  fit.slope_v = static_cast<float>(reference.slope_v - fit.gain * current.slope_v);
  return fit;
}

void KltTracker::Correct(const Photometric& fit, float* window) const {
  for (int r = 0; r < window_; ++r) {
    const float row_bias = fit.bias + fit.slope_v * static_cast<float>(r - half_);
    float* w = window + r * window_;
    for (int col = 0; col < window_; ++col) w[col] = fit.gain * w[col] + row_bias + fit.slope_u * static_cast<float>(col - half_);
  }
}

const char* ToString(KltStatus status) {
  switch (status) {
    case KltStatus::kTracked: return "tracked";
    case KltStatus::kNoReference: return "no_reference";
    case KltStatus::kLowTexture: return "low_texture";
    case KltStatus::kOutOfImage: return "out_of_image";
    case KltStatus::kLost: return "lost";
    case KltStatus::kSsimRejected: return "ssim_rejected";
  }
  return "unknown";
}

KltTracker::KltTracker(const KltOptions& options)
    : options_(options), window_(options.window_px), half_(options.window_px / 2), area_(options.window_px * options.window_px) {
  moment_uu_ = static_cast<double>(window_) * half_ * (half_ + 1) * (2 * half_ + 1) / 3.0;
  options_.Check();
}

void KltTracker::SetReference(const ImagePyramid& reference, const std::vector<cv::Point2f>& points,
                              const cv::Mat& valid) {
  levels_ = std::min(options_.levels, reference.levels());
  points_ = points;
  const size_t slots = points.size() * levels_;
  patch_.assign(slots * area_, 0.f);
  gradient_x_.assign(slots * area_, 0.f);
  gradient_y_.assign(slots * area_, 0.f);
  inverse_normal_.assign(slots * 3, 0.f);
  level_valid_.assign(slots, 0);
  reference_trend_.assign(slots, Trend());
  affine_normal_.assign(points.size() * 36, 0.0);
  affine_steepest_.assign(points.size() * 6 * area_, 0.f);
  const int padded = window_ + 2;
  // OpenCV's scale (calcOpticalFlowPyrLK's minEigThreshold): eigenvalue of Σ∇I∇Iᵀ over the
  // window area, gradients in grey levels per px, divided by 1024.
  const double min_eigenvalue = options_.min_eigenvalue * area_ * 1024.0;

  std::vector<std::vector<float>> projected(omp_get_max_threads(), std::vector<float>(6 * static_cast<size_t>(area_)));
#pragma omp parallel
  {
    std::vector<float> border(static_cast<size_t>(padded) * padded);
#pragma omp for schedule(dynamic, 16)
    for (long p = 0; p < static_cast<long>(points.size()); ++p) {
      for (int level = 0; level < levels_; ++level) {
        const size_t slot = static_cast<size_t>(p) * levels_ + level;
        const cv::Mat& image = reference.level(level);
        const float scale = 1.f / static_cast<float>(1 << level);
        const float x = points[p].x * scale, y = points[p].y * scale;
        if (!std::isfinite(x) || !std::isfinite(y) || !WindowInside(image, x, y, half_ + 1, CoarseOverhang(level, half_))) {
          continue;
        }
        if (!valid.empty()) {
          bool masked = false;
          for (int r = -half_; r <= half_ && !masked; ++r) {
            for (int c = -half_; c <= half_ && !masked; ++c) {
              const int vx = cvRound((x + c) * (1 << level)), vy = cvRound((y + r) * (1 << level));
              masked = vx < 0 || vy < 0 || vx >= valid.cols || vy >= valid.rows || valid.at<uint8_t>(vy, vx) == 0;
            }
          }
          if (masked) continue;
        }
        SampleWindow(image, x, y, padded, border.data());
        float* patch = &patch_[slot * area_];
        float* gx = &gradient_x_[slot * area_];
        float* gy = &gradient_y_[slot * area_];
        for (int r = 0; r < window_; ++r) {
          for (int col = 0; col < window_; ++col) {
            const float* centre = &border[(r + 1) * padded + col + 1];
            const int i = r * window_ + col;
            patch[i] = *centre;
            gx[i] = 0.5f * (centre[1] - centre[-1]);
            gy[i] = 0.5f * (centre[padded] - centre[-padded]);
          }
        }
        // Project out the appearance model: the photometric fit absorbs any error along
        // 1, u, v and the patch itself, so the steps must not count gradients along them
        // (Baker & Matthews' project-out inverse compositional algorithm).
        const AppearanceBasis basis = MakeAppearanceBasis(patch);
        std::vector<float>& steepest = projected[omp_get_thread_num()];
        const int images = level == 0 ? 6 : 2;
        for (int k = 0; k < images; ++k) {
          float* sd = &steepest[static_cast<size_t>(k) * area_];
          for (int r = 0; r < window_; ++r) {
            for (int col = 0; col < window_; ++col) {
              const int i = r * window_ + col;
              const float u = static_cast<float>(col - half_), v = static_cast<float>(r - half_);
              const float values[6] = {gx[i], gy[i], gx[i] * u, gx[i] * v, gy[i] * u, gy[i] * v};
              sd[i] = values[k];
            }
          }
          basis.ProjectOut(sd);
        }
        std::copy_n(steepest.data(), area_, gx);
        std::copy_n(steepest.data() + area_, area_, gy);
        double a = 0, b = 0, c = 0;
        for (int i = 0; i < area_; ++i) {
          a += gx[i] * gx[i];
          b += gx[i] * gy[i];
          c += gy[i] * gy[i];
        }
        const double determinant = a * c - b * b;
        const double min_eig = 0.5 * (a + c - std::sqrt((a - c) * (a - c) + 4 * b * b));
        if (min_eig < min_eigenvalue || determinant <= 0) continue;  // untextured: no usable patch here
        float* inverse = &inverse_normal_[slot * 3];
        inverse[0] = static_cast<float>(c / determinant);
        inverse[1] = static_cast<float>(-b / determinant);
        inverse[2] = static_cast<float>(a / determinant);
        reference_trend_[slot] = WindowTrend(patch);
        level_valid_[slot] = 1;
        if (level == 0) {
          // Steepest-descent images of the affine refinement, [gx, gy, gx·u, gx·v, gy·u, gy·v]
          // with the appearance projected out, and their normal matrix.
          std::copy_n(steepest.data(), 6 * area_, &affine_steepest_[static_cast<size_t>(p) * 6 * area_]);
          double* normal = &affine_normal_[static_cast<size_t>(p) * 36];
          for (int a6 = 0; a6 < 6; ++a6) {
            for (int b6 = 0; b6 <= a6; ++b6) {
              double dot = 0;
              for (int i = 0; i < area_; ++i) dot += steepest[a6 * area_ + i] * steepest[b6 * area_ + i];
              normal[a6 * 6 + b6] = normal[b6 * 6 + a6] = dot;
            }
          }
        }
      }
    }
  }
}

KltResult KltTracker::TrackOne(const ImagePyramid& current, size_t index, const cv::Point2f& guess,
                               double ssim_threshold, float* warped) const {
  // Coarse levels widen the capture range but see more of the light field than of the
  // texture; when they lead a track astray, try again from the seed with fewer of them.
  KltResult best;
  for (int levels = std::min(levels_, current.levels()); levels >= std::min(2, levels_); --levels) {
    const KltResult result = TrackFrom(current, index, guess, ssim_threshold, levels, warped);
    if (result.status != KltStatus::kLost && result.status != KltStatus::kSsimRejected) return result;
    if (best.status != KltStatus::kSsimRejected || result.ssim > best.ssim) best = result;
  }
  return best;
}

KltResult KltTracker::TrackFrom(const ImagePyramid& current, size_t index, const cv::Point2f& guess,
                                double ssim_threshold, int levels, float* warped) const {
  KltResult result;
  result.position = guess;
  if (!level_valid_[index * levels_]) {
    result.status = KltStatus::kNoReference;
    return result;
  }
  if (!std::isfinite(guess.x) || !std::isfinite(guess.y)) return result;  // kLost
  const float epsilon2 = static_cast<float>(options_.epsilon_px * options_.epsilon_px);
  const float max_shift2 = static_cast<float>(options_.max_displacement_px * options_.max_displacement_px);
  const float top_scale = 1.f / static_cast<float>(1 << (levels - 1));
  float x = guess.x * top_scale, y = guess.y * top_scale;
  float gain = 1.f, bias = 0.f;

  for (int level = levels - 1; level >= 0; --level) {
    if (level < levels - 1) {
      x *= 2.f;
      y *= 2.f;
    }
    const size_t slot = index * levels_ + level;
    if (!level_valid_[slot]) continue;  // no patch here: carry the estimate down
    const cv::Mat& image = current.level(level);
    const float* patch = &patch_[slot * area_];
    const float* gx = &gradient_x_[slot * area_];
    const float* gy = &gradient_y_[slot * area_];
    const float* inverse = &inverse_normal_[slot * 3];
    const float start_x = x, start_y = y;
    for (int iteration = 0; iteration < options_.max_iterations; ++iteration) {
      if (!WindowInside(image, x, y, half_, CoarseOverhang(level, half_))) {
        if (level == 0) {
          result.status = KltStatus::kOutOfImage;
          return result;
        }
        break;
      }
      SampleWindow(image, x, y, window_, warped);
      const Photometric fit = FitPhotometric(slot, warped);
      Correct(fit, warped);
      gain = fit.gain;
      bias = fit.bias;
      float bx = 0.f, by = 0.f;
      for (int i = 0; i < area_; ++i) {
        const float error = warped[i] - patch[i];
        bx += gx[i] * error;
        by += gy[i] * error;
      }
      const float step_x = inverse[0] * bx + inverse[1] * by;
      const float step_y = inverse[1] * bx + inverse[2] * by;
      x -= step_x;
      y -= step_y;
      if ((x - start_x) * (x - start_x) + (y - start_y) * (y - start_y) > max_shift2) {
        result.position = cv::Point2f(x * (1 << level), y * (1 << level));
        result.status = KltStatus::kLost;
        return result;
      }
      if (step_x * step_x + step_y * step_y < epsilon2) break;
    }
  }
  result.position = cv::Point2f(x, y);
  result.gain = gain;
  result.bias = bias;
  const cv::Mat& base = current.level(0);
  if (!WindowInside(base, x, y, half_)) {
    result.status = KltStatus::kOutOfImage;
    return result;
  }
  // Affine refinement on level 0: the window may have rotated or changed scale since the
  // reference (the camera advances and turns; the reference is up to a keyframe old), which
  // biases a translation-only estimate by a few tenths of a pixel.
  const size_t slot = index * levels_;
  const float* patch = &patch_[slot * area_];
  float linear[4] = {1.f, 0.f, 0.f, 1.f};  // current window = centre + linear · (u, v)
  if (options_.affine_refinement) RefineAffine(base, slot, &x, &y, linear, warped);
  if (!WindowInside(base, x, y, half_ + 2)) {
    result.status = KltStatus::kOutOfImage;
    return result;
  }
  result.position = cv::Point2f(x, y);
  // SSIM of the reference against the tracked patch with its gain and bias undone.
  SampleAffine(base, x, y, linear, warped);
  const Photometric fit = FitPhotometric(slot, warped);
  Correct(fit, warped);
  result.gain = fit.gain;
  result.bias = fit.bias;
  result.ssim = Ssim(patch, warped, area_);
  result.status = result.ssim >= ssim_threshold ? KltStatus::kTracked : KltStatus::kSsimRejected;
  return result;
}

void KltTracker::SampleAffine(const cv::Mat& image, float x, float y, const float* linear, float* out) const {
  for (int r = 0; r < window_; ++r) {
    const float v = static_cast<float>(r - half_);
    for (int col = 0; col < window_; ++col) {
      const float u = static_cast<float>(col - half_);
      out[r * window_ + col] = SampleAt(image, x + linear[0] * u + linear[1] * v, y + linear[2] * u + linear[3] * v);
    }
  }
}

void KltTracker::RefineAffine(const cv::Mat& image, size_t slot, float* x, float* y, float* linear, float* warped) const {
  const float* patch = &patch_[slot * area_];
  const float* steepest = &affine_steepest_[(slot / levels_) * 6 * area_];
  const double* normal = &affine_normal_[(slot / levels_) * 36];
  const float start_x = *x, start_y = *y;
  float best_x = *x, best_y = *y;
  for (int iteration = 0; iteration < options_.max_iterations; ++iteration) {
    // The warped window's corners must stay inside the image (its reach is at most ~1.5 half).
    if (!WindowInside(image, *x, *y, 2 * half_)) break;
    SampleAffine(image, *x, *y, linear, warped);
    Correct(FitPhotometric(slot, warped), warped);
    double b[6] = {0, 0, 0, 0, 0, 0};
    for (int i = 0; i < area_; ++i) {
      const double error = warped[i] - patch[i];
      for (int k = 0; k < 6; ++k) b[k] += steepest[k * area_ + i] * error;
    }
    double step[6];
    if (!SolveSymmetric6(normal, b, step)) return;  // not enough texture for six parameters
    // Inverse compositional update: W ← W ∘ W(Δ)⁻¹, W(Δ): q ↦ (I + ΔD) q + Δc.
    const double d00 = 1 + step[2], d01 = step[3], d10 = step[4], d11 = 1 + step[5];
    const double determinant = d00 * d11 - d01 * d10;
    if (std::abs(determinant) < 1e-6) return;
    const double i00 = d11 / determinant, i01 = -d01 / determinant, i10 = -d10 / determinant, i11 = d00 / determinant;
    const double l00 = linear[0] * i00 + linear[1] * i10, l01 = linear[0] * i01 + linear[1] * i11;
    const double l10 = linear[2] * i00 + linear[3] * i10, l11 = linear[2] * i01 + linear[3] * i11;
    linear[0] = static_cast<float>(l00);
    linear[1] = static_cast<float>(l01);
    linear[2] = static_cast<float>(l10);
    linear[3] = static_cast<float>(l11);
    const double dx = l00 * step[0] + l01 * step[1], dy = l10 * step[0] + l11 * step[1];
    *x -= static_cast<float>(dx);
    *y -= static_cast<float>(dy);
    // A wild linear part or a big jump means the six-parameter fit is not trustworthy here:
    // fall back to the translation estimate.
    const bool wild = std::abs(linear[0] - 1) > 0.3f || std::abs(linear[3] - 1) > 0.3f || std::abs(linear[1]) > 0.3f ||
                      std::abs(linear[2]) > 0.3f || std::hypot(*x - start_x, *y - start_y) > 2.f;
    if (wild) {
      *x = best_x;
      *y = best_y;
      linear[0] = linear[3] = 1.f;
      linear[1] = linear[2] = 0.f;
      return;
    }
    best_x = *x;
    best_y = *y;
    if (dx * dx + dy * dy < options_.epsilon_px * options_.epsilon_px && std::abs(step[2]) + std::abs(step[3]) +
                                                                                 std::abs(step[4]) + std::abs(step[5]) < 1e-4) {
      break;
    }
  }
}

void KltTracker::Track(const ImagePyramid& current, const std::vector<cv::Point2f>& guesses, double ssim_threshold,
                       std::vector<KltResult>* results) const {
  if (guesses.size() != points_.size()) {
    throw Error("KltTracker::Track: " + std::to_string(guesses.size()) + " guesses for " +
                std::to_string(points_.size()) + " reference points");
  }
  results->resize(points_.size());
#pragma omp parallel
  {
    std::vector<float> scratch(area_);
#pragma omp for schedule(dynamic, 16)
    for (long i = 0; i < static_cast<long>(points_.size()); ++i) {
      (*results)[i] = TrackOne(current, static_cast<size_t>(i), guesses[i], ssim_threshold, scratch.data());
    }
  }
}

}  // namespace nrslam
