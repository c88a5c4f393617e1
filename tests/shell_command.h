// Tests: runs a shell command the way a user would type it, for tests that drive the programs.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>
#include <utility>

#include "nrslam/util/text_file.h"

namespace nrslam {

// Runs a shell command with its standard output and error caught in `log`: its exit status and
// what it printed.
inline std::pair<int, std::string> RunCaught(const std::string& command, const std::filesystem::path& log) {
  const int status = std::system((command + " > " + log.string() + " 2>&1").c_str());
  return {status, FileText(log)};
}

}  // namespace nrslam
