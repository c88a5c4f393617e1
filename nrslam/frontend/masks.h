// frontend: the validity mask of a frame — where features may be detected and reference
// patches cut (non-zero = usable) — and the grey image every front-end step reads.
#pragma once

#include <opencv2/core.hpp>

#include "nrslam/frontend/frontend_options.h"

namespace nrslam {

// The grey image of a BGR frame.
cv::Mat ToGrey(const cv::Mat& bgr);

// Combines the image border, the specular highlights of `grey` (with a margin), and the
// sequence's own mask (its fixed mask AND the frame's mask; may be empty), then erodes the
// result so that nothing right at a mask boundary is used.
cv::Mat BuildValidityMask(const cv::Mat& grey, const cv::Mat& sequence_mask, const MaskOptions& options);

}  // namespace nrslam
