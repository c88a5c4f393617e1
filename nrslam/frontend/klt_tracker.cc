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
  // Truncation after a shift is floor() for anything inside the pyramid's border, and cheaper.
  constexpr int kShift = 64;
  static_assert(kShift > ImagePyramid::border(), "the shift must cover the border");
  const int x0 = static_cast<int>(x + kShift) - kShift, y0 = static_cast<int>(y + kShift) - kShift;
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

// The top-left tap and the four bilinear weights of a window whose top-left sample is at
// (left, top). For a translated window all samples share them, so each row of the window is
// a fixed blend of two image rows.
struct BilinearTaps {
  int x0, y0;
  float w00, w01, w10, w11;
};
BilinearTaps TapsAt(float left, float top) {
  const int x0 = static_cast<int>(std::floor(left)), y0 = static_cast<int>(std::floor(top));
  const float ax = left - x0, ay = top - y0;
  return {x0, y0, (1 - ax) * (1 - ay), ax * (1 - ay), (1 - ax) * ay, ax * ay};
}

// Bilinear sample of the side×side window centred at (x, y).
void SampleWindow(const cv::Mat& image, float x, float y, int side, float* out) {
  const BilinearTaps t = TapsAt(x - (side - 1) * 0.5f, y - (side - 1) * 0.5f);
  for (int r = 0; r < side; ++r) {
    const float* row0 = image.ptr<float>(t.y0 + r) + t.x0;
    const float* row1 = image.ptr<float>(t.y0 + r + 1) + t.x0;
    float* o = out + r * side;
    for (int c = 0; c < side; ++c) o[c] = t.w00 * row0[c] + t.w01 * row0[c + 1] + t.w10 * row1[c] + t.w11 * row1[c + 1];
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
void KltTracker::DetrendedUnitPatch(const float* patch, const Trend& trend, float* out) const {
  // The patch minus its mean and linear trend is orthogonal to 1, u and v (the window is
  // symmetric); normalised, it completes the orthonormal appearance basis.
  double norm = 0;
  for (int i = 0; i < area_; ++i) {
    out[i] = static_cast<float>(patch[i] - trend.mean - trend.slope_u * (i % window_ - half_) -
                                trend.slope_v * (i / window_ - half_));
    norm += static_cast<double>(out[i]) * out[i];
  }
  const float scale = norm > 1e-9 ? static_cast<float>(1.0 / std::sqrt(norm)) : 0.f;
  for (int i = 0; i < area_; ++i) out[i] *= scale;
}

void KltTracker::ProjectOutAppearance(const float* unit_patch, float* image) const {
  // Components along 1, u, v (orthogonal: remove them one by one), then along the patch.
  double sum = 0, along_u = 0, along_v = 0;
  for (int i = 0; i < area_; ++i) {
    sum += image[i];
    along_u += image[i] * (i % window_ - half_);
    along_v += image[i] * (i / window_ - half_);
  }
  const double mean = sum / area_, slope_u = along_u / moment_uu_, slope_v = along_v / moment_uu_;
  double along_patch = 0;
  for (int i = 0; i < area_; ++i) {
    image[i] -= static_cast<float>(mean + slope_u * (i % window_ - half_) + slope_v * (i / window_ - half_));
    along_patch += static_cast<double>(image[i]) * unit_patch[i];
  }
  for (int i = 0; i < area_; ++i) image[i] -= static_cast<float>(along_patch) * unit_patch[i];
}

KltTracker::Trend KltTracker::TrendFromSums(const WindowSums& sums) const {
  Trend trend;
  trend.mean = sums.sum / area_;
  trend.slope_u = sums.along_u / moment_uu_;
  trend.slope_v = sums.along_v / moment_uu_;
  trend.deviation = std::sqrt(std::max(0.0, (sums.squares - area_ * trend.mean * trend.mean -
                                             sums.along_u * trend.slope_u - sums.along_v * trend.slope_v) /
                                                area_));
  return trend;
}

double KltTracker::TextureCorrelation(const float* a, const Trend& a_trend, const float* b, const Trend& b_trend) const {
  double ab = 0, aa = 0, bb = 0;
  for (int i = 0; i < area_; ++i) {
    const double u = i % window_ - half_, v = i / window_ - half_;
    const double da = a[i] - a_trend.mean - a_trend.slope_u * u - a_trend.slope_v * v;
    const double db = b[i] - b_trend.mean - b_trend.slope_u * u - b_trend.slope_v * v;
    ab += da * db;
    aa += da * da;
    bb += db * db;
  }
  return aa > 1e-12 && bb > 1e-12 ? ab / std::sqrt(aa * bb) : 0.0;
}

KltTracker::Trend KltTracker::WindowTrend(const float* window) const {
  WindowSums sums;
  for (int r = 0; r < window_; ++r) {
    const float v = static_cast<float>(r - half_);
    const float* w = window + r * window_;
    float sum = 0.f, squares = 0.f, along_u = 0.f;
#pragma omp simd reduction(+ : sum, squares, along_u)
    for (int col = 0; col < window_; ++col) {
      sum += w[col];
      squares += w[col] * w[col];
      along_u += w[col] * static_cast<float>(col - half_);
    }
    sums.sum += sum;
    sums.squares += squares;
    sums.along_u += along_u;
    sums.along_v += v * sum;
  }
  return TrendFromSums(sums);
}

void KltTracker::AccumulateTranslated(const cv::Mat& image, float x, float y, const float* gx, const float* gy,
                                      WindowSums* sums) const {
  const BilinearTaps t = TapsAt(x - static_cast<float>(half_), y - static_cast<float>(half_));
  const float w00 = t.w00, w01 = t.w01, w10 = t.w10, w11 = t.w11;
  for (int r = 0; r < window_; ++r) {
    const float* row0 = image.ptr<float>(t.y0 + r) + t.x0;
    const float* row1 = image.ptr<float>(t.y0 + r + 1) + t.x0;
    const float* gx_row = gx + r * window_;
    const float* gy_row = gy + r * window_;
    float sum = 0.f, squares = 0.f, along_u = 0.f, gx_j = 0.f, gy_j = 0.f;
#pragma omp simd reduction(+ : sum, squares, along_u, gx_j, gy_j)
    for (int col = 0; col < window_; ++col) {
      const float j = w00 * row0[col] + w01 * row0[col + 1] + w10 * row1[col] + w11 * row1[col + 1];
      sum += j;
      squares += j * j;
      along_u += j * static_cast<float>(col - half_);
      gx_j += gx_row[col] * j;
      gy_j += gy_row[col] * j;
    }
    sums->sum += sum;
    sums->squares += squares;
    sums->along_u += along_u;
    sums->along_v += static_cast<float>(r - half_) * sum;
    sums->gx_j += gx_j;
    sums->gy_j += gy_j;
  }
}

KltTracker::Photometric KltTracker::FitFromSums(size_t slot, const WindowSums& sums) const {
  return FitTrend(slot, TrendFromSums(sums));
}

KltTracker::Photometric KltTracker::FitTrend(size_t slot, const Trend& current) const {
  const Trend& reference = reference_trend_[slot];
  Photometric fit;
  fit.textured = current.deviation > 1e-3;
  const auto ratio = static_cast<float>(reference.deviation / current.deviation);
  fit.gain = fit.textured ? std::clamp(ratio, kKltMinGain, kKltMaxGain) : 1.f;
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
  points_.clear();
  Append(reference, points, valid);
}

void KltTracker::Append(const ImagePyramid& reference, const std::vector<cv::Point2f>& new_points,
                        const cv::Mat& valid) {
  if (points_.empty()) levels_ = std::min(options_.levels, reference.levels());
  if (reference.levels() < levels_) {
    throw Error("KltTracker::Append: the pyramid has " + std::to_string(reference.levels()) + " levels, the tracker " +
                std::to_string(levels_));
  }
  const size_t first = points_.size();
  points_.insert(points_.end(), new_points.begin(), new_points.end());
  const size_t slots = points_.size() * levels_;
  patch_.resize(slots * area_, 0.f);
  gradient_x_.resize(slots * area_, 0.f);
  gradient_y_.resize(slots * area_, 0.f);
  inverse_normal_.resize(slots * 3, 0.f);
  level_valid_.resize(slots, 0);
  reference_trend_.resize(slots, Trend());
  affine_normal_.resize(points_.size() * 36, 0.0);
  affine_steepest_.resize(points_.size() * 6 * area_, 0.f);
  std::fill(level_valid_.begin() + first * levels_, level_valid_.end(), 0);
  const int padded = window_ + 2;
  // OpenCV's scale (calcOpticalFlowPyrLK's minEigThreshold): eigenvalue of Σ∇I∇Iᵀ over the
  // window area, gradients in grey levels per px, divided by 1024.
  const double min_eigenvalue = options_.min_eigenvalue * area_ * 1024.0;

  std::vector<std::vector<float>> projected(omp_get_max_threads(), std::vector<float>(6 * static_cast<size_t>(area_)));
#pragma omp parallel
  {
    std::vector<float> border(static_cast<size_t>(padded) * padded);
    std::vector<float> unit_patch_buffer(area_);
#pragma omp for schedule(dynamic, 16)
    for (long p = static_cast<long>(first); p < static_cast<long>(points_.size()); ++p) {
      for (int level = 0; level < levels_; ++level) {
        const size_t slot = static_cast<size_t>(p) * levels_ + level;
        const cv::Mat& image = reference.level(level);
        const float scale = 1.f / static_cast<float>(1 << level);
        const float x = points_[p].x * scale, y = points_[p].y * scale;
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
        reference_trend_[slot] = WindowTrend(patch);
        float* unit_patch = unit_patch_buffer.data();
        DetrendedUnitPatch(patch, reference_trend_[slot], unit_patch);
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
          ProjectOutAppearance(unit_patch, sd);
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

  for (int level = levels - 1; level >= 0; --level) {
    if (level < levels - 1) {
      x *= 2.f;
      y *= 2.f;
    }
    const size_t slot = index * levels_ + level;
    if (!level_valid_[slot]) continue;  // no patch here: carry the estimate down
    const cv::Mat& image = current.level(level);
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
      // One pass: sample the window and accumulate what the step needs. The steepest-descent
      // images are orthogonal to 1, u, v and the patch, so the fitted bias plane drops out of
      // the step and the gain only scales it: b = gain · Σ ∇T · J.
      WindowSums sums;
      AccumulateTranslated(image, x, y, gx, gy, &sums);
      const float gain = FitFromSums(slot, sums).gain;
      const float step_x = gain * (inverse[0] * sums.gx_j + inverse[1] * sums.gy_j);
      const float step_y = gain * (inverse[1] * sums.gx_j + inverse[2] * sums.gy_j);
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
  const Trend window_trend = WindowTrend(warped);
  const Photometric fit = FitTrend(slot, window_trend);
  const bool texture_matches =
      options_.min_texture_correlation <= -1 ||
      TextureCorrelation(patch, reference_trend_[slot], warped, window_trend) >= options_.min_texture_correlation;
  Correct(fit, warped);
  result.gain = fit.gain;
  result.bias = fit.bias;
  result.ssim = Ssim(patch, warped, area_);
  result.status =
      fit.textured && texture_matches && result.ssim >= ssim_threshold ? KltStatus::kTracked : KltStatus::kSsimRejected;
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
  const float* steepest = &affine_steepest_[(slot / levels_) * 6 * area_];
  const double* normal = &affine_normal_[(slot / levels_) * 36];
  const float start_x = *x, start_y = *y;
  float best_x = *x, best_y = *y;
  for (int iteration = 0; iteration < options_.affine_iterations; ++iteration) {
    // The warped window's corners must stay inside the image (its reach is at most ~1.5 half).
    if (!WindowInside(image, *x, *y, 2 * half_)) break;
    // As in translation, the projected steepest-descent images make b = gain · Σ SD · J.
    double sd_j[6] = {0, 0, 0, 0, 0, 0};
    WindowSums sums;
    SampleAffine(image, *x, *y, linear, warped);
    for (int r = 0; r < window_; ++r) {
      const float* w = warped + r * window_;
      float sum = 0.f, squares = 0.f, along_u = 0.f;
      float products[6] = {0.f, 0.f, 0.f, 0.f, 0.f, 0.f};
#pragma omp simd reduction(+ : sum, squares, along_u)
      for (int col = 0; col < window_; ++col) {
        sum += w[col];
        squares += w[col] * w[col];
        along_u += w[col] * static_cast<float>(col - half_);
      }
      for (int k = 0; k < 6; ++k) {
        const float* sd = steepest + static_cast<size_t>(k) * area_ + r * window_;
        float dot = 0.f;
#pragma omp simd reduction(+ : dot)
        for (int col = 0; col < window_; ++col) dot += sd[col] * w[col];
        products[k] = dot;
      }
      sums.sum += sum;
      sums.squares += squares;
      sums.along_u += along_u;
      sums.along_v += static_cast<float>(r - half_) * sum;
      for (int k = 0; k < 6; ++k) sd_j[k] += products[k];
    }
    const double gain = FitFromSums(slot, sums).gain;
    double b[6];
    for (int k = 0; k < 6; ++k) b[k] = gain * sd_j[k];
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
    // Converged when no pixel of the window moves by more than epsilon.
    const double corner_motion = std::hypot(dx, dy) + half_ * (std::abs(step[2]) + std::abs(step[3]) +
                                                                std::abs(step[4]) + std::abs(step[5]));
    if (corner_motion < options_.epsilon_px) break;
  }
}

void KltTracker::Track(const ImagePyramid& current, const std::vector<cv::Point2f>& guesses, double ssim_threshold,
                       std::vector<KltResult>* results, int threads) const {
  if (guesses.size() != points_.size()) {
    throw Error("KltTracker::Track: " + std::to_string(guesses.size()) + " guesses for " +
                std::to_string(points_.size()) + " reference points");
  }
  results->resize(points_.size());
#pragma omp parallel num_threads(threads > 0 ? threads : omp_get_max_threads())
  {
    std::vector<float> scratch(area_);
#pragma omp for schedule(dynamic, 16)
    for (long i = 0; i < static_cast<long>(points_.size()); ++i) {
      (*results)[i] = TrackOne(current, static_cast<size_t>(i), guesses[i], ssim_threshold, scratch.data());
    }
  }
}

}  // namespace nrslam
