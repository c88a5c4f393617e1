// frontend: the validity mask of a frame — where features may be detected and reference
// patches cut (non-zero = usable) — and the grey image every front-end step reads.
#pragma once

#include <opencv2/core.hpp>

#include <vector>

#include "nrslam/frontend/frontend_options.h"

namespace nrslam {

// The grey image of a BGR frame.
cv::Mat ToGrey(const cv::Mat& bgr);

// Combines the image border, the specular highlights of `grey` (with a margin), and the
// sequence's own mask (its fixed mask AND the frame's mask; may be empty), then erodes the
// result so that nothing right at a mask boundary is used.
cv::Mat BuildValidityMask(const cv::Mat& grey, const cv::Mat& sequence_mask, const MaskOptions& options);

// The regions that never change over `greys` (8-bit grey frames of one size, spread over a
// run; at least MaskOptions::kMinStaticFrames): non-zero where static, with
// `static_margin_px` around; empty when there is none. A pixel is static when in 9 of 10
// frames it is within `static_max_change` of its median, so that a dropout or a flash does not
// hide an on-screen display. Static patches smaller than `static_min_area_px` (once the strokes
// of text are joined), or without an edge of `static_min_edge` in the median frame, are still
// tissue, not a display. Pixels `sequence_mask` (may be empty) leaves out are not looked at: a
// masked black border is no news, nor should it grow a margin.
cv::Mat FindStaticRegions(const std::vector<cv::Mat>& greys, const cv::Mat& sequence_mask, const MaskOptions& options);

}  // namespace nrslam
