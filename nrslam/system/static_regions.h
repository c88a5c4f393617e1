// system: the parts of a sequence's image that never change (an on-screen display, a black
// border without a mask), found window by window over the whole sequence, whatever part a run
// takes, and left out of each frame's mask. A display shown for a while only (a mode banner, a
// freeze indicator) is found in the windows it fills, and left out of their frames alone.
#pragma once

#include <opencv2/core.hpp>

#include <ostream>
#include <utility>
#include <vector>

#include "nrslam/frontend/frontend_options.h"
#include "nrslam/io/sequence_reader.h"

namespace nrslam {

// The frame ranges [first, last) looked at for static regions in a sequence of `frame_count`
// frames at `fps`: windows of `options.static_window_seconds` (and of at least
// MaskOptions::kMinStaticFrames frames), each starting half a window after the one before, the
// last one ending with the sequence; a single window over all of a sequence no longer than one.
// None when the check is off, or the sequence spans under `static_min_seconds` (tissue the
// camera barely moves past would pass for a display).
std::vector<std::pair<int, int>> StaticWindows(int frame_count, double fps, const MaskOptions& options);

class StaticRegions {
 public:
  StaticRegions() = default;
  // Looks at the windows of `reader`'s sequence (StaticWindows) that hold any of the frames
  // [first, last) a run takes: frontend FindStaticRegions over `static_frames` frames spread over
  // each, read from the whole window even where the run takes part of it; a window with more
  // than `static_max_fraction` of the image static is a still view and keeps all of it. Says in
  // `log` what it found and where, or why it did not look. Frames that cannot be read are passed
  // over here; a run reports them when it reaches them.
  static StaticRegions OfSequence(const SequenceReader& reader, const MaskOptions& options, int first, int last,
                                  std::ostream& log);

  // Non-zero where `frame` is left out: the regions of every window holding it. Empty when none.
  cv::Mat At(int frame) const;
  // Clears in `mask` (8-bit, the image's size; an empty one is made all usable first) what
  // `frame` leaves out, part by part: the per-frame path, which builds no image of the regions.
  void LeaveOut(int frame, cv::Mat* mask) const;
  // Every pixel left out on some frame (empty when none): the run's static_mask.png.
  cv::Mat Union() const;
  // Union()'s share of the image (0 when none).
  double Fraction() const;

 private:
  // A connected part of a span's regions, cropped to its box. A display is a few small shapes,
  // so each span of a long video holds kilobytes rather than an image.
  struct Patch {
    cv::Rect box;
    cv::Mat mask;  // the part's pixels within `box`
  };
  struct Span {
    int first = 0, last = 0;     // frames [first, last)
    std::vector<Patch> patches;  // never empty
  };
  // Adds frames [first, last), after every span so far, with their regions (not empty).
  void Append(int first, int last, const cv::Mat& regions);
  cv::Mat Regions(const Span& span) const;
  const Span* SpanOf(int frame) const;  // nullptr: nothing left out of `frame`
  cv::Size size_;
  std::vector<Span> spans_;  // in frame order, not overlapping
};

}  // namespace nrslam
