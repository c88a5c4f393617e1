// util: Student's t distribution, for confidence intervals of a mean over few runs.
#pragma once

namespace nrslam {

// The two-sided critical value t* of Student's t with `degrees_of_freedom` (≥ 1):
// P(|T| ≤ t*) = confidence, for 0 < confidence < 1 (0.95 gives 12.706 at 1 degree of
// freedom, 2.069 at 23, → 1.960 as the degrees grow). Exact to 1e-9 relative, from the
// closed form of the distribution at integer degrees of freedom.
double StudentTCriticalValue(double confidence, int degrees_of_freedom);

}  // namespace nrslam
