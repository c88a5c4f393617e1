// tracking: the image-dropout rule, shared by the tracker and the monocular initialiser.
//
// A frame on which the KLT finds too few of the live tracks (blank, saturated, noise) is
// skipped with everything kept, so that the next frame starts from where the last used one
// left the tracks; at most TrackingOptions::max_dropout_frames in a row, after which frames are
// used again whatever they hold.
#pragma once

#include <string>
#include <vector>

#include "nrslam/tracking/tracking_options.h"

namespace nrslam {

class ImageDropouts {
 public:
  // A track alive before this frame: whether the KLT found it now, and if so how well it
  // matched (KltResult::ssim and gain).
  struct LiveTrack {
    bool found;
    float ssim;
    float gain;
  };

  explicit ImageDropouts(const TrackingOptions& options)
      : max_in_a_row_(options.max_dropout_frames),
        min_fraction_(options.min_tracked_fraction),
        min_match_ssim_(options.dropout_min_match_ssim) {}

  // Whether to skip a frame on which the KLT found fewer than `min_found` of the live tracks,
  // or (with a min_tracked_fraction) none, or fewer than that fraction of them while those it
  // found match like chance: their median SSIM at most dropout_min_match_ssim, or their median
  // gain at one of the KLT's bounds (kKltMinGain, kKltMaxGain). The found tracks of a view that
  // an instrument partly hides match as well as on an intact frame, and such a frame is used. A
  // skip is counted, up to the allowance; a frame used ends the run of skips.
  bool Skip(const std::vector<LiveTrack>& tracks, int min_found);
  void Reset() { in_a_row_ = 0; }

  // The tracks found on the last frame given to Skip.
  int found() const { return found_; }
  // Whether that frame was used although under the share, because its found tracks matched
  // well: most of the view hidden at once (an instrument, fluid). Once per such occlusion, as
  // the tracks it hides are lost and no longer count as live on the next frame.
  bool SuddenOcclusion() const { return under_share_ && !too_few_; }

  // The last frame's note, for counted = "points tracked", kept = ", the map kept". Skipped:
  // "only 11 of 119 points tracked (median SSIM 0.80, gain 0.20): skipped as an image dropout,
  // the map kept (1 of at most 5 in a row)". Used under the share: "only 60 of 187 points
  // tracked, but they match well (median SSIM 0.97, gain 0.93): the view partly hidden, the frame
  // used". Used once the allowance is spent: "... (median SSIM 0.80, gain 0.20): used, the
  // allowance of 5 dropouts in a row spent". Empty for a frame with enough tracks.
  std::string Note(const std::string& counted, const std::string& kept) const;

 private:
  int max_in_a_row_;
  double min_fraction_;
  double min_match_ssim_;
  int in_a_row_ = 0;
  int live_ = 0, found_ = 0;
  bool under_share_ = false, too_few_ = false;
  float median_ssim_ = 0, median_gain_ = 1;
  std::vector<float> found_ssim_, found_gain_;  // re-filled every frame: they keep their capacity
};

}  // namespace nrslam
