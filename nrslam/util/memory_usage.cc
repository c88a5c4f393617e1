#include "nrslam/util/memory_usage.h"

#include <sys/resource.h>

namespace nrslam {

double MaxResidentMb(const rusage& usage) {
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // Linux reports kilobytes
}

double PeakResidentMemoryMb() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  return MaxResidentMb(usage);
}

}  // namespace nrslam
