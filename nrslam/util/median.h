// util: the median the modules take of depths and displacement norms.
#pragma once

#include <algorithm>
#include <vector>

namespace nrslam {

// The upper median (the element at index n/2 once sorted) of a non-empty set; takes a copy
// because partial sorting reorders it.
inline double Median(std::vector<double> values) {
  const auto middle = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace nrslam
