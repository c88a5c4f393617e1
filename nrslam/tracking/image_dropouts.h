// tracking: the image-dropout rule, shared by the tracker and the monocular initialiser.
//
// A frame on which the KLT finds too few of the live tracks (blank, saturated, noise) is
// skipped with everything kept, so that the next frame starts from where the last used one
// left the tracks; at most TrackingOptions::max_dropout_frames in a row, after which frames are
// used again whatever they hold.
#pragma once

#include <string>

#include "nrslam/tracking/tracking_options.h"

namespace nrslam {

class ImageDropouts {
 public:
  explicit ImageDropouts(const TrackingOptions& options)
      : max_in_a_row_(options.max_dropout_frames), min_fraction_(options.min_tracked_fraction) {}

  // Whether to skip a frame on which `found` of `live` tracks were found: fewer than
  // `min_found`, or than the options' min_tracked_fraction of them, while the allowance lasts.
  // A skip is counted; a frame used ends the run of skips.
  bool Skip(int found, int live, int min_found) {
    const bool too_few = found < min_found || found < min_fraction_ * live;
    in_a_row_ = too_few && in_a_row_ < max_in_a_row_ ? in_a_row_ + 1 : 0;
    return in_a_row_ > 0;
  }
  void Reset() { in_a_row_ = 0; }

  // The skipped frame's note: "only 11 of 119 points tracked: skipped as an image dropout, the
  // map kept (1 of at most 5 in a row)" for counted = "points tracked", kept = ", the map kept".
  std::string Note(int found, int live, const std::string& counted, const std::string& kept) const {
    return "only " + std::to_string(found) + " of " + std::to_string(live) + " " + counted +
           ": skipped as an image dropout" + kept + " (" + std::to_string(in_a_row_) + " of at most " +
           std::to_string(max_in_a_row_) + " in a row)";
  }

 private:
  int max_in_a_row_;
  double min_fraction_;
  int in_a_row_ = 0;
};

}  // namespace nrslam
