#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>

#include "frontend_fixtures.h"
#include "nrslam/frontend/feature_detector.h"
#include "nrslam/frontend/masks.h"
#include "nrslam/frontend/shading.h"
#include "nrslam/util/error.h"

namespace nrslam {
namespace {

// Frames are read in OpenCV's BGR order. The reference converted them with RGB weights
// (reference-behaviour §9.2), which weighs red as blue and blue as red.
TEST(Grey, WeighsTheChannelsOfABgrFrameAsTheirColoursNeed) {
  const cv::Mat blue(1, 1, CV_8UC3, cv::Scalar(255, 0, 0));
  const cv::Mat green(1, 1, CV_8UC3, cv::Scalar(0, 255, 0));
  const cv::Mat red(1, 1, CV_8UC3, cv::Scalar(0, 0, 255));
  EXPECT_EQ(ToGrey(blue).at<uint8_t>(0, 0), 29);    // 0.114 × 255
  EXPECT_EQ(ToGrey(green).at<uint8_t>(0, 0), 150);  // 0.587 × 255
  EXPECT_EQ(ToGrey(red).at<uint8_t>(0, 0), 76);     // 0.299 × 255
}

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

// 24 frames of 160×120: a blurred random texture moving 3 px right and 2 px down a frame, under
// a black border (columns 0–11), a display's text, a flat grey square and a small white speck
// that never change; frame 7 is a black dropout.
struct StaticScene {
  std::vector<cv::Mat> frames;
  cv::Mat text;  // the display's strokes
};
StaticScene RenderStaticScene() {
  cv::Mat texture(300, 400, CV_8UC1);
  cv::RNG rng(7);
  rng.fill(texture, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 2.0);
  cv::normalize(texture, texture, 0, 255, cv::NORM_MINMAX);
  StaticScene scene;
  scene.text = cv::Mat::zeros(120, 160, CV_8UC1);
  cv::putText(scene.text, "OSD 42", {40, 100}, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(255), 1);
  for (int k = 0; k < 24; ++k) {
    cv::Mat frame = texture(cv::Rect(3 * k, 2 * k, 160, 120)).clone();
    frame.colRange(0, 12) = 0;
    frame.setTo(200, scene.text);
    frame(cv::Rect(110, 10, 24, 24)) = 128;
    frame(cv::Rect(130, 80, 5, 5)) = 255;
    if (k == 7) frame = 0;
    scene.frames.push_back(frame);
  }
  return scene;
}

TEST(StaticRegions, FindsADisplayAndABlackBorderButNotMovingOrFlatTissue) {
  const StaticScene scene = RenderStaticScene();
  MaskOptions options;  // 4 grey levels, 64 px, an edge of 16 grey levels per px, a 10 px margin
  const cv::Mat regions = FindStaticRegions(scene.frames, {}, options);
  ASSERT_FALSE(regions.empty());
  EXPECT_EQ(regions.at<uint8_t>(60, 5), 255);   // the border, through the dropout
  EXPECT_EQ(regions.at<uint8_t>(60, 21), 255);  // its margin
  EXPECT_EQ(regions.at<uint8_t>(60, 26), 0);
  EXPECT_EQ(cv::countNonZero(regions & scene.text), cv::countNonZero(scene.text));  // the display
  EXPECT_EQ(regions.at<uint8_t>(96, 48), 255);  // and the texture between its strokes, within the margin
  EXPECT_EQ(regions.at<uint8_t>(60, 80), 0);  // moving tissue
  EXPECT_EQ(regions.at<uint8_t>(22, 122), 0);  // still but flat: no edge to track
  EXPECT_EQ(regions.at<uint8_t>(82, 132), 0);  // too small to be a display
  // Each rule is what leaves its patch out.
  options.static_min_edge = 0;
  EXPECT_EQ(FindStaticRegions(scene.frames, {}, options).at<uint8_t>(22, 122), 255);
  options.static_min_area_px = 0;
  EXPECT_EQ(FindStaticRegions(scene.frames, {}, options).at<uint8_t>(82, 132), 255);
}

TEST(StaticRegions, LeavesWhatTheSequenceMasksAloneAndNeedsTenFramesOfOneSize) {
  const StaticScene scene = RenderStaticScene();
  cv::Mat sequence_mask(120, 160, CV_8UC1, cv::Scalar(255));
  sequence_mask.colRange(0, 16) = 0;
  const cv::Mat regions = FindStaticRegions(scene.frames, sequence_mask, MaskOptions{});
  ASSERT_FALSE(regions.empty());
  EXPECT_EQ(regions.at<uint8_t>(60, 5), 0);   // masked already: no news
  EXPECT_EQ(regions.at<uint8_t>(60, 21), 0);  // and no margin grows from it
  EXPECT_EQ(cv::countNonZero(regions & scene.text), cv::countNonZero(scene.text));
  // Moving texture alone: nothing.
  std::vector<cv::Mat> moving;
  for (const cv::Mat& frame : scene.frames) moving.push_back(frame(cv::Rect(16, 0, 24, 80)).clone());
  EXPECT_TRUE(FindStaticRegions(moving, {}, MaskOptions{}).empty());
  const std::vector<cv::Mat> nine(scene.frames.begin(), scene.frames.begin() + 9);
  EXPECT_THROW(FindStaticRegions(nine, {}, MaskOptions{}), Error);
  std::vector<cv::Mat> mixed = scene.frames;
  mixed[3] = cv::Mat(60, 80, CV_8UC1, cv::Scalar(0));
  EXPECT_THROW(FindStaticRegions(mixed, {}, MaskOptions{}), Error);
  EXPECT_THROW(FindStaticRegions(scene.frames, cv::Mat(10, 10, CV_8UC1), MaskOptions{}), Error);
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

TEST(Shading, BrightnessIsTheLinearMeanOverTheValidPixelsOfTheBox) {
  // Left half grey 200, right half grey 50; the right half is invalid except one column.
  cv::Mat grey(40, 60, CV_8UC1, cv::Scalar(200));
  grey(cv::Rect(30, 0, 30, 40)).setTo(50);
  cv::Mat valid(grey.size(), CV_8UC1, cv::Scalar(255));
  valid(cv::Rect(30, 0, 30, 40)).setTo(0);
  valid(cv::Rect(45, 0, 1, 40)).setTo(255);
  ShadingOptions options;
  options.gamma = 2.0;
  options.patch_px = 2;
  const double bright = std::pow(200 / 255.0, 2.0), dark = std::pow(50 / 255.0, 2.0);
  const std::vector<double> brightness = LinearBrightness(
      grey, valid, {cv::Point2f(10, 10), cv::Point2f(31, 20), cv::Point2f(29, 20), cv::Point2f(38, 20),
                    cv::Point2f(45.3f, 20), cv::Point2f(0, 0)},
      options);
  ASSERT_EQ(brightness.size(), 6u);
  EXPECT_NEAR(brightness[0], bright, 1e-12);
  EXPECT_NEAR(brightness[1], bright, 1e-12);                        // only its valid (left) columns count
  EXPECT_NEAR(brightness[2], bright, 1e-12);                        // its two invalid dark columns do not count
  EXPECT_EQ(brightness[3], 0.0);                                    // nothing valid in the box
  EXPECT_NEAR(brightness[4], dark, 1e-12);                          // the one valid column
  EXPECT_NEAR(brightness[5], bright, 1e-12);                        // a box cut by the image corner
  // The mean is of linear levels, not of grey levels: a box half 200 and half 50 is brighter
  // than grey 125 would be.
  const double mixed = LinearBrightness(grey, cv::Mat(grey.size(), CV_8UC1, cv::Scalar(255)),
                                        {cv::Point2f(29.5f, 20)}, ShadingOptions{})[0];
  EXPECT_GT(mixed, std::pow(125 / 255.0, 2.2));
}

TEST(Shading, BlendMovesDistancesTowardWhatTheBrightnessSays) {
  // Points lit from the camera: brightness 7 / r². The distances to correct are a compressed,
  // rescaled version of the truth (what two views of moving tissue give): 3·r^0.6.
  const std::vector<double> truth = {20, 25, 33, 41, 60, 95, 120};  // an odd count: one median
  ShadedPoints measured;
  for (double r : truth) {
    measured.distances.push_back(3 * std::pow(r, 0.6));
    measured.brightness.push_back(7 / (r * r));
  }
  // Weight 1: the truth up to one factor, whatever the calibration's own distances say.
  const std::vector<double> shaded = BlendWithShading(measured, measured, 1.0);
  for (size_t i = 1; i < truth.size(); ++i) EXPECT_NEAR(shaded[i] / truth[i], shaded[0] / truth[0], 1e-9);
  // The factor puts the brightness on the calibration's scale: the median log ratio is 0.
  std::vector<double> log_ratios;
  for (size_t i = 0; i < truth.size(); ++i) log_ratios.push_back(std::log(shaded[i] / measured.distances[i]));
  std::sort(log_ratios.begin(), log_ratios.end());
  EXPECT_NEAR(log_ratios[truth.size() / 2], 0.0, 1e-9);
  // Weight 0 changes nothing; 0.5 is the geometric mean of the two.
  const std::vector<double> unchanged = BlendWithShading(measured, measured, 0.0);
  const std::vector<double> half = BlendWithShading(measured, measured, 0.5);
  for (size_t i = 0; i < truth.size(); ++i) {
    EXPECT_NEAR(unchanged[i], measured.distances[i], 1e-12);
    EXPECT_NEAR(half[i], std::sqrt(shaded[i] * measured.distances[i]), 1e-9);
  }
  // Targets other than the calibration points; one without a brightness keeps its distance.
  const ShadedPoints targets{{10, 10}, {7 / (50.0 * 50.0), 0}};
  const std::vector<double> moved = BlendWithShading(measured, targets, 1.0);
  EXPECT_NEAR(moved[0] / 50, shaded[0] / truth[0], 1e-9);
  EXPECT_EQ(moved[1], 10);
  // No calibration point with a brightness: nothing to scale by, nothing moves.
  const ShadedPoints dark{{5, 6}, {0, 0}};
  EXPECT_EQ(BlendWithShading(dark, targets, 1.0), targets.distances);
}

}  // namespace
}  // namespace nrslam
