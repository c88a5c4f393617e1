#include "nrslam/tracking/image_dropouts.h"

#include <cstdio>

#include "nrslam/frontend/klt_tracker.h"
#include "nrslam/util/median.h"

namespace nrslam {

bool ImageDropouts::Skip(const std::vector<LiveTrack>& tracks, int min_found) {
  found_ssim_.clear();
  found_gain_.clear();
  for (const LiveTrack& track : tracks) {
    if (!track.found) continue;
    found_ssim_.push_back(track.ssim);
    found_gain_.push_back(track.gain);
  }
  live_ = static_cast<int>(tracks.size());
  found_ = static_cast<int>(found_ssim_.size());
  median_ssim_ = found_ > 0 ? MedianInPlace(&found_ssim_) : 0.f;
  median_gain_ = found_ > 0 ? MedianInPlace(&found_gain_) : 1.f;
  under_share_ = min_fraction_ > 0 && live_ > 0 && found_ < min_fraction_ * live_;
  // A median at a bound means more than half of the found tracks needed the most correction the
  // fit allows: their windows hold much fainter or stronger texture than the references.
  const bool match_well =
      found_ > 0 && median_ssim_ > min_match_ssim_ && median_gain_ > kKltMinGain && median_gain_ < kKltMaxGain;
  too_few_ = found_ < min_found || (under_share_ && !match_well);
  in_a_row_ = too_few_ && in_a_row_ < max_in_a_row_ ? in_a_row_ + 1 : 0;
  return in_a_row_ > 0;
}

std::string ImageDropouts::Note(const std::string& counted, const std::string& kept) const {
  if (!too_few_ && !under_share_) return "";
  std::string text = "only " + std::to_string(found_) + " of " + std::to_string(live_) + " " + counted;
  char scores[64] = "";
  if (found_ > 0) std::snprintf(scores, sizeof scores, " (median SSIM %.2f, gain %.2f)", median_ssim_, median_gain_);
  if (!too_few_) return text + ", but they match well" + scores + ": the view partly hidden, the frame used";
  text += scores;
  if (in_a_row_ == 0) {
    return text + ": used, the allowance of " + std::to_string(max_in_a_row_) + " dropouts in a row spent";
  }
  return text + ": skipped as an image dropout" + kept + " (" + std::to_string(in_a_row_) + " of at most " +
         std::to_string(max_in_a_row_) + " in a row)";
}

}  // namespace nrslam
