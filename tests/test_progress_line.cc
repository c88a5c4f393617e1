// The tools' progress line: rewritten in place on a terminal, whole lines (the first, at most
// one per interval, the last) anywhere else.
#include <gtest/gtest.h>

#include <sstream>

#include "nrslam/util/progress_line.h"

namespace nrslam {
namespace {

TEST(ProgressLine, IntoAFileTheFirstAndLastUpdatesGetLinesAndTheRestWaitForTheInterval) {
  std::ostringstream out;
  ProgressLine progress(out, /*in_place=*/false, /*interval_s=*/3600);
  progress.Update("frame 1/4", false);
  progress.Update("frame 2/4", false);
  progress.Update("frame 3/4", false);
  progress.Update("frame 4/4", true);
  EXPECT_EQ(out.str(), "frame 1/4\nframe 4/4\n");
}

TEST(ProgressLine, IntoAFileWithNoIntervalEveryUpdateIsALine) {
  std::ostringstream out;
  ProgressLine progress(out, false, 0);
  for (const char* line : {"a", "b", "c"}) progress.Update(line, false);
  EXPECT_EQ(out.str(), "a\nb\nc\n");
}

TEST(ProgressLine, OnATerminalOneLineIsRewrittenAndBlankedWhereItShrinks) {
  std::ostringstream out;
  ProgressLine progress(out, /*in_place=*/true, 3600);
  progress.Update("frame 9/10", false);
  progress.Update("frame 10/10", false);
  progress.Update("done", true);
  progress.Update("next", true);  // after a finished line, a new one starts without padding
  EXPECT_EQ(out.str(), "\rframe 9/10\rframe 10/10\rdone       \n\rnext\n");
}

TEST(ProgressLine, OnATerminalAShrinkingLineIsBlankedByColumnsNotBytes) {
  std::ostringstream out;
  ProgressLine progress(out, /*in_place=*/true, 3600);
  progress.Update("sim-0-abcd", false);
  progress.Update("sim-0-\u00fc\u00fc", true);  // 8 columns in 10 bytes: 2 columns to blank
  EXPECT_EQ(out.str(), "\rsim-0-abcd\rsim-0-\u00fc\u00fc  \n");
}

}  // namespace
}  // namespace nrslam
