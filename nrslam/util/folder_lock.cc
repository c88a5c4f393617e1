#include "nrslam/util/folder_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "nrslam/util/error.h"
#include "nrslam/util/folder.h"
#include "nrslam/util/text_file.h"

namespace nrslam {

FolderLock::FolderLock(const std::filesystem::path& folder, const std::string& holder) {
  CreateFolder(folder);
  const std::filesystem::path path = folder / ".lock";
  // Not close-on-exec: child processes share the lock, so that runs an evaluation started hold
  // the folder until they end even when the evaluation itself was killed.
  descriptor_ = ::open(path.c_str(), O_RDWR | O_CREAT, 0644);
  if (descriptor_ < 0) throw Error("cannot open " + path.string() + ": " + std::strerror(errno));
  if (::flock(descriptor_, LOCK_EX | LOCK_NB) != 0) {
    const int reason = errno;
    ::close(descriptor_);
    descriptor_ = -1;
    if (reason != EWOULDBLOCK) throw Error("cannot lock " + path.string() + ": " + std::strerror(reason));
    const std::string other = FileText(path);
    throw Error(folder.string() + " is in use by another process (" + (other.empty() ? "unknown" : other) +
                ", or a process it started); wait for it to end, or give another output folder");
  }
  // Who holds it, for the message of the next one to try; the lock holds even if this fails.
  const std::string text = holder + ", pid " + std::to_string(::getpid());
  [[maybe_unused]] const int truncated = ::ftruncate(descriptor_, 0);
  [[maybe_unused]] const ssize_t written = ::write(descriptor_, text.data(), text.size());
}

FolderLock::~FolderLock() {
  if (descriptor_ >= 0) ::close(descriptor_);  // closing releases the lock
}

}  // namespace nrslam
