// A whole text file is written whole or not at all, and a file that cannot be written is an
// error rather than a silently missing or short one. Read whole, it comes back byte for byte;
// opened to read, a folder in its place is named as one.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "nrslam/util/error.h"
#include "nrslam/util/text_file.h"
#include "temp_folder.h"

namespace nrslam {
namespace {

TEST(TextFile, ReplacesTheWholeFileAndLeavesNothingElse) {
  const auto folder = UniqueTempFolder("text_file");
  std::filesystem::create_directories(folder);
  WriteTextFile(folder / "results.csv", "a,b\n1,2\n3,4\n");
  WriteTextFile(folder / "results.csv", "a,b\n5,6\n");
  EXPECT_EQ(FileText(folder / "results.csv"), "a,b\n5,6\n");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(folder), {}), 1);  // no temporary left
  std::filesystem::remove_all(folder);
}

TEST(TextFile, AFileThatCannotBeWrittenIsAnError) {
  const auto folder = UniqueTempFolder("text_file_missing");
  std::filesystem::remove_all(folder);
  try {
    WriteTextFile(folder / "results.json", "{}\n");
    ADD_FAILURE() << "wrote into a folder that does not exist";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot write " + (folder / "results.json").string()), std::string::npos)
        << e.what();
  }
  std::filesystem::remove_all(folder);
}

TEST(TextFile, ReadsEveryByteAsWrittenAndNothingFromAMissingFile) {
  const auto folder = UniqueTempFolder("text_file_read");
  std::filesystem::create_directories(folder);
  // Line ends, a NUL and no final newline: nothing translated, nothing cut at the NUL.
  const std::string bytes = std::string("line\r\nnul:") + '\0' + "end";
  WriteTextFile(folder / "log.txt", bytes);
  EXPECT_EQ(FileText(folder / "log.txt"), bytes);
  EXPECT_EQ(FileText(folder / "log.txt").size(), 14u);
  EXPECT_EQ(FileText(folder / "absent.txt"), "");
  EXPECT_EQ(FileText(folder), "");  // a folder is not a file's text
  std::filesystem::remove_all(folder);
}

TEST(TextFile, OpensToReadOrSaysWhyNot) {
  const auto folder = UniqueTempFolder("text_file_open");
  std::filesystem::create_directories(folder);
  WriteTextFile(folder / "points.csv", "frame,u\n0,1\n");
  std::ifstream file = OpenToRead(folder / "points.csv", "CSV file");
  std::string header;
  EXPECT_TRUE(std::getline(file, header));
  EXPECT_EQ(header, "frame,u");
  auto message = [](const std::filesystem::path& path) {
    try {
      OpenToRead(path, "CSV file");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("opened");
  };
  EXPECT_EQ(message(folder / "absent.csv"), "cannot open " + (folder / "absent.csv").string());
  EXPECT_EQ(message(folder), folder.string() + " is a folder, not a CSV file");
  std::filesystem::remove_all(folder);
}

}  // namespace
}  // namespace nrslam
