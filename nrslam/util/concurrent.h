// util: two tasks at once, for overlapping independent work within one frame.
#pragma once

#include <functional>

namespace nrslam {

// Runs `first` and `second` at the same time on OpenMP's threads and returns when both are
// done; an exception from either is rethrown here (the first task's if both throw). With one
// OpenMP thread, or inside a parallel region, they run one after the other.
//
// OpenMP rather than a std::thread: libgomp's idle workers spin for milliseconds after each
// parallel region (the KLT's), so a thread started beside them shares a core with a spinning
// worker and both tasks slow down; inside a region the worker runs the task itself.
void RunConcurrently(const std::function<void()>& first, const std::function<void()>& second);

}  // namespace nrslam
