#include "nrslam/sim/mucosa_texture.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

#include "nrslam/util/random.h"

namespace nrslam {
namespace {

float Fade(float t) { return t * t * t * (t * (t * 6.f - 15.f) + 10.f); }

// Value noise in [-1, 1] on a lattice of unit cells, periodic in y every `period_y` cells
// (0 = not periodic). Lattice values come from a hash, so any texel is computed alone.
float ValueNoise(uint64_t seed, double x, double y, int period_y) {
  const double fx = std::floor(x), fy = std::floor(y);
  const long ix = static_cast<long>(fx);
  long iy0 = static_cast<long>(fy), iy1 = iy0 + 1;
  if (period_y > 0) {
    iy0 = ((iy0 % period_y) + period_y) % period_y;
    iy1 = ((iy1 % period_y) + period_y) % period_y;
  }
  auto lattice = [&](long i, long j) {
    return static_cast<float>(2.0 * UnitFromBits(HashCoordinates(seed, static_cast<uint64_t>(i + (1L << 40)),
                                                                 static_cast<uint64_t>(j + (1L << 40)))) - 1.0);
  };
  const float tx = Fade(static_cast<float>(x - fx)), ty = Fade(static_cast<float>(y - fy));
  const float a = lattice(ix, iy0) + tx * (lattice(ix + 1, iy0) - lattice(ix, iy0));
  const float b = lattice(ix, iy1) + tx * (lattice(ix + 1, iy1) - lattice(ix, iy1));
  return a + ty * (b - a);
}

// Sum of octaves at the given feature sizes (mm), amplitude ∝ size^0.5, normalised to ~[-1, 1].
float Fbm(uint64_t seed, double u_mm, double v_mm, double height_mm, bool periodic_v,
          std::initializer_list<double> sizes_mm) {
  float sum = 0.f, norm = 0.f;
  int octave = 0;
  for (double size : sizes_mm) {
    const int period = periodic_v ? std::max(1, static_cast<int>(std::lround(height_mm / size))) : 0;
    const double scale_v = periodic_v ? height_mm / period : size;
    const float amplitude = static_cast<float>(std::sqrt(size));
    sum += amplitude * ValueNoise(SplitMix64(seed + 101 * ++octave), u_mm / size, v_mm / scale_v, period);
    norm += amplitude;
  }
  return 1.6f * sum / norm;
}

struct VesselPainter {
  cv::Mat* map;
  double texel_mm;
  bool periodic_v;
  Rng* rng;

  void Segment(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double width_mm) const {
    const int thickness = std::max(1, static_cast<int>(std::lround(width_mm / texel_mm)));
    const double strength = std::min(1.0, 0.45 + width_mm / 0.6);
    const cv::Scalar colour(255.0 * strength);
    const double height_texels = map->rows;
    for (int wrap = periodic_v ? -1 : 0; wrap <= (periodic_v ? 1 : 0); ++wrap) {
      const cv::Point2d pa(a.x() / texel_mm, a.y() / texel_mm + wrap * height_texels);
      const cv::Point2d pb(b.x() / texel_mm, b.y() / texel_mm + wrap * height_texels);
      cv::line(*map, cv::Point(cvRound(pa.x * 4), cvRound(pa.y * 4)), cv::Point(cvRound(pb.x * 4), cvRound(pb.y * 4)),
               colour, thickness, cv::LINE_AA, 2);
    }
  }

