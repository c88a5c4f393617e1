#include <gtest/gtest.h>

#include "frontend_fixtures.h"
#include "nrslam/frontend/feature_detector.h"
#include "nrslam/frontend/masks.h"
#include "nrslam/util/error.h"

namespace nrslam {
namespace {

TEST(Masks, CombinesBorderHighlightsAndTheSequenceMaskThenErodes) {
  cv::Mat grey(100, 120, CV_8UC1, cv::Scalar(100));
  grey.at<uint8_t>(50, 60) = 250;  // a specular highlight
  cv::Mat sequence_mask(100, 120, CV_8UC1, cv::Scalar(255));
  sequence_mask.colRange(100, 120) = 0;
  MaskOptions options;
  options.border_px = 4;
  options.bright_threshold = 240;
  options.bright_margin_px = 3;
  options.erosion_px = 2;
  const cv::Mat valid = BuildValidityMask(grey, sequence_mask, options);
  EXPECT_EQ(valid.at<uint8_t>(2, 50), 0);    // border
  EXPECT_EQ(valid.at<uint8_t>(50, 60), 0);   // highlight
  EXPECT_EQ(valid.at<uint8_t>(50, 65), 0);   // within margin 3 + erosion 2
  EXPECT_EQ(valid.at<uint8_t>(50, 67), 255);
  EXPECT_EQ(valid.at<uint8_t>(30, 99), 0);   // eroded edge of the sequence mask
  EXPECT_EQ(valid.at<uint8_t>(30, 97), 255);
  EXPECT_EQ(valid.at<uint8_t>(30, 110), 0);  // the sequence mask itself
  EXPECT_THROW(BuildValidityMask(grey, cv::Mat(10, 10, CV_8UC1), options), Error);
}

TEST(Features, RenderedMucosaGivesManyCornersThatRespectMaskSpacingAndExclusion) {
  const cv::Mat grey = RenderedGrey("sim-0", 0);
  const cv::Mat valid = BuildValidityMask(grey, {}, MaskOptions{});
  FeatureOptions options;
  const auto corners = DetectCorners(grey, valid, {}, options);
  EXPECT_GE(corners.size(), 300u);
  EXPECT_LE(corners.size(), static_cast<size_t>(options.max_features));
  for (size_t i = 0; i < corners.size(); ++i) {
    EXPECT_NE(valid.at<uint8_t>(cvRound(corners[i].y), cvRound(corners[i].x)), 0);
    for (size_t j = i + 1; j < corners.size(); ++j) {
      ASSERT_GT(cv::norm(corners[i] - corners[j]), options.nms_radius_px) << i << " " << j;
    }
  }
  // New corners stay away from existing tracks.
  const std::vector<cv::Point2f> existing(corners.begin(), corners.begin() + 50);
  const auto more = DetectCorners(grey, valid, existing, options);
  for (const auto& c : more) {
    for (const auto& e : existing) EXPECT_GT(cv::norm(c - e), options.exclusion_radius_px - 1.0);
  }
  options.max_features = 25;
  EXPECT_EQ(DetectCorners(grey, valid, {}, options).size(), 25u);
}

}  // namespace
}  // namespace nrslam
