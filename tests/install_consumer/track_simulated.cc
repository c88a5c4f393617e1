// A user's program on the installed library. Usage: track_simulated WORK_FOLDER.
#include <iostream>

#include "track_simulated_job.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: track_simulated WORK_FOLDER\n";
    return 2;
  }
  return TrackSimulatedSequence(argv[1]);
}
