// Known-answer tests of the evaluator (design README §5).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "nrslam/eval/birth_errors.h"
#include "nrslam/eval/common_points.h"
#include "nrslam/eval/depth_evaluation.h"
#include "nrslam/eval/error_view.h"
#include "nrslam/util/error.h"

namespace nrslam {
namespace {

// Estimated depths 1.0 … 2.98 (map units); pairs (i, i+1) share a depth, so ± noise on them
// leaves the least-squares scale exact.
std::vector<double> Estimates(int pairs) {
  std::vector<double> z;
  for (int i = 0; i < pairs; ++i) {
    z.push_back(1.0 + 0.02 * i);
    z.push_back(1.0 + 0.02 * i);
  }
  return z;
}

TEST(DepthEvaluation, ScaledGroundTruthWithKnownNoiseGivesKnownScaleAndRmse) {
  // 190 points at ±0.4 mm around 30× the estimate, plus 10 gross outliers (5 %): trimming
  // must drop exactly the outliers, leaving scale 30 and RMSE 0.4.
  const std::vector<double> estimated = Estimates(100);
  std::vector<double> truth;
  for (size_t i = 0; i < estimated.size(); ++i) truth.push_back(30.0 * estimated[i] + (i % 2 ? 0.4 : -0.4));
  for (int pair = 0; pair < 5; ++pair) {  // whole pairs, so the kept noise stays balanced
    truth[40 * pair] += 90.0;
    truth[40 * pair + 1] -= 60.0;
  }
  const FrameEvaluation result = EvaluateDepthPairs(estimated, truth, EvaluationOptions{});
  ASSERT_TRUE(result.evaluated);
  EXPECT_EQ(result.points_kept, 190);  // floor(0.95 · 200)
  EXPECT_NEAR(result.scale, 30.0, 1e-9);
  EXPECT_NEAR(result.rmse_mm, 0.4, 1e-9);
}

TEST(DepthEvaluation, WithoutTrimmingItIsPlainLeastSquares) {
  const std::vector<double> estimated = Estimates(50);
  std::vector<double> truth;
  for (size_t i = 0; i < estimated.size(); ++i) truth.push_back(12.5 * estimated[i] + (i % 2 ? 0.3 : -0.3));
  EvaluationOptions untrimmed;
  untrimmed.keep_fraction = 1.0;
  const FrameEvaluation result = EvaluateDepthPairs(estimated, truth, untrimmed);
  EXPECT_NEAR(result.scale, 12.5, 1e-9);
  EXPECT_NEAR(result.rmse_mm, 0.3, 1e-9);
}

TEST(DepthEvaluation, OutliersWithinTheTrimmedFivePercentDoNotMoveIt) {
  const std::vector<double> estimated = Estimates(100);
  std::vector<double> truth;
  for (double z : estimated) truth.push_back(30.0 * z);
  for (int k : {3, 50, 77, 120, 121, 160, 199}) truth[k] += (k % 2 ? 500.0 : -25.0);  // 3.5 % gross outliers
  const FrameEvaluation result = EvaluateDepthPairs(estimated, truth, EvaluationOptions{});
  EXPECT_NEAR(result.scale, 30.0, 1e-9);
  EXPECT_NEAR(result.rmse_mm, 0.0, 1e-9);
  // Without trimming they dominate: the check above is not vacuous.
  EvaluationOptions untrimmed;
  untrimmed.keep_fraction = 1.0;
  EXPECT_GT(EvaluateDepthPairs(estimated, truth, untrimmed).rmse_mm, 50.0);
}

TEST(DepthEvaluation, PointsOnInvalidGroundTruthAreExcludedAndCounted) {
  cv::Mat depth(40, 60, CV_32F);
  for (int y = 0; y < 40; ++y) {
    for (int x = 0; x < 60; ++x) depth.at<float>(y, x) = 20.0f + 0.5f * x;  // a ramp in x
  }
  depth(cv::Rect(30, 0, 30, 40)) = 0.0f;  // right half: no ground truth
  std::vector<DepthPoint> points;
  for (int i = 0; i < 20; ++i) {
    const double x = 2.25 + i, y = 10.5;  // sub-pixel, left half
    points.push_back({{x, y}, (20.0 + 0.5 * x) / 10.0});  // exact at scale 10
  }
  points.push_back({{45.0, 10.0}, 1.0});  // right half
  points.push_back({{29.5, 10.0}, 1.0});  // straddles the hole: one tap invalid
  points.push_back({{-3.0, 10.0}, 1.0});  // outside the image
  const FrameEvaluation result = EvaluateFrame(points, depth, EvaluationOptions{});
  ASSERT_TRUE(result.evaluated);
  EXPECT_EQ(result.points_used, 20);
  EXPECT_EQ(result.points_without_groundtruth, 3);
  EXPECT_NEAR(result.scale, 10.0, 1e-9);  // bilinear sampling recovers the ramp exactly
  EXPECT_NEAR(result.rmse_mm, 0.0, 1e-9);
}

TEST(DepthEvaluation, TheFlatMapScoresTheSpreadOfTheTrueDepths) {
  // Truth 20, 22, …, 58 mm on a ramp; the estimates follow it exactly. A map at one depth can
  // only be scaled to the (trimmed) mean, so its RMSE is the spread of the truth around it.
  cv::Mat depth(40, 60, CV_32F);
  for (int y = 0; y < 40; ++y) {
    for (int x = 0; x < 60; ++x) depth.at<float>(y, x) = 20.0f + 2.0f * static_cast<float>(x);
  }
  std::vector<DepthPoint> points;
  for (int x = 0; x < 20; ++x) points.push_back({{static_cast<double>(x), 20.0}, 0.1 * (20.0 + 2.0 * x)});
  EvaluationOptions untrimmed;
  untrimmed.keep_fraction = 1.0;
  const FrameEvaluation result = EvaluateFrame(points, depth, untrimmed);
  ASSERT_TRUE(result.evaluated);
  EXPECT_NEAR(result.rmse_mm, 0.0, 1e-9);
  // Truth 20 + 2x, x = 0…19: around its mean, the spread is 2·√((20² − 1)/12).
  EXPECT_NEAR(result.flat_rmse_mm, 2.0 * std::sqrt((20.0 * 20.0 - 1.0) / 12.0), 1e-9);
  // Trimmed (the default), the flat map drops its worst point, an end of the ramp.
  const FrameEvaluation trimmed = EvaluateFrame(points, depth, EvaluationOptions{});
  EXPECT_EQ(trimmed.points_kept, 19);
  EXPECT_NEAR(trimmed.flat_rmse_mm, 2.0 * std::sqrt((19.0 * 19.0 - 1.0) / 12.0), 1e-9);
}

TEST(DepthEvaluation, TooFewPointsOrBadInputAreReportedNotGuessed) {
  EXPECT_FALSE(EvaluateDepthPairs({1.0, 2.0}, {10.0, 20.0}, EvaluationOptions{}).evaluated);
  EXPECT_THROW(EvaluateDepthPairs({1.0, NAN, 1, 1, 1}, {1, 1, 1, 1, 1}, EvaluationOptions{}), Error);
  EXPECT_THROW(EvaluateDepthPairs({1.0}, {1.0, 2.0}, EvaluationOptions{}), Error);
  EXPECT_FALSE(EvaluateDepthPairs({0, 0, 0, 0, 0}, {1, 2, 3, 4, 5}, EvaluationOptions{}).evaluated);
}

TEST(DepthEvaluation, SequenceAggregates) {
  std::vector<FrameEvaluation> frames(4);
  const double rmse[4] = {1.0, 2.0, 4.0, 0.0};
  for (int i = 0; i < 3; ++i) {
    frames[i].evaluated = true;
    frames[i].rmse_mm = rmse[i];
    frames[i].points_kept = 100;
    frames[i].squared_error_sum = rmse[i] * rmse[i] * 100;
    frames[i].flat_rmse_mm = 10.0 * rmse[i];
  }
  frames[3].flat_rmse_mm = 99.0;  // not evaluated: must not count
  const SequenceMetrics metrics = AggregateFrames(frames);  // the 4th frame was not evaluated
  EXPECT_EQ(metrics.frames_evaluated, 3);
  EXPECT_NEAR(metrics.rmse_mm, 7.0 / 3.0, 1e-12);
  EXPECT_NEAR(metrics.rmse_median_mm, 2.0, 1e-12);
  EXPECT_NEAR(metrics.rmse_pooled_mm, std::sqrt(21.0 / 3.0), 1e-12);
  EXPECT_NEAR(metrics.rmse_flat_mm, 70.0 / 3.0, 1e-12);
}

TEST(DepthEvaluation, AtAGivenScaleItTrimsButDoesNotFit) {
  const std::vector<double> estimated = Estimates(100);
  std::vector<double> truth;
  for (double z : estimated) truth.push_back(30.0 * z);
  for (int k : {3, 50, 77, 120, 121, 160, 199}) truth[k] += 500.0;  // dropped by the trimming at scale 30
  const FrameEvaluation exact = EvaluateDepthPairsAtScale(estimated, truth, 30.0, EvaluationOptions{});
  ASSERT_TRUE(exact.evaluated);
  EXPECT_EQ(exact.points_kept, 190);
  EXPECT_DOUBLE_EQ(exact.scale, 30.0);
  EXPECT_NEAR(exact.rmse_mm, 0.0, 1e-12);
  // At scale 33 each kept residual is 3·z: the 190 smallest are the first 190 clean points'.
  const FrameEvaluation off = EvaluateDepthPairsAtScale(estimated, truth, 33.0, EvaluationOptions{});
  double squared = 0.0;
  int kept = 0;
  for (size_t i = 0; i < estimated.size() && kept < 190; ++i) {
    if (truth[i] != 30.0 * estimated[i]) continue;
    squared += 9.0 * estimated[i] * estimated[i];
    ++kept;
  }
  EXPECT_NEAR(off.rmse_mm, std::sqrt(squared / 190), 1e-9);
  EXPECT_FALSE(EvaluateDepthPairsAtScale({1.0, 2.0}, {10.0, 20.0}, 10.0, EvaluationOptions{}).evaluated);
}

// A frame evaluated as EvaluateFrame leaves it: its pairs, and the map they belong to.
FrameEvaluation FrameOfPairs(int map, const std::vector<double>& estimated, const std::vector<double>& truth) {
  EvaluationOptions untrimmed;
  untrimmed.keep_fraction = 1.0;
  FrameEvaluation frame = EvaluateDepthPairs(estimated, truth, untrimmed);
  frame.map = map;
  frame.estimated = estimated;
  frame.groundtruth = truth;
  return frame;
}

TEST(DepthEvaluation, OneScalePerMapMakesAScaleDriftCount) {
  EvaluationOptions untrimmed;
  untrimmed.keep_fraction = 1.0;
  const std::vector<double> z = {1, 2, 3, 4, 5};  // Σz² = 55
  auto scaled = [&](double s) {
    std::vector<double> truth;
    for (double value : z) truth.push_back(s * value);
    return truth;
  };
  // Map 0 drifts from scale 10 to 20: each frame alone is exact, the map's one scale is 15
  // (least squares over both frames), leaving 5·z in each, RMSE 5·√(55/5).
  // Map 1 keeps scale 40 and is exact at its own scale.
  const std::vector<FrameEvaluation> frames = {FrameOfPairs(0, z, scaled(10)), FrameOfPairs(0, z, scaled(20)),
                                               FrameOfPairs(1, z, scaled(40)), FrameOfPairs(1, z, scaled(40))};
  EXPECT_NEAR(AggregateFrames(frames).rmse_mm, 0.0, 1e-12);
  const OtherAlignments other = EvaluateOtherAlignments(frames, untrimmed);
  EXPECT_EQ(other.frames_evaluated, 4);
  EXPECT_NEAR(other.rmse_map_scale_mm, (5.0 * std::sqrt(11.0) * 2 + 0.0 * 2) / 4, 1e-9);
  EXPECT_NEAR(other.rmse_median_scale_mm, 0.0, 1e-12);  // every frame's ratios all agree
}

TEST(DepthEvaluation, TheMedianScaleIsTheMiddleRatioOfEachFrame) {
  // Ratios 2, 2, 2, 9, 9 (two points far off): the median ratio is 2, so the three points that
  // agree score 0 and the two others 7·z; least squares would have pulled the scale up.
  const std::vector<double> z = {1, 1, 1, 1, 1};
  const std::vector<double> truth = {2, 2, 2, 9, 9};
  EvaluationOptions untrimmed;
  untrimmed.keep_fraction = 1.0;
  const OtherAlignments other = EvaluateOtherAlignments({FrameOfPairs(0, z, truth)}, untrimmed);
  EXPECT_NEAR(other.rmse_median_scale_mm, std::sqrt(2 * 49.0 / 5), 1e-12);
  // Estimates behind the camera have no ratio: here only the positive ones vote (ratio 3).
  const OtherAlignments behind =
      EvaluateOtherAlignments({FrameOfPairs(0, {1, 1, 1, -1, -1}, {3, 3, 3, 3, 3})}, untrimmed);
  EXPECT_NEAR(behind.rmse_median_scale_mm, std::sqrt(2 * 36.0 / 5), 1e-12);
}

TEST(DepthEvaluation, OtherAlignmentsNeedTheFramesPairs) {
  FrameEvaluation frame;
  frame.evaluated = true;  // as AggregateFrames' own test builds one: figures, no pairs
  EXPECT_THROW(EvaluateOtherAlignments({frame}, EvaluationOptions{}), Error);
  EXPECT_EQ(EvaluateOtherAlignments({}, EvaluationOptions{}).frames_evaluated, 0);
}

// Depth at any scale correlates with the truth at +1; its inverse, over an endoscope's 10–60 mm,
// at −0.89; an estimate that does not vary, not at all.
TEST(DepthEvaluation, InverseDepthCorrelatesNegatively) {
  std::vector<double> truth, scaled, inverse;
  for (double z = 10; z <= 60; z += 2.5) {
    truth.push_back(z);
    scaled.push_back(0.03 * z);
    inverse.push_back(1 / z);
  }
  EXPECT_NEAR(DepthCorrelation(scaled, truth), 1.0, 1e-12);
  EXPECT_NEAR(DepthCorrelation(inverse, truth), -0.887543, 1e-6);  // numpy's corrcoef of the same
  EXPECT_EQ(DepthCorrelation(std::vector<double>(truth.size(), 5.0), truth), 0.0);
  EXPECT_EQ(DepthCorrelation({}, {}), 0.0);
  EXPECT_THROW(DepthCorrelation({1, 2}, {1}), Error);
}

// Ground truth for the common-point tests: a slanted plane, 80 mm + 1 mm per column.
cv::Mat SlantedPlaneDepth() {
  cv::Mat depth(40, 60, CV_32F);
  for (int y = 0; y < depth.rows; ++y) {
    for (int x = 0; x < depth.cols; ++x) depth.at<float>(y, x) = 80.0f + x;
  }
  return depth;
}

// Run a keeps ten exact points and ten bad ones; run b only the ten exact ones (and one of its
// own). On their own points a scores badly and b perfectly; on the common points both are exact.
TEST(CommonPoints, BothRunsAreScoredOnThePointsTheyShare) {
  const cv::Mat depth = SlantedPlaneDepth();
  const auto truth = [&](int x, int y) { return static_cast<double>(depth.at<float>(y, x)); };
  RunPoints a, b;
  for (int id = 0; id < 20; ++id) {
    const int x = 2 + 2 * id, y = 5 + id;
    const double bad = id >= 10 ? (id % 2 ? 8.0 : -8.0) : 0.0;  // mm, far beyond the 5 % trimmed
    a[3][id] = {cv::Point2d(x, y), (truth(x, y) + bad) / 2.0};  // map units: 2 mm each
    if (id < 10) b[3][id] = {cv::Point2d(x, y), truth(x, y) * 3.0};
  }
  b[3][100] = {cv::Point2d(50, 30), truth(50, 30) * 3.0};
  a[4] = a[3];  // a frame b does not report: not compared
  b[5] = b[3];
  a[5][0] = a[3][0];  // a frame with a single common point: too few to evaluate, not compared
  const CommonPointsComparison comparison =
      CompareOnCommonPoints(a, b, [&](int) { return depth; }, EvaluationOptions{});
  EXPECT_EQ(comparison.frames, 1);
  EXPECT_DOUBLE_EQ(comparison.mean_points_a, 20);
  EXPECT_DOUBLE_EQ(comparison.mean_points_b, 11);
  EXPECT_DOUBLE_EQ(comparison.mean_common_points, 10);
  EXPECT_GT(comparison.a_own.rmse_mm, 4.0);
  EXPECT_NEAR(comparison.b_own.rmse_mm, 0.0, 1e-9);
  EXPECT_NEAR(comparison.a_common.rmse_mm, 0.0, 1e-9);
  EXPECT_NEAR(comparison.b_common.rmse_mm, 0.0, 1e-9);
}

// Two monocular runs number their new points in the order each made them, so one id can name
// different points. Ids 20-22 are first reported by b a frame earlier, ids 23-24 a pixel away
// from where a first reports them; a puts all five 8 mm off. Paired, they would spoil a's common
// score; they are counted and left out.
TEST(CommonPoints, AnIdThatNamesDifferentTracksInTheTwoRunsIsNotCommon) {
  const cv::Mat depth = SlantedPlaneDepth();
  const auto truth = [&](int x, int y) { return static_cast<double>(depth.at<float>(y, x)); };
  RunPoints a, b;
  for (int id = 0; id < 10; ++id) {
    const int x = 2 + 2 * id, y = 5 + id;
    a[3][id] = {cv::Point2d(x, y), truth(x, y) / 2.0};
    b[3][id] = {cv::Point2d(x, y), truth(x, y) * 3.0};
  }
  for (int id = 20; id < 25; ++id) {
    const int x = 2 * id - 10, y = 30;
    a[3][id] = {cv::Point2d(x, y), (truth(x, y) + 8.0) / 2.0};
    b[3][id] = {cv::Point2d(id < 23 ? x : x + 1, y), truth(id < 23 ? x : x + 1, y) * 3.0};
    if (id < 23) b[2][id] = b[3][id];
  }
  const CommonPointsComparison comparison =
      CompareOnCommonPoints(a, b, [&](int) { return depth; }, EvaluationOptions{});
  EXPECT_EQ(comparison.mismatched_ids, 5);
  EXPECT_EQ(comparison.frames, 1);
  EXPECT_DOUBLE_EQ(comparison.mean_common_points, 10);
  EXPECT_NEAR(comparison.a_common.rmse_mm, 0.0, 1e-9);
  EXPECT_NEAR(comparison.b_common.rmse_mm, 0.0, 1e-9);
  EXPECT_GT(comparison.a_own.rmse_mm, 1.0);
}

// A 80×60 frame of grey at 50 mm, with no depth on its first 10 columns. 39 points at z = 5
// fix the scale at 10 (the two off ones fall in the trimmed 5 %).
class ErrorViewTest : public ::testing::Test {
 protected:
  void SetUp() override {
    depth_.colRange(0, 10).setTo(0.0f);
    int64_t id = 0;
    for (int y = 5; y <= 55; y += 10) {
      for (int x = 15; x <= 75; x += 10) points_[id++] = {cv::Point2d(x, y), 5.0};
    }
    points_[kTooDeep].depth = 6.5;     // 65 mm after scaling: 30 % too deep
    points_[kTooShallow].depth = 3.5;  // 35 mm: 30 % too shallow
    points_[kNoEstimate].depth = std::numeric_limits<double>::infinity();
    points_[kNoTruth] = {cv::Point2d(4.25, 30.5), 5.0};
  }
  static constexpr int64_t kTooDeep = 8, kTooShallow = 20, kRight = 30, kNoEstimate = 33, kNoTruth = 100;
  cv::Vec3b At(const cv::Mat& image, int64_t id, int panel_offset = 0) const {
    const cv::Point2d pixel = points_.at(id).pixel;
    return image.at<cv::Vec3b>(static_cast<int>(std::lround(pixel.y)),
                               static_cast<int>(std::lround(pixel.x)) + panel_offset);
  }
  const cv::Mat bgr_ = cv::Mat(60, 80, CV_8UC3, cv::Scalar::all(100));
  cv::Mat depth_ = cv::Mat(60, 80, CV_32F, cv::Scalar(50.0));
  FramePoints points_;
};

TEST_F(ErrorViewTest, EachPointIsColouredByItsScaledDepthError) {
  const ErrorView view = DrawErrorView(bgr_, depth_, points_, EvaluationOptions(), ErrorViewOptions());
  std::vector<DepthPoint> all;
  for (const auto& [id, point] : points_) all.push_back(point);
  const FrameEvaluation expected = EvaluateFrame(all, depth_, EvaluationOptions());
  ASSERT_TRUE(view.evaluation.evaluated);
  EXPECT_DOUBLE_EQ(view.evaluation.scale, expected.scale);
  EXPECT_DOUBLE_EQ(view.evaluation.rmse_mm, expected.rmse_mm);
  EXPECT_NEAR(view.evaluation.scale, 10.0, 1e-12);
  EXPECT_EQ(view.evaluation.points_without_groundtruth, 2);  // no truth, and no finite estimate

  ASSERT_EQ(view.image.size(), cv::Size(160, 60));  // colour | depth
  EXPECT_EQ(At(view.image, kRight), cv::Vec3b(255, 255, 255));
  EXPECT_EQ(At(view.image, kTooDeep), cv::Vec3b(0, 0, 255));     // BGR: red
  EXPECT_EQ(At(view.image, kTooShallow), cv::Vec3b(255, 0, 0));  // blue
  EXPECT_EQ(At(view.image, kNoTruth), cv::Vec3b(100, 100, 100)) << "a ring leaves the pixel under it visible";
  EXPECT_EQ(At(view.image, kNoEstimate), cv::Vec3b(100, 100, 100));

  // Depth panel: a right point has the background's colour, a wrong one does not.
  const cv::Vec3b background = ColourDepth(depth_, 10, 120).at<cv::Vec3b>(30, 50);
  EXPECT_EQ(view.image.at<cv::Vec3b>(0, 80 + 10), background);
  EXPECT_EQ(At(view.image, kRight, 80), background);
  EXPECT_EQ(At(view.image, kTooDeep, 80), ColourDepth(cv::Mat(1, 1, CV_32F, cv::Scalar(65.0)), 10, 120).at<cv::Vec3b>(0, 0));
  EXPECT_NE(At(view.image, kTooDeep, 80), background);
  EXPECT_EQ(At(view.image, kNoTruth, 80), cv::Vec3b(0, 0, 0)) << "no depth there: black, and no point drawn";
  EXPECT_DOUBLE_EQ(view.full_scale_error, 0.25);

  // Full colour from the frame's own errors: three times their rms over the 41 scored points.
  ErrorViewOptions automatic;
  automatic.full_scale_error = 0;
  const ErrorView scaled = DrawErrorView(bgr_, depth_, points_, EvaluationOptions(), automatic);
  EXPECT_NEAR(scaled.full_scale_error, 3 * std::sqrt(2 * 0.3 * 0.3 / 41), 1e-12);
  EXPECT_EQ(At(scaled.image, kTooDeep), cv::Vec3b(0, 0, 255));
}

TEST_F(ErrorViewTest, WithoutAScaleNothingIsScored) {
  const ErrorView no_depth = DrawErrorView(bgr_, cv::Mat(), points_, EvaluationOptions(), ErrorViewOptions());
  EXPECT_FALSE(no_depth.evaluation.evaluated);
  ASSERT_EQ(no_depth.image.size(), bgr_.size());
  EXPECT_EQ(At(no_depth.image, kRight), cv::Vec3b(100, 100, 100));

  EvaluationOptions needs_more;
  needs_more.min_points = 100;
  const ErrorView too_few = DrawErrorView(bgr_, depth_, points_, needs_more, ErrorViewOptions());
  EXPECT_FALSE(too_few.evaluation.evaluated);
  EXPECT_EQ(At(too_few.image, kTooDeep), cv::Vec3b(100, 100, 100));
  EXPECT_EQ(At(too_few.image, kTooDeep, 80), ColourDepth(depth_, 10, 120).at<cv::Vec3b>(30, 50));

  EXPECT_THROW(DrawErrorView(bgr_, depth_.colRange(0, 40).clone(), points_, EvaluationOptions(), ErrorViewOptions()),
               Error);
  ErrorViewOptions inverted;
  inverted.far_mm = 5;
  EXPECT_THROW(DrawErrorView(bgr_, depth_, points_, EvaluationOptions(), inverted), Error);
}

// Known answers: a map at half the truth's scale (true depth 20 mm everywhere but a hole), so
// each frame's median ratio is 2 and a point's birth error is log(2·z / 20).
TEST(BirthErrors, NewPointsAreScoredOnceAgainstTheirFramesScale) {
  cv::Mat depth(40, 40, CV_32F, cv::Scalar(20.0f));
  depth(cv::Rect(30, 30, 10, 10)) = 0.0f;  // no ground truth there
  const auto at = [](double x, double z) { return DepthPoint{{x, 5.0}, z}; };
  const std::vector<DepthPoint> map{at(1, 10), at(2, 10), at(3, 10), at(4, 10), at(5, 10)};
  BirthErrors births;
  // Each frame evaluated as the runner evaluates it: 5 points with ground truth make its scale.
  const auto add = [&births](const std::vector<int64_t>& ids, const std::vector<DepthPoint>& points,
                             const cv::Mat& depth_mm, bool map_start) {
    const FrameEvaluation evaluation =
        depth_mm.empty() ? FrameEvaluation{} : EvaluateFrame(points, depth_mm, EvaluationOptions{});
    births.AddFrame(ids, points, depth_mm, evaluation, map_start);
  };
  add({0, 1, 2, 3, 4}, map, depth, true);  // the map's first frame: no births
  EXPECT_TRUE(births.log_errors().empty());

  // Frame 1: three new points, one 10 % too far, one 10 % too near, one without ground truth.
  std::vector<DepthPoint> frame1 = map;
  frame1.push_back(at(10, 11));
  frame1.push_back(at(11, 9));
  frame1.push_back({{35, 35}, 10});
  add({0, 1, 2, 3, 4, 5, 6, 7}, frame1, depth, false);
  ASSERT_EQ(births.log_errors().size(), 2u);
  EXPECT_NEAR(births.log_errors()[0], std::log(1.1), 1e-12);
  EXPECT_NEAR(births.log_errors()[1], std::log(0.9), 1e-12);

  // Seen before: not born again, whatever its depth now. Born on a frame without ground truth,
  // or with too few points for a scale: born unscored, and not scored later either.
  add({0, 1, 2, 3, 4, 5, 8}, {at(1, 10), at(2, 10), at(3, 10), at(4, 10), at(5, 10), at(10, 30), at(12, 10)},
      cv::Mat(), false);
  add({0, 1, 9}, {at(1, 10), at(2, 10), at(13, 10)}, depth, false);
  add({0, 1, 2, 3, 4, 5, 8, 9}, frame1, depth, false);
  EXPECT_EQ(births.log_errors().size(), 2u);
  // A new map's first frame: its points are the map, not births.
  add({20, 21, 22, 23, 24, 25}, {at(1, 5), at(2, 5), at(3, 5), at(4, 5), at(5, 5), at(6, 7)}, depth, true);
  EXPECT_EQ(births.log_errors().size(), 2u);
  // The frame's scale is the median ratio over all its points, new ones included: here 4.
  add({20, 21, 22, 23, 24, 26}, {at(1, 5), at(2, 5), at(3, 5), at(4, 5), at(5, 5), at(7, 2.5)}, depth, false);
  ASSERT_EQ(births.log_errors().size(), 3u);
  EXPECT_NEAR(births.log_errors()[2], std::log(0.5), 1e-12);

  const BirthErrorSummary summary = births.Summarise();
  EXPECT_EQ(summary.births_evaluated, 3);
  ASSERT_TRUE(summary.mean && summary.median);
  EXPECT_NEAR(*summary.mean, (std::log(1.1) + std::log(0.9) + std::log(0.5)) / 3, 1e-12);
  EXPECT_NEAR(*summary.median, std::log(0.9), 1e-12);
  EXPECT_FALSE(BirthErrors().Summarise().mean);
  EXPECT_THROW(births.AddFrame({1, 2}, map, depth, EvaluateFrame(map, depth, EvaluationOptions{}), false), Error);
}

}  // namespace
}  // namespace nrslam
