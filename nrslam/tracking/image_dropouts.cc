#include "nrslam/tracking/image_dropouts.h"

#include <algorithm>
#include <cmath>

namespace nrslam {
namespace {

int Cell(float coordinate, int size, int grid) {
  if (!std::isfinite(coordinate)) return 0;
  return std::clamp(static_cast<int>(std::floor(coordinate * grid / size)), 0, grid - 1);
}

}  // namespace

bool ImageDropouts::Skip(const std::vector<LiveTrack>& tracks, cv::Size image_size, int min_found) {
  live_ = static_cast<int>(tracks.size());
  found_ = static_cast<int>(std::count_if(tracks.begin(), tracks.end(), [](const LiveTrack& t) { return t.found; }));
  counted_ = CountedLive(tracks, image_size);
  const bool too_few =
      found_ < min_found || (min_fraction_ > 0 && live_ > 0 && (found_ == 0 || found_ < min_fraction_ * counted_));
  in_a_row_ = too_few && in_a_row_ < max_in_a_row_ ? in_a_row_ + 1 : 0;
  return in_a_row_ > 0;
}

int ImageDropouts::CountedLive(const std::vector<LiveTrack>& tracks, cv::Size image_size) {
  const int grid =
      tracks_per_cell_ > 0
          ? std::max(1, static_cast<int>(std::lround(std::sqrt(static_cast<double>(tracks.size()) / tracks_per_cell_))))
          : 1;
  live_in_cell_.assign(grid * grid, 0);  // every frame: the buffers keep their capacity
  found_in_cell_.assign(grid * grid, false);
  for (const LiveTrack& track : tracks) {
    const int cell =
        Cell(track.last_pixel.y, image_size.height, grid) * grid + Cell(track.last_pixel.x, image_size.width, grid);
    ++live_in_cell_[cell];
    if (track.found) found_in_cell_[cell] = true;
  }
  int counted = 0;
  for (size_t cell = 0; cell < live_in_cell_.size(); ++cell) counted += found_in_cell_[cell] ? live_in_cell_[cell] : 0;
  return counted;
}

std::string ImageDropouts::Note(const std::string& counted, const std::string& kept) const {
  std::string share;
  if (counted_ > 0 && counted_ < live_) {  // none found: no part of the image to name
    share = std::to_string(found_) + " of the " + std::to_string(counted_) + " where any were found; ";
  }
  return "only " + std::to_string(found_) + " of " + std::to_string(live_) + " " + counted +
         ": skipped as an image dropout" + kept + " (" + share + std::to_string(in_a_row_) + " of at most " +
         std::to_string(max_in_a_row_) + " in a row)";
}

}  // namespace nrslam
