#include "nrslam/util/text_file.h"

#include <unistd.h>

#include <fstream>
#include <iterator>
#include <system_error>

#include "nrslam/util/error.h"

namespace nrslam {

void WriteTextFile(const std::filesystem::path& path, const std::string& text) {
  // A name of this process's own: no other writer's temporary file is taken for this one.
  std::filesystem::path partial = path;
  partial += ".partial-" + std::to_string(getpid());
  std::ofstream file(partial, std::ios::binary);
  file << text;
  file.close();  // a full disk may show only when the last buffer is written
  std::error_code error;
  if (!file.fail()) std::filesystem::rename(partial, path, error);
  if (file.fail() || error) {
    std::error_code ignored;
    std::filesystem::remove(partial, ignored);
    throw Error("cannot write " + path.string() + (error ? ": " + error.message() : ""));
  }
}

void CloseWritten(std::ofstream& file, const std::filesystem::path& path) {
  file.close();
  if (file.fail()) throw Error("cannot write " + path.string() + " (is the disk full?)");
}

std::ifstream OpenToRead(const std::filesystem::path& path, const std::string& kind) {
  std::error_code ignored;
  if (std::filesystem::is_directory(path, ignored)) throw Error(path.string() + " is a folder, not a " + kind);
  std::ifstream file(path);
  if (!file) throw Error("cannot open " + path.string());
  return file;
}

std::string FileText(const std::filesystem::path& path) {
  std::error_code ignored;
  if (std::filesystem::is_directory(path, ignored)) return "";  // opens as a file, then throws on reading
  std::ifstream file(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(file), {});
}

}  // namespace nrslam
