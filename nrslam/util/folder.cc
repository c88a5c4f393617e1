#include "nrslam/util/folder.h"

#include <string>
#include <system_error>

#include "nrslam/util/error.h"

namespace nrslam {

void CreateFolder(const std::filesystem::path& folder) {
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  if (!error) return;
  std::filesystem::path part;
  for (const std::filesystem::path& name : folder) {
    part /= name;
    std::error_code ignored;
    if (std::filesystem::exists(part, ignored) && !std::filesystem::is_directory(part, ignored)) {
      const std::string is_file = part.string() + " is a file, not a folder";
      throw Error(part == folder ? is_file : "cannot create " + folder.string() + ": " + is_file);
    }
  }
  throw Error("cannot create " + folder.string() + ": " + error.message());
}

}  // namespace nrslam
