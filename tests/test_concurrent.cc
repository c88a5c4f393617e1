// RunConcurrently (util/concurrent.h): both tasks run, at the same time, and an exception from
// either reaches the caller instead of ending the program inside an OpenMP region.
#include <gtest/gtest.h>
#include <omp.h>

#include <chrono>
#include <condition_variable>
#include <mutex>

#include "error_message.h"
#include "nrslam/util/concurrent.h"
#include "nrslam/util/error.h"

namespace nrslam {
namespace {

// Each task announces itself and waits (up to 10 s) for the other: run one after the other,
// the first would find the second never started.
TEST(RunConcurrently, RunsBothTasksAtOnce) {
#if !defined(__SANITIZE_THREAD__)  // under ThreadSanitizer the second task has a thread of its own
  if (omp_get_thread_limit() < 2) GTEST_SKIP() << "OMP_THREAD_LIMIT allows one thread: the tasks run in turn";
#endif
  std::mutex mutex;
  std::condition_variable changed;
  int started = 0;
  bool first_met_second = false, second_met_first = false;
  const auto meet = [&](bool* met) {
    std::unique_lock<std::mutex> lock(mutex);
    ++started;
    changed.notify_all();
    *met = changed.wait_for(lock, std::chrono::seconds(10), [&] { return started == 2; });
  };
  RunConcurrently([&] { meet(&first_met_second); }, [&] { meet(&second_met_first); });
  EXPECT_EQ(started, 2);
  EXPECT_TRUE(first_met_second);
  EXPECT_TRUE(second_met_first);
}

TEST(RunConcurrently, RethrowsATasksExceptionAfterBothEnd) {
  bool first_ended = false;
  EXPECT_EQ(ErrorMessage([&] { RunConcurrently([&] { first_ended = true; }, [] { throw Error("second failed"); }); }),
            "second failed");
  EXPECT_TRUE(first_ended);
  EXPECT_EQ(ErrorMessage([] {
              RunConcurrently([] { throw Error("first failed"); }, [] { throw Error("second failed"); });
            }),
            "first failed");
  EXPECT_EQ(ErrorMessage([] { RunConcurrently([] {}, [] {}); }), "");
}

}  // namespace
}  // namespace nrslam
