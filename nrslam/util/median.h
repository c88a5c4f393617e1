// util: the median (and mean) the modules take of depths, displacement norms and RMSEs.
#pragma once

#include <algorithm>
#include <numeric>
#include <vector>

namespace nrslam {

// The upper median (the element at index n/2 once sorted) of a non-empty set; takes a copy
// because partial sorting reorders it.
inline double Median(std::vector<double> values) {
  const auto middle = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// The arithmetic mean of a non-empty set.
inline double Mean(const std::vector<double>& values) {
  return std::accumulate(values.begin(), values.end(), 0.0) / values.size();
}

}  // namespace nrslam
