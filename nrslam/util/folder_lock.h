// util: one process at a time writing into a folder.
//
// Two evaluations started into the same output folder (a sweep launched twice, a resume while
// the first still runs) would run the same runs into the same run folders at once and leave
// results that mix both. The lock is advisory (flock on <folder>/.lock) and shared with the
// holder's child processes: the kernel drops it when the holder and every child it started
// have ended, however they end, so it is never left stale and never dropped while a run of a
// killed evaluation still writes.
#pragma once

#include <filesystem>
#include <string>

namespace nrslam {

class FolderLock {
 public:
  // Takes the lock on `folder` (created if missing) for `holder`, a description such as
  // "nrslam_eval data_manifests/ci-sim.json". Throws Error naming the process that took it.
  FolderLock(const std::filesystem::path& folder, const std::string& holder);
  ~FolderLock();
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

 private:
  int descriptor_ = -1;
};

}  // namespace nrslam
