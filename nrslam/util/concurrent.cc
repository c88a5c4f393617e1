#include "nrslam/util/concurrent.h"

#include <array>
#include <exception>

namespace nrslam {

void RunConcurrently(const std::function<void()>& first, const std::function<void()>& second) {
  // Exceptions must not leave an OpenMP region: each task's is kept and rethrown after it.
  std::array<std::exception_ptr, 2> errors;
  const auto run = [&errors](const std::function<void()>& task, size_t slot) {
    try {
      task();
    } catch (...) {
      errors[slot] = std::current_exception();
    }
  };
#pragma omp parallel sections num_threads(2)
  {
#pragma omp section
    run(first, 0);
#pragma omp section
    run(second, 1);
  }
  for (const std::exception_ptr& error : errors) {
    if (error) std::rethrow_exception(error);
  }
}

}  // namespace nrslam
