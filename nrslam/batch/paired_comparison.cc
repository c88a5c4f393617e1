#include "nrslam/batch/paired_comparison.h"

#include <algorithm>
#include <cmath>

#include "nrslam/util/median.h"
#include "nrslam/util/student_t.h"
#include "nrslam/util/text_table.h"

namespace nrslam {
namespace {

// A ratio as the tables print it; `reciprocal` turns it the other way up.
std::string RatioCell(double ratio, bool reciprocal) { return FormatFixed(reciprocal ? 1 / ratio : ratio, 3); }

}  // namespace

void RmseChangeCounts::Add(double reference_mm, double rmse_mm) {
  const double change = rmse_mm - reference_mm;
  const bool unchanged = std::abs(change) < 5e-4;
  ++(unchanged ? same : change < 0 ? better : worse);
  if (reference_mm > 0 && rmse_mm > 0) {
    log_ratios.push_back(std::log(rmse_mm / reference_mm));
    pair_moved.push_back(!unchanged);
  }
}

double RmseChangeCounts::GeometricMeanRatio() const {
  return log_ratios.empty() ? 1.0 : std::exp(Mean(log_ratios));
}

std::optional<RmseChangeCounts::RatioInterval> RmseChangeCounts::GeometricMeanRatioInterval(double confidence) const {
  const size_t n = log_ratios.size();
  if (n < 2) return std::nullopt;
  const double mean = Mean(log_ratios);
  double squares = 0;
  for (double r : log_ratios) squares += (r - mean) * (r - mean);
  const double standard_error = std::sqrt(squares / (n - 1) / n);
  const double half_width = StudentTCriticalValue(confidence, static_cast<int>(n) - 1) * standard_error;
  return RatioInterval{std::exp(mean - half_width), std::exp(mean + half_width)};
}

std::string RmseChangeCounts::GeometricMeanRatioIntervalText(bool reciprocal) const {
  const auto interval = GeometricMeanRatioInterval();
  if (!interval) return "";
  // Turned the other way up, the interval's upper end becomes the lower.
  const double first = reciprocal ? interval->high : interval->low, last = reciprocal ? interval->low : interval->high;
  return RatioCell(first, reciprocal) + " to " + RatioCell(last, reciprocal);
}

std::string RmseChangeCounts::GeometricMeanRatioText(bool reciprocal) const {
  const std::string interval = GeometricMeanRatioIntervalText(reciprocal);
  return RatioCell(GeometricMeanRatio(), reciprocal) + (interval.empty() ? "" : " (95 % CI " + interval + ")");
}

double RmseChangeCounts::SignedRankP() const {
  std::vector<double> changes;
  for (size_t i = 0; i < log_ratios.size(); ++i) {
    if (pair_moved[i]) changes.push_back(log_ratios[i]);
  }
  const int n = static_cast<int>(changes.size());
  if (n == 0) return 1.0;
  std::sort(changes.begin(), changes.end(), [](double a, double b) { return std::abs(a) < std::abs(b); });
  // Ranks of |change|, ties sharing their mean rank; doubled so that every rank is an integer.
  std::vector<int> doubled_rank(n);
  double tie_term = 0;  // sum of t³ − t over the tie groups
  for (int first = 0; first < n;) {
    int last = first;
    while (last + 1 < n && std::abs(changes[last + 1]) == std::abs(changes[first])) ++last;
    for (int i = first; i <= last; ++i) doubled_rank[i] = first + last + 2;
    const double t = last - first + 1;
    tie_term += t * t * t - t;
    first = last + 1;
  }
  int doubled_w_plus = 0;  // twice the rank sum of the runs that got worse
  for (int i = 0; i < n; ++i) doubled_w_plus += changes[i] > 0 ? doubled_rank[i] : 0;
  const int doubled_total = n * (n + 1);
  if (n <= 200) {
    // Distribution of the doubled rank sum when each run's sign is a fair coin.
    std::vector<double> probability(doubled_total + 1, 0.0);
    probability[0] = 1;
    int reach = 0;
    for (int r : doubled_rank) {
      for (int s = reach; s >= 0; --s) {
        probability[s + r] += 0.5 * probability[s];
        probability[s] *= 0.5;
      }
      reach += r;
    }
    double lower = 0, upper = 0;
    for (int s = 0; s <= doubled_total; ++s) (s <= doubled_w_plus ? lower : upper) += probability[s];
    upper += probability[doubled_w_plus];  // P(W+ >= w) includes w itself
    return std::min(1.0, 2 * std::min(lower, upper));
  }
  const double mean = n * (n + 1) / 4.0;
  const double variance = n * (n + 1) * (2.0 * n + 1) / 24.0 - tie_term / 48.0;
  const double distance = std::max(0.0, std::abs(doubled_w_plus / 2.0 - mean) - 0.5);  // continuity correction
  return variance > 0 ? std::min(1.0, std::erfc(distance / std::sqrt(2 * variance))) : 1.0;
}

double RmseChangeCounts::SignTestP() const {
  const int moved = better + worse, larger = std::max(better, worse);
  // Binomial(moved, 1/2) tail from `larger` up, each term by log-gamma so that long sweeps
  // cannot overflow.
  const double log_all_splits = std::lgamma(moved + 1.0) - moved * std::log(2.0);
  double tail = 0;
  for (int k = larger; k <= moved; ++k) tail += std::exp(log_all_splits - std::lgamma(k + 1.0) - std::lgamma(moved - k + 1.0));
  return moved == 0 ? 1.0 : std::min(1.0, 2 * tail);
}

std::string RmseChangeCounts::ToString() const {
  return std::to_string(better) + " / " + std::to_string(same) + " / " + std::to_string(worse);
}

}  // namespace nrslam
