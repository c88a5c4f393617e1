// CSV as nrslam writes and reads it: every field round-trips, however awkward; a file cut
// inside a quoted field, or a row with fields missing, is refused with where it happened.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "nrslam/batch/run_folder.h"
#include "nrslam/util/csv.h"
#include "nrslam/util/error.h"
#include "temp_folder.h"

namespace nrslam {
namespace {

std::vector<std::vector<std::string>> ReadAll(const std::string& text, int* lines) {
  std::istringstream in(text);
  std::vector<std::vector<std::string>> records;
  std::vector<std::string> fields;
  *lines = 0;
  while (ReadCsvRecord(in, "test.csv", lines, &fields)) records.push_back(fields);
  return records;
}

TEST(Csv, AwkwardFieldsRoundTrip) {
  const std::vector<std::string> fields = {"plain", "", "a, b", "say \"hi\"", "two\nlines", "\"", "end,"};
  std::string line;
  for (size_t i = 0; i < fields.size(); ++i) line += (i ? "," : "") + CsvField(fields[i]);
  EXPECT_EQ(CsvField("plain"), "plain");  // quoted only when needed
  EXPECT_EQ(CsvField("say \"hi\""), "\"say \"\"hi\"\"\"");
  int lines = 0;
  const auto records = ReadAll("h\n" + line + "\n\nlast\n", &lines);
  ASSERT_EQ(records.size(), 3u);
  EXPECT_EQ(records[1], fields);
  EXPECT_EQ(records[2], std::vector<std::string>{"last"});  // the blank line passed over
  EXPECT_EQ(lines, 5);  // the record with a line break spans two lines
}

TEST(Csv, WindowsLineEndsByteOrderMarkAndEmptyFields) {
  int lines = 0;
  const auto records = ReadAll("\xEF\xBB\xBF" "a,b,c\r\n1,,\r\n\"x\r\ny\",2,3\r\n", &lines);
  ASSERT_EQ(records.size(), 3u);
  EXPECT_EQ(records[0], (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_EQ(records[1], (std::vector<std::string>{"1", "", ""}));
  EXPECT_EQ(records[2], (std::vector<std::string>{"x\ny", "2", "3"}));
}

TEST(Csv, AFileCutInsideAQuotedFieldIsRefused) {
  int lines = 0;
  try {
    ReadAll("a,b\n1,\"unfinished\n", &lines);
    ADD_FAILURE() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("test.csv:2: a quoted field is not closed"), std::string::npos) << e.what();
  }
}

// A run's metrics.csv whose notes hold commas reads back whole; a points.csv cut mid-row is
// refused rather than read with a truncated last number.
TEST(Csv, RunFilesReadByColumnAndCutShortOnesRefused) {
  const auto folder = UniqueTempFolder("csv_run_files");
  std::filesystem::create_directories(folder);
  std::ofstream(folder / "metrics.csv") << "frame,state,note\n0,not_initialised,"
                                        << CsvField("initialising: 204 E inliers, 0 triangulated") << "\n1,tracking,\n";
  const auto metrics = ReadCsv(folder / "metrics.csv");
  ASSERT_EQ(metrics.size(), 2u);
  EXPECT_EQ(metrics[0].at("note"), "initialising: 204 E inliers, 0 triangulated");
  EXPECT_EQ(metrics[1].at("state"), "tracking");
  EXPECT_EQ(metrics[1].at("note"), "");
  std::ofstream(folder / "points.csv") << "frame,point_id,u,v,z_est,x,y,z,status\n"
                                       << "0,1,10.5,20.5,47.6,7.2,16.2,47.6,tracked\n0,2,100,87,62.3099";
  try {
    ReadCsv(folder / "points.csv");
    ADD_FAILURE() << "a cut-short points.csv was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("points.csv:3: 5 fields where the header has 9"), std::string::npos)
        << e.what();
  }
  std::filesystem::remove_all(folder);
}

}  // namespace
}  // namespace nrslam
