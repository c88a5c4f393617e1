// Tests: a temporary folder unique to this process. CTest runs test cases as parallel
// processes, so fixed names would race.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

namespace nrslam {

inline std::filesystem::path UniqueTempFolder(const std::string& name) {
  return std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()));
}

}  // namespace nrslam
