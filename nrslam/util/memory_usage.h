// util: how much memory this process has held, for the run summaries and the benchmarks.
#pragma once

struct rusage;

namespace nrslam {

// A process's peak resident memory as getrusage or wait4 report it (ru_maxrss), in MB.
double MaxResidentMb(const rusage& usage);

// The most resident memory this process has held since it started, in MB (getrusage's
// ru_maxrss). It never goes down, so in a process that runs several sequences it is their
// common peak, not the last one's. 0 when the system does not report it.
double PeakResidentMemoryMb();

}  // namespace nrslam
