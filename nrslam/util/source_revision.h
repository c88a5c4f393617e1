// Which code built this library, for the provenance of every result it writes.
#pragma once

#include <string>

namespace nrslam {

// The git commit the library was built from, 12 hex digits; with "-dirty-" and 8 hex digits
// of a hash of the uncommitted changes to tracked files when there were any at build time;
// "unknown" when built outside a git checkout. Written into each run's config.json, so that a
// figure can be traced to the code that produced it and a run by other code is not reused.
const char* SourceRevision();

// 12 hex digits of a hash of the contents of the library's, the tools' and the build's source
// files, of the compiler and its flags, and of the versions of Eigen, Ceres, OpenCV and Embree
// (cmake/WriteSourceRevision.cmake). Two builds with the same fingerprint compute the same
// figures, whatever else differs between their commits (README, tests, manifests), so a
// finished run is reused exactly when it matches.
const char* CodeFingerprint();

// The same over the code that makes sequences alone: the simulator, the importers, the
// folders they build on (io, camera, geometry, util) and their tools. Recorded in each
// rendered or imported sequence.json and part of the cache's key, so that a sequence made by
// other code is made again rather than reused, while a change to tracking or mapping keeps it.
const char* SequenceCodeFingerprint();

// "nrslam <version> (revision <SourceRevision()>, code <CodeFingerprint()>)": what the tools
// print for --version and the benchmarks above their figures.
std::string VersionString();

}  // namespace nrslam
