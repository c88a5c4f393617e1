// tracking: the image-dropout rule, shared by the tracker and the monocular initialiser.
//
// A frame on which the KLT finds too few of the live tracks (blank, saturated, noise) is
// skipped with everything kept, so that the next frame starts from where the last used one
// left the tracks; at most TrackingOptions::max_dropout_frames in a row, after which frames are
// used again whatever they hold.
#pragma once

#include <opencv2/core/types.hpp>

#include <string>
#include <vector>

#include "nrslam/tracking/tracking_options.h"

namespace nrslam {

class ImageDropouts {
 public:
  // A track alive before this frame: where it was last, and whether the KLT found it now.
  struct LiveTrack {
    cv::Point2f last_pixel;
    bool found;
  };

  explicit ImageDropouts(const TrackingOptions& options)
      : max_in_a_row_(options.max_dropout_frames),
        min_fraction_(options.min_tracked_fraction),
        tracks_per_cell_(options.dropout_tracks_per_cell) {}

  // Whether to skip a frame of `image_size` on which the KLT found fewer than `min_found` of
  // the live tracks, or (with a min_tracked_fraction) none, or fewer than that fraction of those
  // it counts, while the allowance lasts. It counts the live tracks in the cells of a grid over
  // the image that hold a found one, the grid holding about dropout_tracks_per_cell live tracks
  // a cell: noise lets a few chance tracks through all over the image and leaves nearly every
  // track counted, whereas an instrument or a mask over part of the view takes the tracks it
  // hides out of the count. A skip is counted; a frame used ends the run of skips.
  bool Skip(const std::vector<LiveTrack>& tracks, cv::Size image_size, int min_found);
  void Reset() { in_a_row_ = 0; }

  // The tracks found on the last frame given to Skip.
  int found() const { return found_; }

  // The last skipped frame's note: "only 11 of 119 points tracked: skipped as an image dropout,
  // the map kept (1 of at most 5 in a row)" for counted = "points tracked", kept = ", the map
  // kept"; when the share counted some but not all of them, "(11 of the 100 where any were found;
  // 1 of at most 5 in a row)".
  std::string Note(const std::string& counted, const std::string& kept) const;

 private:
  // The live tracks in the cells that hold a found one.
  int CountedLive(const std::vector<LiveTrack>& tracks, cv::Size image_size);

  int max_in_a_row_;
  double min_fraction_;
  int tracks_per_cell_;
  int in_a_row_ = 0;
  int live_ = 0, found_ = 0, counted_ = 0;
  std::vector<int> live_in_cell_;
  std::vector<bool> found_in_cell_;
};

}  // namespace nrslam
