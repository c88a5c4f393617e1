// The image-dropout rule (tracking/image_dropouts.h) on known layouts of tracks.
#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

#include "nrslam/tracking/image_dropouts.h"

namespace nrslam {
namespace {

const cv::Size kImage(640, 480);

// 16 × 16 tracks on a regular lattice over the image, found where `found` says.
std::vector<ImageDropouts::LiveTrack> Lattice(const std::function<bool(float x, float y, int index)>& found) {
  std::vector<ImageDropouts::LiveTrack> tracks;
  for (int row = 0; row < 16; ++row) {
    for (int col = 0; col < 16; ++col) {
      const float x = 20.0f + 40.0f * col, y = 15.0f + 30.0f * row;
      tracks.push_back({cv::Point2f(x, y), found(x, y, row * 16 + col)});
    }
  }
  return tracks;
}

// 256 tracks at this many a cell: a grid of 8 × 8 cells at 4, 4 × 4 at 16; 0: the whole image.
TrackingOptions WithTracksPerCell(int tracks) {
  TrackingOptions options;
  options.dropout_tracks_per_cell = tracks;
  return options;
}

// Noise: a quarter of the tracks pass, on diagonals over the whole image. Every cell of these
// grids holds a found one, so every track counts, and the frame is a dropout on any of them.
TEST(ImageDropouts, ChanceTracksAllOverTheImageMakeADropout) {
  const auto tracks = Lattice([](float, float, int index) { return (index / 16 + index % 16) % 4 == 0; });
  for (int tracks_per_cell : {0, 16, 4}) {
    ImageDropouts dropouts(WithTracksPerCell(tracks_per_cell));
    EXPECT_TRUE(dropouts.Skip(tracks, kImage, 10)) << tracks_per_cell;
    EXPECT_EQ(dropouts.Note("points tracked", ""),
              "only 64 of 256 points tracked: skipped as an image dropout (1 of at most 5 in a row)");
  }
}

// An instrument over the right 5/8 of the view: every track left of x = 240 is found, none
// right of it. On a 4 × 4 grid the share counts the two left columns of cells (128 tracks, 96
// found: 75 %) and the frame is used; over the whole image 96 of 256 is a dropout.
TEST(ImageDropouts, TracksHiddenByAnInstrumentDoNotCount) {
  const auto tracks = Lattice([](float x, float, int) { return x < 240; });
  ImageDropouts gridded(WithTracksPerCell(16));
  EXPECT_FALSE(gridded.Skip(tracks, kImage, 10));
  ImageDropouts whole(WithTracksPerCell(0));
  EXPECT_TRUE(whole.Skip(tracks, kImage, 10));
  EXPECT_EQ(whole.Note("points tracked", ", the map kept"),
            "only 96 of 256 points tracked: skipped as an image dropout, the map kept (1 of at most 5 in a row)");

  // A smaller share of the visible part is still a dropout, and the note says what was counted.
  const auto sparse = Lattice([](float x, float, int index) { return x < 240 && index % 3 == 0; });
  ImageDropouts dropouts(WithTracksPerCell(16));
  EXPECT_TRUE(dropouts.Skip(sparse, kImage, 10));
  EXPECT_EQ(dropouts.Note("points tracked", ""),
            "only 32 of 256 points tracked: skipped as an image dropout (32 of the 128 where any were found; "
            "1 of at most 5 in a row)");
}

// A blank frame finds nothing: a dropout even with no minimum count (the initialiser's case),
// unless the share rule is off.
TEST(ImageDropouts, NoTrackFoundIsADropoutUnlessTheShareRuleIsOff) {
  const auto none = Lattice([](float, float, int) { return false; });
  ImageDropouts dropouts(WithTracksPerCell(16));
  EXPECT_TRUE(dropouts.Skip(none, kImage, 0));
  EXPECT_EQ(dropouts.Note("tracks found", ""),
            "only 0 of 256 tracks found: skipped as an image dropout (1 of at most 5 in a row)");
  TrackingOptions off = WithTracksPerCell(16);
  off.min_tracked_fraction = 0;
  ImageDropouts count_only(off);
  EXPECT_FALSE(count_only.Skip(none, kImage, 0));
  EXPECT_TRUE(count_only.Skip(none, kImage, 10));
  // No live track at all: only the minimum count can make it a dropout.
  ImageDropouts empty(WithTracksPerCell(16));
  EXPECT_FALSE(empty.Skip({}, kImage, 0));
}

// At most max_dropout_frames in a row; a frame used starts the count again.
TEST(ImageDropouts, TheAllowanceRunsOutAndStartsAgain) {
  TrackingOptions options = WithTracksPerCell(16);
  options.max_dropout_frames = 2;
  ImageDropouts dropouts(options);
  const auto noise = Lattice([](float, float, int index) { return index % 5 == 0; });
  const auto intact = Lattice([](float, float, int) { return true; });
  EXPECT_TRUE(dropouts.Skip(noise, kImage, 10));
  EXPECT_TRUE(dropouts.Skip(noise, kImage, 10));
  EXPECT_FALSE(dropouts.Skip(noise, kImage, 10));  // used, whatever it holds
  EXPECT_TRUE(dropouts.Skip(noise, kImage, 10));
  EXPECT_FALSE(dropouts.Skip(intact, kImage, 10));
  EXPECT_TRUE(dropouts.Skip(noise, kImage, 10));
  dropouts.Reset();
  EXPECT_TRUE(dropouts.Skip(noise, kImage, 10));
  EXPECT_EQ(dropouts.Note("tracks found", ""),
            "only 52 of 256 tracks found: skipped as an image dropout (1 of at most 2 in a row)");
}

}  // namespace
}  // namespace nrslam
