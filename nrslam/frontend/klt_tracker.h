// frontend: illumination-invariant multi-scale Lucas–Kanade (paper eq. klt_enhan_residual).
//
// Each point is tracked against a reference patch cut at the last keyframe (not against the
// previous image), minimising Σ (I⁰(v) − α J(v + d) − β)² with a local gain α and bias β per
// point and iteration (β extended to a plane across the window: the light changes within a patch too). Formulation: inverse compositional on the reference patch, so its
// gradients and 2×2 normal matrix are computed once per reference, not per frame, with the
// photometric model projected out of them (project-out IC); α and β come in closed form. Coarse to fine over the
// pyramid (a track that goes astray is retried with fewer coarse levels), then (option affine_refinement) a six-parameter affine refinement on level 0 that
// removes the bias rotation and scale changes put on a translation-only estimate. A final SSIM check compares the reference patch with the gain/bias-corrected
// tracked patch (structure, not brightness), with a threshold chosen per use.
//
// Speed: patches live in flat arrays; tracking allocates one scratch buffer per thread.
#pragma once

#include <opencv2/core.hpp>

#include <vector>

#include "nrslam/frontend/frontend_options.h"
#include "nrslam/frontend/image_pyramid.h"

namespace nrslam {

enum class KltStatus {
  kTracked,
  kNoReference,   // no usable reference patch (masked or outside the reference image)
  kLowTexture,    // the patch's normal matrix is near singular
  kOutOfImage,    // the window left the current image
  kLost,          // moved farther than max_displacement_px on some level
  kSsimRejected,  // converged, but onto something that does not look like the reference
};
const char* ToString(KltStatus status);

// The bounds of the fitted gain α. A window whose texture is much fainter or stronger than the
// reference's (a near-black frame, noise) sits at one of them.
inline constexpr float kKltMinGain = 0.2f;
inline constexpr float kKltMaxGain = 5.f;

struct KltResult {
  cv::Point2f position;
  KltStatus status = KltStatus::kLost;
  float ssim = 0.f;
  float gain = 1.f;  // α, in [kKltMinGain, kKltMaxGain]
  float bias = 0.f;  // β
};

class KltTracker {
 public:
  explicit KltTracker(const KltOptions& options);

  // Cuts reference patches at `points` on every level of `reference`. With a non-empty
  // `valid` mask (level-0 size), a level whose window touches an invalid pixel has no patch.
  void SetReference(const ImagePyramid& reference, const std::vector<cv::Point2f>& points, const cv::Mat& valid = {});
  // Adds reference points cut from another image (e.g. a re-found point's patch from the
  // keyframe it was last seen in); indices continue after the existing ones.
  void Append(const ImagePyramid& reference, const std::vector<cv::Point2f>& points, const cv::Mat& valid = {});
  size_t size() const { return points_.size(); }
  bool has_reference(size_t index) const { return level_valid_[index * levels_]; }

  // Tracks every reference point into `current`, starting from guesses[i] (level-0 px).
  // `results` is resized to size(); an invalid guess (NaN) gives kLost. Points are tracked
  // independently, on `threads` threads (0: OpenMP's default), with the same results for any.
  void Track(const ImagePyramid& current, const std::vector<cv::Point2f>& guesses, double ssim_threshold,
             std::vector<KltResult>* results, int threads = 0) const;

 private:
  KltOptions options_;
  int window_;
  int half_;
  int area_;
  int levels_ = 0;
  std::vector<cv::Point2f> points_;
  // Per (point, level): the patch, its gradients, statistics and inverse normal matrix.
  std::vector<float> patch_, gradient_x_, gradient_y_;
  // A window's mean, linear trend along u and v, and the deviation left once both are removed.
  struct Trend {
    double mean = 0, slope_u = 0, slope_v = 0, deviation = 1;
  };
  std::vector<Trend> reference_trend_;  // per (point, level)
  double moment_uu_ = 1.0;              // Σ u² over the window (= Σ v²)
  std::vector<float> inverse_normal_;  // 3 per (point, level): symmetric 2x2 [a b; b c]
  std::vector<uint8_t> level_valid_;
  std::vector<double> affine_normal_;  // 36 per point: level-0 normal matrix of the affine refinement
  std::vector<float> affine_steepest_; // 6 windows per point: its steepest-descent images

  struct Photometric {
    float gain = 1.f, bias = 0.f, slope_u = 0.f, slope_v = 0.f;
    // The window has texture of its own (something left after its linear trend). A flat window
    // (a black or saturated frame) is corrected into the reference's own trend plane, which
    // the SSIM would take for a match, so it cannot confirm a track.
    bool textured = true;
  };
  // The appearance the photometric fit absorbs is spanned by 1, u, v and the patch; these
  // remove it from a steepest-descent image (project-out).
  void DetrendedUnitPatch(const float* patch, const Trend& trend, float* out) const;
  // Correlation of two windows with their mean and linear trend removed (the texture), in [-1, 1].
  double TextureCorrelation(const float* a, const Trend& a_trend, const float* b, const Trend& b_trend) const;
  void ProjectOutAppearance(const float* unit_patch, float* image) const;
  // Running sums over a window J: Σ J, Σ J², Σ J·u, Σ J·v, and Σ ∇T·J for the step.
  struct WindowSums {
    double sum = 0, squares = 0, along_u = 0, along_v = 0, gx_j = 0, gy_j = 0;
  };
  Trend TrendFromSums(const WindowSums& sums) const;
  Trend WindowTrend(const float* window) const;
  void AccumulateTranslated(const cv::Mat& image, float x, float y, const float* gx, const float* gy,
                            WindowSums* sums) const;
  Photometric FitTrend(size_t slot, const Trend& current) const;
  Photometric FitFromSums(size_t slot, const WindowSums& sums) const;
  Photometric FitGainBias(size_t slot, const float* window) const;    // gain and constant bias
  void Correct(const Photometric& fit, float* window) const;
  void SampleAffine(const cv::Mat& image, float x, float y, const float* linear, float* out) const;
  void RefineAffine(const cv::Mat& image, size_t slot, float* x, float* y, float* linear, float* warped) const;
  KltResult TrackOne(const ImagePyramid& current, size_t index, const cv::Point2f& guess, double ssim_threshold,
                     float* scratch) const;
  KltResult TrackFrom(const ImagePyramid& current, size_t index, const cv::Point2f& guess, double ssim_threshold,
                      int levels, float* scratch) const;
};

}  // namespace nrslam
