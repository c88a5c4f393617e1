// The image-dropout rule (tracking/image_dropouts.h) on known sets of tracks.
#include <gtest/gtest.h>

#include <vector>

#include "nrslam/frontend/klt_tracker.h"
#include "nrslam/tracking/image_dropouts.h"

namespace nrslam {
namespace {

constexpr int kLive = 256;

// kLive tracks, of which every `every`-th one up to `found` is found with these scores.
std::vector<ImageDropouts::LiveTrack> Tracks(int found, float ssim, float gain) {
  std::vector<ImageDropouts::LiveTrack> tracks(kLive, {false, 0.f, 1.f});
  for (int i = 0; i < found; ++i) tracks[static_cast<size_t>(i * kLive / found)] = {true, ssim, gain};
  return tracks;
}

// Noise: a quarter of the tracks lock onto chance patterns, which match like chance (median SSIM
// near the KLT's threshold) and need the most gain the fit allows (0.2 on bright noise, 5 on a
// near-black frame). Each of the two is enough.
TEST(ImageDropouts, ChanceMatchesUnderTheShareMakeADropout) {
  ImageDropouts dropouts{TrackingOptions{}};
  EXPECT_TRUE(dropouts.Skip(Tracks(64, 0.80f, kKltMinGain), 10));
  EXPECT_EQ(dropouts.Note("points tracked", ", the map kept"),
            "only 64 of 256 points tracked (median SSIM 0.80, gain 0.20): skipped as an image dropout, the map kept "
            "(1 of at most 5 in a row)");
  ImageDropouts dark{TrackingOptions{}};
  EXPECT_TRUE(dark.Skip(Tracks(64, 0.95f, kKltMaxGain), 10));
  ImageDropouts faint_match{TrackingOptions{}};
  EXPECT_TRUE(faint_match.Skip(Tracks(64, 0.85f, 1.0f), 10));
}

// An instrument hides 5/8 of the view: 96 of 256 tracks are found, and they match as on an
// intact frame. The frame is used as a sudden occlusion, and the note says why; with the
// threshold at 1 it is skipped.
TEST(ImageDropouts, WellMatchedTracksOfAPartlyHiddenViewAreUsed) {
  const auto tracks = Tracks(96, 0.97f, 0.93f);
  ImageDropouts dropouts{TrackingOptions{}};
  EXPECT_FALSE(dropouts.Skip(tracks, 10));
  EXPECT_EQ(dropouts.Note("points tracked", ", the map kept"),
            "only 96 of 256 points tracked, but they match well (median SSIM 0.97, gain 0.93): the view partly "
            "hidden, the frame used");
  EXPECT_TRUE(dropouts.SuddenOcclusion());
  TrackingOptions strict;
  strict.dropout_min_match_ssim = 1;
  ImageDropouts skipping(strict);
  EXPECT_TRUE(skipping.Skip(tracks, 10));
  EXPECT_FALSE(skipping.SuddenOcclusion());
  // The medians decide, not a few chance matches among the found tracks.
  auto mixed = tracks;
  int chance = 0;
  for (auto& track : mixed) {
    if (track.found && chance++ < 40) track = {true, 0.76f, kKltMaxGain};
  }
  ImageDropouts robust{TrackingOptions{}};
  EXPECT_FALSE(robust.Skip(mixed, 10));
  // Too few for min_found is a dropout however well they match.
  EXPECT_TRUE(robust.Skip(Tracks(8, 0.99f, 1.0f), 10));
}

// A blank frame finds nothing: a dropout even with no minimum count (the initialiser's case),
// unless the share rule is off. A frame with enough tracks has no note.
TEST(ImageDropouts, NoTrackFoundIsADropoutUnlessTheShareRuleIsOff) {
  const auto none = Tracks(0, 0.f, 1.f);
  ImageDropouts dropouts{TrackingOptions{}};
  EXPECT_TRUE(dropouts.Skip(none, 0));
  EXPECT_EQ(dropouts.Note("tracks found", ""),
            "only 0 of 256 tracks found: skipped as an image dropout (1 of at most 5 in a row)");
  EXPECT_FALSE(dropouts.Skip(Tracks(200, 0.99f, 0.95f), 0));
  EXPECT_EQ(dropouts.Note("tracks found", ""), "");
  EXPECT_FALSE(dropouts.SuddenOcclusion());
  TrackingOptions off;
  off.min_tracked_fraction = 0;
  ImageDropouts count_only(off);
  EXPECT_FALSE(count_only.Skip(none, 0));
  EXPECT_TRUE(count_only.Skip(none, 10));
  // No live track at all: only the minimum count can make it a dropout.
  ImageDropouts empty{TrackingOptions{}};
  EXPECT_FALSE(empty.Skip({}, 0));
}

// At most max_dropout_frames in a row; a frame used starts the count again.
TEST(ImageDropouts, TheAllowanceRunsOutAndStartsAgain) {
  TrackingOptions options;
  options.max_dropout_frames = 2;
  ImageDropouts dropouts(options);
  const auto noise = Tracks(52, 0.79f, kKltMinGain);
  const auto intact = Tracks(kLive, 0.99f, 0.97f);
  EXPECT_TRUE(dropouts.Skip(noise, 10));
  EXPECT_TRUE(dropouts.Skip(noise, 10));
  EXPECT_FALSE(dropouts.Skip(noise, 10));  // used, whatever it holds
  EXPECT_EQ(dropouts.Note("points tracked", ""),
            "only 52 of 256 points tracked (median SSIM 0.79, gain 0.20): used, the allowance of 2 dropouts in a row "
            "spent");
  EXPECT_FALSE(dropouts.SuddenOcclusion());  // used for want of a choice, not for its matches
  EXPECT_TRUE(dropouts.Skip(noise, 10));
  EXPECT_FALSE(dropouts.Skip(intact, 10));
  EXPECT_TRUE(dropouts.Skip(noise, 10));
  dropouts.Reset();
  EXPECT_TRUE(dropouts.Skip(noise, 10));
  EXPECT_EQ(dropouts.Note("tracks found", ""),
            "only 52 of 256 tracks found (median SSIM 0.79, gain 0.20): skipped as an image dropout (1 of at most 2 "
            "in a row)");
}

}  // namespace
}  // namespace nrslam
