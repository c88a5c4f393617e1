#include "nrslam/util/concurrent.h"

#include <array>
#include <exception>
#if defined(__SANITIZE_THREAD__)
#include <future>
#endif

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
#if defined(__SANITIZE_THREAD__)
  // ThreadSanitizer cannot see how libgomp hands work to its threads (Debian's libgomp is not
  // instrumented), so it would report every access of the second task. Under it the second task
  // runs on a std::async thread, whose start and end it sees: what it then checks is whether
  // the two tasks touch the same data.
  std::future<void> second_done = std::async(std::launch::async, run, std::cref(second), 1);
  run(first, 0);
  second_done.wait();
#else
#pragma omp parallel sections num_threads(2)
  {
#pragma omp section
    run(first, 0);
#pragma omp section
    run(second, 1);
  }
#endif
  for (const std::exception_ptr& error : errors) {
    if (error) std::rethrow_exception(error);
  }
}

}  // namespace nrslam