  // A meandering branch that splits in two until the vessels get too thin.
  void Branch(Eigen::Vector2d position, double angle, double width_mm, double length_mm, int depth) const {
    constexpr double kStep = 0.5;  // mm
    const int steps = std::max(2, static_cast<int>(length_mm / kStep));
    for (int i = 0; i < steps; ++i) {
      angle += 0.18 * rng->Normal();
      const Eigen::Vector2d next = position + kStep * Eigen::Vector2d(std::cos(angle), std::sin(angle));
      Segment(position, next, width_mm);
      position = next;
      if (depth < 4 && i > 3 && rng->Uniform() < 0.04) {
        const double side = rng->Uniform() < 0.5 ? -1.0 : 1.0;
        Branch(position, angle + side * rng->Uniform(0.4, 0.9), width_mm * 0.6, length_mm * 0.55, depth + 1);
      }
    }
    if (depth < 4 && width_mm > 0.08) {
      const double spread = rng->Uniform(0.35, 0.8);
      Branch(position, angle + spread, width_mm * 0.7, length_mm * 0.6, depth + 1);
      Branch(position, angle - spread, width_mm * 0.7, length_mm * 0.6, depth + 1);
    }
  }
};

}  // namespace

MucosaTexture::MucosaTexture(double width_mm, double height_mm, bool periodic_v, const AppearanceOptions& options,
                             uint64_t seed, const Eigen::Vector3f& base_colour)
    : texel_mm_(options.texel_mm), width_mm_(width_mm), height_mm_(height_mm), periodic_v_(periodic_v) {
  const int width = std::max(8, static_cast<int>(std::ceil(width_mm / texel_mm_)));
  const int height = std::max(8, static_cast<int>(periodic_v ? std::lround(height_mm / texel_mm_)
                                                             : std::ceil(height_mm / texel_mm_)));
  if (periodic_v) texel_mm_ = height_mm / height;  // whole texels around the period

  // Vessel trees drawn first (sequential: the random stream is the tree layout).
  cv::Mat vessels = cv::Mat::zeros(height, width, CV_8UC1);
  Rng rng(SplitMix64(seed ^ 0x7e55e1ULL));
  VesselPainter painter{&vessels, texel_mm_, periodic_v, &rng};
  const int trees = static_cast<int>(std::lround(options.vessel_density * width_mm * height_mm / 100.0));
  for (int tree = 0; tree < trees; ++tree) {
    const Eigen::Vector2d root(rng.Uniform(0, width_mm), rng.Uniform(0, height_mm));
    painter.Branch(root, rng.Uniform(0, 2 * M_PI), rng.Uniform(0.25, 0.7), rng.Uniform(6, 18), 0);
  }
  cv::GaussianBlur(vessels, vessels, cv::Size(3, 3), 0.8);

  const Eigen::Vector3f pale(0.98f, 0.62f, 0.50f);
  const Eigen::Vector3f vessel_colour(0.42f, 0.05f, 0.09f);
  cv::Mat level0(height, width, CV_8UC3);
#pragma omp parallel for schedule(static)
  for (int y = 0; y < height; ++y) {
    const uint8_t* vessel_row = vessels.ptr<uint8_t>(y);
    cv::Vec3b* out = level0.ptr<cv::Vec3b>(y);
    for (int x = 0; x < width; ++x) {
      const double u = (x + 0.5) * texel_mm_, v = (y + 0.5) * texel_mm_;
      const float broad = Fbm(seed + 1, u, v, height_mm, periodic_v, {14.0, 7.0});
      const float fine = Fbm(seed + 2, u, v, height_mm, periodic_v, {2.0, 1.0, 0.5, 0.25});
      const float faint_region = 0.5f + 0.5f * Fbm(seed + 3, u, v, height_mm, periodic_v, {30.0});
      const float contrast = 1.f - static_cast<float>(options.weak_texture) * std::clamp(2.f * faint_region - 0.6f, 0.f, 0.85f);
      const float mix = std::clamp(0.5f + 0.35f * broad, 0.f, 1.f);
      Eigen::Vector3f albedo = (1.f - mix) * pale + mix * base_colour;
      albedo *= 1.f + 0.45f * contrast * fine;
      const float vessel = contrast * vessel_row[x] / 255.f;
      albedo = (1.f - 0.8f * vessel) * albedo + 0.8f * vessel * vessel_colour;
      for (int c = 0; c < 3; ++c) out[x][c] = cv::saturate_cast<uint8_t>(255.f * albedo[c]);
    }
  }
  levels_.push_back(level0);
  while (std::min(levels_.back().cols, levels_.back().rows) >= 16) {
    cv::Mat smaller;
    cv::resize(levels_.back(), smaller, cv::Size(levels_.back().cols / 2, levels_.back().rows / 2), 0, 0, cv::INTER_AREA);
    levels_.push_back(smaller);
  }
}

Eigen::Vector3f MucosaTexture::SampleLevel(int level, double u_mm, double v_mm) const {
  const cv::Mat& image = levels_[level];
  const double texel_x = width_mm_ / image.cols;
  const double texel_y = (periodic_v_ ? height_mm_ : image.rows * texel_mm_ * (1 << level)) / image.rows;
  const double x = u_mm / texel_x - 0.5, y = v_mm / texel_y - 0.5;
  const double fx = std::floor(x), fy = std::floor(y);
  const float ax = static_cast<float>(x - fx), ay = static_cast<float>(y - fy);
  const int x0 = std::clamp(static_cast<int>(fx), 0, image.cols - 1), x1 = std::min(x0 + 1, image.cols - 1);
  int y0 = static_cast<int>(fy), y1 = y0 + 1;
  if (periodic_v_) {
    y0 = ((y0 % image.rows) + image.rows) % image.rows;
    y1 = ((y1 % image.rows) + image.rows) % image.rows;
  } else {
    y0 = std::clamp(y0, 0, image.rows - 1);
    y1 = std::clamp(y1, 0, image.rows - 1);
  }
  auto texel = [&](int xx, int yy) {
    const cv::Vec3b& c = image.at<cv::Vec3b>(yy, xx);
    return Eigen::Vector3f(c[0], c[1], c[2]);
  };
  const Eigen::Vector3f top = (1 - ax) * texel(x0, y0) + ax * texel(x1, y0);
  const Eigen::Vector3f bottom = (1 - ax) * texel(x0, y1) + ax * texel(x1, y1);
  return ((1 - ay) * top + ay * bottom) / 255.f;
}

Eigen::Vector3f MucosaTexture::Sample(double u_mm, double v_mm, double footprint_mm) const {
  // The nearest mip level, bilinear within it: trilinear blending cost a second lookup per
  // pixel for no visible difference under sensor noise.
  const double level = std::log2(std::max(footprint_mm, texel_mm_) / texel_mm_);
  return SampleLevel(std::min(static_cast<int>(level + 0.5), static_cast<int>(levels_.size()) - 1), u_mm, v_mm);
}

}  // namespace nrslam
