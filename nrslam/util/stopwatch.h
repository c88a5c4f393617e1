// util: wall-clock milliseconds for the per-stage timings every module reports.
#pragma once

#include <chrono>

namespace nrslam {

using Clock = std::chrono::steady_clock;

inline double MillisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace nrslam
