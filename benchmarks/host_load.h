// benchmarks: how busy the host was when a benchmark started, printed above its table.
#pragma once

#include <cstdio>
#include <fstream>
#include <thread>

// Prints Linux's 1-minute load average (/proc/loadavg) beside the core count; nothing where it
// cannot be read. This machine's timings drift with other work on it, and a load near the core
// count before the first run says a slow table may be the host, not the code.
inline void PrintHostLoad() {
  std::ifstream loadavg("/proc/loadavg");
  double one_minute = 0;
  if (!(loadavg >> one_minute)) return;
  std::printf("host load before the runs: %.2f (1-minute average) on %u cores\n", one_minute,
              std::thread::hardware_concurrency());
}
