#include "nrslam/util/student_t.h"

#include <cmath>
#include <string>

#include "nrslam/util/error.h"

namespace nrslam {
namespace {

// P(|T| ≤ t) at ν degrees of freedom. With θ = atan(t / √ν) it is a finite sum of powers of
// cos θ (Abramowitz & Stegun 26.7.3–4): for odd ν, (2/π)(θ + sin θ Σ_{k odd < ν−1} c_k cos^k θ)
// with c_1 = 1, c_{k+2} = c_k (k+1)/(k+2); for even ν, sin θ Σ_{k even ≤ ν−2} c_k cos^k θ with
// c_0 = 1 and the same recurrence. Every term is positive, so the sum is stable at any ν.
double TwoSidedProbability(double t, int nu) {
  const double theta = std::atan(t / std::sqrt(static_cast<double>(nu)));
  const double c = std::cos(theta), c2 = c * c;
  const bool odd = nu % 2 == 1;
  double term = odd ? c : 1.0, sum = 0;
  for (int k = odd ? 1 : 0; k <= nu - 2; k += 2) {
    sum += term;
    term *= c2 * (k + 1.0) / (k + 2.0);
  }
  const double pi = std::acos(-1.0);
  return odd ? 2 / pi * (theta + std::sin(theta) * sum) : std::sin(theta) * sum;
}

}  // namespace

double StudentTCriticalValue(double confidence, int degrees_of_freedom) {
  if (!(confidence > 0 && confidence < 1) || degrees_of_freedom < 1) {
    throw Error("Student's t: confidence must be in (0, 1) and degrees of freedom >= 1, got " +
                std::to_string(confidence) + " and " + std::to_string(degrees_of_freedom));
  }
  double low = 0, high = 1;
  while (TwoSidedProbability(high, degrees_of_freedom) < confidence) high *= 2;
  // The probability rises with t, so bisection closes in on the one root.
  for (int i = 0; i < 200 && high - low > 1e-12 * high; ++i) {
    const double middle = 0.5 * (low + high);
    (TwoSidedProbability(middle, degrees_of_freedom) < confidence ? low : high) = middle;
  }
  return 0.5 * (low + high);
}

}  // namespace nrslam
