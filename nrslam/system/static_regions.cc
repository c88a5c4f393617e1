#include "nrslam/system/static_regions.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>

#include "nrslam/frontend/masks.h"
#include "nrslam/util/concurrent.h"
#include "nrslam/util/error.h"
#include "nrslam/util/text_table.h"

namespace nrslam {
namespace {

// The grey images of `samples` frames spread evenly over [first, last), those that can be read.
// Decoding takes most of the check's time: each core decodes every other frame.
std::vector<cv::Mat> ReadSpreadGreys(const SequenceReader& reader, int first, int last, int samples) {
  std::vector<cv::Mat> greys(static_cast<size_t>(samples));
  const int span = last - first;
  const auto read_every_other = [&](int parity) {
    for (int k = parity; k < samples; k += 2) {
      const int frame = first + static_cast<int>(static_cast<int64_t>(k) * (span - 1) / (samples - 1));
      try {
        greys[static_cast<size_t>(k)] = ToGrey(reader.ReadRgb(frame));
      } catch (const Error&) {
      }
    }
  };
  RunConcurrently([&] { read_every_other(0); }, [&] { read_every_other(1); });
  greys.erase(std::remove_if(greys.begin(), greys.end(), [](const cv::Mat& grey) { return grey.empty(); }),
              greys.end());
  return greys;
}

// A window's frames [first, last) and what it found static there.
struct Window {
  int first = 0, last = 0;
  cv::Mat regions;
};

double ShareOfImage(const cv::Mat& regions) {
  return regions.empty() ? 0.0 : cv::countNonZero(regions) / static_cast<double>(regions.total());
}

std::string FrameRange(int first, int last) {
  return "frames " + std::to_string(first) + "-" + std::to_string(last - 1);
}

}  // namespace

std::vector<std::pair<int, int>> StaticWindows(int frame_count, double fps, const MaskOptions& options) {
  if (options.static_frames == 0 || frame_count <= 0 || frame_count / fps < options.static_min_seconds) return {};
  // At a low frame rate (a capsule's 1-2 fps) a window still holds the frames a verdict needs.
  const int length =
      std::max(MaskOptions::kMinStaticFrames, static_cast<int>(std::lround(options.static_window_seconds * fps)));
  if (frame_count <= length) return {{0, frame_count}};
  const int step = std::max(1, length / 2);
  std::vector<std::pair<int, int>> windows;
  for (int first = 0; first + length < frame_count; first += step) windows.emplace_back(first, first + length);
  windows.emplace_back(frame_count - length, frame_count);
  return windows;
}

StaticRegions StaticRegions::OfSequence(const SequenceReader& reader, const MaskOptions& options, int first_run_frame,
                                        int last_run_frame, std::ostream& log) {
  StaticRegions found;
  if (options.static_frames == 0) return found;
  const double seconds = reader.frame_count() / reader.info().fps;
  if (seconds < options.static_min_seconds) {
    log << "not looked for regions that never change (an on-screen display): the sequence spans "
        << FormatFixed(seconds, 1) << " s, under static_min_seconds = " << FormatFixed(options.static_min_seconds, 1)
        << " s\n";
    return found;
  }
  if (reader.frame_count() < MaskOptions::kMinStaticFrames) {
    log << "not looked for regions that never change (an on-screen display): " << reader.frame_count()
        << " frames, under the " << MaskOptions::kMinStaticFrames << " that can tell\n";
    return found;
  }
  // Windows come in frame order, so the frames before a window's first are final once it comes:
  // their spans are made then, and only the windows that may still share frames with later
  // ones are kept whole (at most three), whatever the sequence's length.
  std::vector<Window> open;  // windows with regions that end after `done`
  int done = 0;              // frames before this have their spans
  const auto close_until = [&](int until) {
    std::set<int> bounds{done, until};
    for (const Window& window : open) {
      for (int bound : {window.first, window.last}) {
        if (bound > done && bound < until) bounds.insert(bound);
      }
    }
    for (auto bound = bounds.begin(); std::next(bound) != bounds.end(); ++bound) {
      // A frame in two windows loses what either found.
      cv::Mat regions;
      for (const Window& window : open) {
        if (window.first > *bound || window.last < *std::next(bound)) continue;
        if (regions.empty()) {
          regions = window.regions.clone();
        } else {
          regions |= window.regions;
        }
      }
      if (!regions.empty()) found.Append(*bound, *std::next(bound), regions);
    }
    done = until;
    open.erase(std::remove_if(open.begin(), open.end(), [&](const Window& window) { return window.last <= done; }),
               open.end());
  };
  for (const auto& [first, last] : StaticWindows(reader.frame_count(), reader.info().fps, options)) {
    if (last <= first_run_frame || first >= last_run_frame) continue;  // none of the run's frames
    close_until(first);
    // A window holds at least kMinStaticFrames frames, and static_frames is at least that.
    const std::vector<cv::Mat> greys =
        ReadSpreadGreys(reader, first, last, std::min(options.static_frames, last - first));
    if (greys.size() < static_cast<size_t>(MaskOptions::kMinStaticFrames)) continue;
    cv::Mat regions = FindStaticRegions(greys, reader.fixed_mask(), options);
    const double share = ShareOfImage(regions);
    if (share > options.static_max_fraction) {
      log << FrameRange(first, last) << ": " << std::lround(100 * share)
          << " % of the image never changed: a still view rather than a display, so none of it was left out\n";
    } else if (share > 0) {
      log << FrameRange(first, last) << ": " << FormatFixed(100 * share, 1)
          << " % of the image never changed and is left out of them\n";
      open.push_back({first, last, std::move(regions)});
    }
  }
  close_until(reader.frame_count());
  return found;
}

void StaticRegions::Append(int first, int last, const cv::Mat& regions) {
  size_ = regions.size();
  cv::Mat labels, stats, centroids;
  const int parts = cv::connectedComponentsWithStats(regions, labels, stats, centroids, 8, CV_32S);
  Span span{first, last, {}};
  for (int part = 1; part < parts; ++part) {
    const cv::Rect box(stats.at<int>(part, cv::CC_STAT_LEFT), stats.at<int>(part, cv::CC_STAT_TOP),
                       stats.at<int>(part, cv::CC_STAT_WIDTH), stats.at<int>(part, cv::CC_STAT_HEIGHT));
    span.patches.push_back(Patch{box, cv::Mat(labels(box) == part)});
  }
  spans_.push_back(std::move(span));
}

cv::Mat StaticRegions::Regions(const Span& span) const {
  cv::Mat regions(size_, CV_8UC1, cv::Scalar(0));
  for (const Patch& patch : span.patches) regions(patch.box) |= patch.mask;
  return regions;
}

const StaticRegions::Span* StaticRegions::SpanOf(int frame) const {
  for (const Span& span : spans_) {
    if (frame >= span.first && frame < span.last) return &span;
  }
  return nullptr;
}

cv::Mat StaticRegions::At(int frame) const {
  const Span* span = SpanOf(frame);
  return span ? Regions(*span) : cv::Mat();
}

void StaticRegions::LeaveOut(int frame, cv::Mat* mask) const {
  const Span* span = SpanOf(frame);
  if (!span) return;
  if (mask->empty()) *mask = cv::Mat(size_, CV_8UC1, cv::Scalar(255));
  for (const Patch& patch : span->patches) (*mask)(patch.box).setTo(0, patch.mask);
}

cv::Mat StaticRegions::Union() const {
  cv::Mat all;
  for (const Span& span : spans_) {
    if (all.empty()) {
      all = Regions(span);
    } else {
      all |= Regions(span);
    }
  }
  return all;
}

double StaticRegions::Fraction() const { return ShareOfImage(Union()); }

}  // namespace nrslam
