// util: the median (and mean) the modules take of depths, displacement norms and RMSEs.
#pragma once

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <vector>

namespace nrslam {

// The upper median (the element at index n/2 once sorted) of a non-empty set, found by
// partial sorting, which reorders it: for a buffer re-filled every frame.
template <typename T>
T MedianInPlace(std::vector<T>* values) {
  const auto middle = values->begin() + static_cast<std::ptrdiff_t>(values->size() / 2);
  std::nth_element(values->begin(), middle, values->end());
  return *middle;
}

// The same of a copy.
inline double Median(std::vector<double> values) { return MedianInPlace(&values); }

// The arithmetic mean of a non-empty set.
inline double Mean(const std::vector<double>& values) {
  return std::accumulate(values.begin(), values.end(), 0.0) / values.size();
}

}  // namespace nrslam
