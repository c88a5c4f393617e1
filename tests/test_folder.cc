// An output folder is created with its parents, or the error names what is in the way: a file
// where a folder of the path should be, or the system's reason.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "error_message.h"
#include "nrslam/util/folder.h"
#include "nrslam/util/text_file.h"
#include "temp_folder.h"

namespace nrslam {
namespace {

std::string CreateFolderError(const std::filesystem::path& folder) {
  return ErrorMessage([&] { CreateFolder(folder); });
}

TEST(Folder, CreatesItsParentsAndAcceptsOneThatExists) {
  const auto root = UniqueTempFolder("folder_nested");
  std::filesystem::remove_all(root);
  CreateFolder(root / "a" / "b");
  EXPECT_TRUE(std::filesystem::is_directory(root / "a" / "b"));
  WriteTextFile(root / "a" / "b" / "kept.txt", "x");
  CreateFolder(root / "a" / "b");
  EXPECT_EQ(FileText(root / "a" / "b" / "kept.txt"), "x");
  std::filesystem::remove_all(root);
}

TEST(Folder, AFileInThePathIsNamed) {
  const auto root = UniqueTempFolder("folder_file");
  std::filesystem::remove_all(root);
  CreateFolder(root);
  WriteTextFile(root / "out", "not a folder");
  EXPECT_EQ(CreateFolderError(root / "out"), (root / "out").string() + " is a file, not a folder");
  EXPECT_EQ(CreateFolderError(root / "out" / "run" / "depth"),
            "cannot create " + (root / "out" / "run" / "depth").string() + ": " + (root / "out").string() +
                " is a file, not a folder");
  EXPECT_EQ(FileText(root / "out"), "not a folder");
  std::filesystem::remove_all(root);
}

TEST(Folder, TheSystemsReasonIsGivenOtherwise) {
  // /proc takes no new folders, even from root.
  const std::string error = CreateFolderError("/proc/nrslam_test_folder/run");
  EXPECT_EQ(error.rfind("cannot create /proc/nrslam_test_folder/run: ", 0), 0u) << error;
  EXPECT_GT(error.size(), std::string("cannot create /proc/nrslam_test_folder/run: ").size());
}

}  // namespace
}  // namespace nrslam
