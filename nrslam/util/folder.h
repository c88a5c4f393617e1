// util: creating the folders a program writes into. std::filesystem's own error reads "cannot
// create directories: Not a directory [a/b/c]", which does not say that a/b is a file.
#pragma once

#include <filesystem>

namespace nrslam {

// Creates `folder` and any missing parents (nothing when it exists). Throws Error naming the part
// of the path that is a file ("PATH is a file, not a folder"), or else the folder and the
// system's reason (a read-only or full disk).
void CreateFolder(const std::filesystem::path& folder);

}  // namespace nrslam
