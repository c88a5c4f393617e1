// Tests: the whole content of a file, for tests that check what a program or a writer wrote.
#pragma once

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace nrslam {

// Every byte of `path`, as written; "" when it cannot be opened (the caller's assertions say
// what was expected).
inline std::string FileText(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(file), {});
}

}  // namespace nrslam
