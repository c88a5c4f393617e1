// End to end: a short simulated colonoscopy through nrslam's runner (map from depth, then
// deformable tracking), checked against the simulator's ground truth.
#include <gtest/gtest.h>

#include <omp.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <numeric>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <tuple>
#include <utility>

#include "camera_fixtures.h"
#include "error_message.h"
#include "temp_folder.h"
#include "nrslam/batch/report.h"
#include "nrslam/batch/run_folder.h"
#include "nrslam/datasets/dataset_import.h"
#include "nrslam/deformation/deformation_graph.h"
#include "nrslam/eval/birth_errors.h"
#include "nrslam/eval/depth_evaluation.h"
#include "nrslam/eval/trajectory_error.h"
#include "nrslam/io/sequence_reader.h"
#include "nrslam/io/tum.h"
#include "nrslam/sim/renderer.h"
#include "nrslam/sim/simulate.h"
#include "nrslam/system/external_result.h"
#include "nrslam/system/run_files.h"
#include "nrslam/system/run_sequence.h"
#include "nrslam/system/static_regions.h"
#include "nrslam/tracking/tracker.h"
#include "nrslam/util/error.h"
#include "nrslam/util/json_options.h"
#include "nrslam/util/median.h"
#include "nrslam/util/source_revision.h"
#include "nrslam/util/text_file.h"

namespace nrslam {
namespace {
namespace fs = std::filesystem;

struct CsvPoint {
  int frame;
  PointId id;
  double u, v, z;  // pixel and estimated depth (map units: mm from depth, arbitrary when monocular)
  Eigen::Vector3d world;  // map units
};

std::vector<CsvPoint> ReadPointsCsv(const fs::path& path) {
  std::ifstream file(path);
  std::string line;
  std::getline(file, line);  // header
  std::vector<CsvPoint> points;
  while (std::getline(file, line)) {
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream fields(line);
    CsvPoint p;
    fields >> p.frame >> p.id >> p.u >> p.v >> p.z >> p.world.x() >> p.world.y() >> p.world.z();
    points.push_back(p);
  }
  return points;
}

int CountLines(const fs::path& file, const std::string& text) {
  std::ifstream in(file);
  int count = 0;
  for (std::string line; std::getline(in, line);) count += line.find(text) != std::string::npos;
  return count;
}

// The paper's tracking experiment: the map from the first frame's depth, no mapping.
SystemOptions TrackingExperiment() {
  SystemOptions options;
  options.run.init = "depth";
  options.run.mapping = false;
  return options;
}

void SimulateSmall(const std::string& preset, int frames, int width, int height, const fs::path& folder) {
  SimOptions sim = SimPreset(preset);
  sim.frames = frames;
  sim.camera.width = width;
  sim.camera.height = height;
  SimulateSequence(sim, preset + "-small", folder);
}

// Frames [first, end) of a 320×240 sequence made one flat colour: a blank view (a flush, the
// lens against the tissue) or, black, the light off.
void BlankFrames(const fs::path& sequence, int first, int end, const cv::Scalar& colour) {
  const cv::Mat blank(240, 320, CV_8UC3, colour);
  for (int frame = first; frame < end; ++frame) cv::imwrite((sequence / "rgb" / FrameFileName(frame)).string(), blank);
}

class RunSequenceTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // CTest runs each test case in its own process, in parallel: one folder per process.
    base_ = new fs::path(UniqueTempFolder("nrslam_run_test"));
    fs::remove_all(*base_);
    SimulateSmall("sim-3", 40, 320, 240, *base_ / "sequence");  // A = 5 mm, ω = 2.5 rad/s
    summary_ = new RunSummary(RunSequence(*base_ / "sequence", TrackingExperiment(), *base_ / "run"));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*base_);
    delete base_;
    delete summary_;
  }
  // A copy of the sequence in a folder of its own (folder / "sequence"), to spoil frames of.
  static fs::path CopyOfSequence(const std::string& name) {
    const fs::path folder = *base_ / name;
    fs::create_directories(folder);
    fs::copy(*base_ / "sequence", folder / "sequence", fs::copy_options::recursive);
    return folder;
  }
  // A grey instrument shaft from the right edge of a frame of a 320×240 sequence, its tip at
  // column `tip_x`.
  static void PaintShaft(const fs::path& sequence, int frame, int tip_x) {
    const fs::path file = sequence / "rgb" / FrameFileName(frame);
    cv::Mat image = cv::imread(file.string());
    const std::vector<cv::Point> shaft = {{tip_x, 50}, {320, 0}, {320, 240}, {tip_x, 190}};
    cv::fillConvexPoly(image, shaft, cv::Scalar(120, 125, 130));
    cv::imwrite(file.string(), image);
  }
  // Runs the copy in `folder` with `options` into folder / name, which must track every frame,
  // and returns the points found again over frames [first, end) and the run's summary.
  static std::pair<int, RunSummary> FoundAgain(const fs::path& folder, const std::string& name,
                                               const SystemOptions& options, int first, int end) {
    const RunSummary summary = RunSequence(folder / "sequence", options, folder / name);
    EXPECT_EQ(summary.frames_tracked, 40) << name;
    const auto metrics = ReadCsv(folder / name / "metrics.csv");
    int count = 0;
    for (int frame = first; frame < end && frame < static_cast<int>(metrics.size()); ++frame) {
      count += std::stoi(metrics[static_cast<size_t>(frame)].at("reassociated"));
    }
    return {count, summary};
  }
  // The shaft over the right three quarters of frames [first, end), hiding more than half of the view.
  static void PaintInstrument(const fs::path& sequence, int first, int end) {
    for (int frame = first; frame < end; ++frame) PaintShaft(sequence, frame, 80);
  }
  static fs::path* base_;
  static RunSummary* summary_;
};
fs::path* RunSequenceTest::base_ = nullptr;
RunSummary* RunSequenceTest::summary_ = nullptr;

TEST_F(RunSequenceTest, TracksEveryFrameAndBeatsAFrozenMapByFar) {
  EXPECT_EQ(summary_->init_frame, 0);
  EXPECT_EQ(summary_->frames_tracked, 40);
  EXPECT_EQ(summary_->frames_lost, 0);
  EXPECT_EQ(summary_->frames_evaluated, 40);
  EXPECT_LT(summary_->rmse_mm, 2.0);
  // 40 frames are 1.3 s: too short to tell a display from tissue the camera has barely moved past.
  EXPECT_EQ(summary_->input.static_fraction, 0);
  EXPECT_FALSE(fs::exists(*base_ / "run" / "static_mask.png"));
  EXPECT_EQ(CountLines(*base_ / "run" / "run.log", "the sequence spans 1.3 s, under static_min_seconds = 3.5 s"), 1);
  EXPECT_EQ(summary_->input.view_jumps, 0);
  // What a tracker that never moved would score: every tracked point at its initial depth.
  const SequenceReader reader(*base_ / "sequence");
  const std::vector<CsvPoint> points = ReadPointsCsv(*base_ / "run" / "points.csv");
  std::map<PointId, double> initial_depth;
  for (const CsvPoint& p : points) {
    if (p.frame == 0) initial_depth[p.id] = p.z;
  }
  std::map<int, std::vector<DepthPoint>> frozen;
  for (const CsvPoint& p : points) frozen[p.frame].push_back({{p.u, p.v}, initial_depth.at(p.id)});
  std::vector<FrameEvaluation> evaluations;
  for (const auto& [frame, depth_points] : frozen) {
    evaluations.push_back(EvaluateFrame(depth_points, reader.ReadDepthMm(frame), EvaluationOptions{}));
  }
  const double frozen_rmse = AggregateFrames(evaluations).rmse_mm;
  EXPECT_LT(summary_->rmse_mm, 0.5 * frozen_rmse) << "frozen map: " << frozen_rmse << " mm";
}

TEST_F(RunSequenceTest, SummaryRmseIsRecomputableFromPointsCsvAndGroundTruth) {
  const SequenceReader reader(*base_ / "sequence");
  std::map<int, std::vector<DepthPoint>> by_frame;
  for (const CsvPoint& p : ReadPointsCsv(*base_ / "run" / "points.csv")) by_frame[p.frame].push_back({{p.u, p.v}, p.z});
  std::vector<FrameEvaluation> evaluations;
  for (const auto& [frame, depth_points] : by_frame) {
    evaluations.push_back(EvaluateFrame(depth_points, reader.ReadDepthMm(frame), EvaluationOptions{}));
  }
  const SequenceMetrics recomputed = AggregateFrames(evaluations);
  const OtherAlignments other = EvaluateOtherAlignments(evaluations, EvaluationOptions{});  // one map: the run's only
  nlohmann::json summary;
  std::ifstream(*base_ / "run" / "summary.json") >> summary;
  // points.csv stores 9 significant digits; the RMSE agrees to far better than a micrometre.
  EXPECT_NEAR(recomputed.rmse_mm, summary.at("rmse_mm").get<double>(), 1e-5);
  EXPECT_NEAR(other.rmse_map_scale_mm, summary.at("rmse_map_scale_mm").get<double>(), 1e-5);
  EXPECT_NEAR(other.rmse_median_scale_mm, summary.at("rmse_median_scale_mm").get<double>(), 1e-5);
  // A map from depth is in millimetres from the start, so one scale costs little over a
  // scale per frame; a tracker whose scale drifted would pay here.
  EXPECT_GE(other.rmse_map_scale_mm, recomputed.rmse_mm - 1e-9);
  EXPECT_LT(other.rmse_map_scale_mm, 2.0 * recomputed.rmse_mm);
  EXPECT_NEAR(recomputed.rmse_median_mm, summary.at("rmse_median_mm").get<double>(), 1e-5);
  EXPECT_NEAR(recomputed.rmse_pooled_mm, summary.at("rmse_pooled_mm").get<double>(), 1e-5);
  EXPECT_NEAR(recomputed.rmse_flat_mm, summary.at("rmse_flat_mm").get<double>(), 1e-5);
  EXPECT_LT(summary.at("rmse_mm").get<double>(), 0.5 * summary.at("rmse_flat_mm").get<double>());
  EXPECT_EQ(summary.at("frames_tracked").get<int>(), 40);
  // Tracking alone makes no points: nothing is born after the map's first frame.
  EXPECT_EQ(summary.at("births_evaluated").get<int>(), 0);
  EXPECT_TRUE(summary.at("birth_log_error_mean").is_null());
}

// metrics.csv's median_depth is the median depth of the frame's points in points.csv, and
// summary.json's map_depth_change its last over its first. A map from depth is in millimetres,
// so the median is also the true median there, to the tracker's drift in scale (up to 6 % on
// these 40 frames).
TEST_F(RunSequenceTest, MedianDepthIsRecomputableFromPointsCsvAndFollowsTheTruth) {
  const SequenceReader reader(*base_ / "sequence");
  std::map<int, std::vector<DepthPoint>> by_frame;
  for (const CsvPoint& p : ReadPointsCsv(*base_ / "run" / "points.csv")) by_frame[p.frame].push_back({{p.u, p.v}, p.z});
  std::map<int, double> recorded;
  for (const auto& row : ReadCsv(*base_ / "run" / "metrics.csv")) {
    recorded[std::stoi(row.at("frame"))] = row.at("median_depth").empty() ? 0 : std::stod(row.at("median_depth"));
  }
  ASSERT_EQ(recorded.size(), 40u);
  ASSERT_EQ(by_frame.size(), 40u);
  for (const auto& [frame, depth_points] : by_frame) {
    const double median = MedianDepth(depth_points);
    EXPECT_NEAR(recorded.at(frame), median, 1e-7 * median) << "frame " << frame;
    const cv::Mat truth = reader.ReadDepthMm(frame);
    std::vector<double> true_depths;
    for (const DepthPoint& point : depth_points) {
      if (const std::optional<double> z = SampleDepth(truth, point.pixel)) true_depths.push_back(*z);
    }
    EXPECT_NEAR(median, Median(true_depths), 0.1 * Median(true_depths)) << "frame " << frame;
  }
  nlohmann::json summary;
  std::ifstream(*base_ / "run" / "summary.json") >> summary;
  EXPECT_NEAR(summary.at("map_depth_change").get<double>(), recorded.at(39) / recorded.at(0), 1e-6);
  EXPECT_TRUE(summary.at("map_depth_change_beyond_from").is_null());
  EXPECT_EQ(summary_->map_depth.Note(), "");
}

// A metrics.csv row reads back under the header's names with what it was given: an
// unscored frame leaves its RMSEs empty and its scale 0, a map with no points its median depth
// empty, and a note with commas and quotes stays one field.
TEST(MetricsCsv, ARowReadsBackUnderTheHeadersNames) {
  const fs::path folder = UniqueTempFolder("metrics_row");
  fs::create_directories(folder);
  MetricsRow tracked;
  tracked.frame = 7;
  tracked.state = TrackingState::kTracking;
  tracked.map = 2;
  tracked.points = 151;
  tracked.new_points = 12;
  tracked.new_point_depth_bias = 1.31;
  tracked.batch_rejected = true;
  FrameEvaluation evaluation;
  evaluation.evaluated = true;
  evaluation.scale = 48.5;
  evaluation.rmse_mm = 1.25;
  evaluation.flat_rmse_mm = 3.5;
  evaluation.points_without_groundtruth = 4;
  tracked.Score(evaluation);
  tracked.ms_total = 33.5;
  tracked.median_depth = 1.75;
  tracked.note = "view jump, \"12 px\"";
  MetricsRow unscored;
  unscored.frame = 8;
  unscored.state = TrackingState::kLost;
  evaluation.evaluated = false;
  unscored.Score(evaluation);
  {
    std::ofstream file = OpenForWriting(folder / "metrics.csv");
    file << MetricsCsvHeader() << '\n';
    WriteMetricsRow(file, tracked);
    WriteMetricsRow(file, unscored);
  }
  const auto rows = ReadCsv(folder / "metrics.csv");  // refuses a row whose fields miscount
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].at("frame"), "7");
  EXPECT_EQ(rows[0].at("state"), "tracking");
  EXPECT_EQ(rows[0].at("map"), "2");
  EXPECT_EQ(rows[0].at("points"), "151");
  EXPECT_EQ(rows[0].at("new_points"), "12");
  EXPECT_EQ(rows[0].at("new_point_depth_bias"), "1.31");
  EXPECT_EQ(rows[0].at("batch_rejected"), "1");
  EXPECT_EQ(rows[0].at("points_without_gt"), "4");
  EXPECT_EQ(rows[0].at("scale"), "48.5");
  EXPECT_EQ(rows[0].at("rmse_mm"), "1.250000");
  EXPECT_EQ(rows[0].at("rmse_flat_mm"), "3.500000");
  EXPECT_EQ(rows[0].at("ms_total"), "33.5");
  EXPECT_EQ(rows[0].at("median_depth"), "1.75");
  EXPECT_EQ(rows[0].at("note"), "view jump, \"12 px\"");
  EXPECT_EQ(rows[1].at("state"), "lost");
  EXPECT_EQ(rows[1].at("scale"), "0");
  EXPECT_EQ(rows[1].at("rmse_mm"), "");
  EXPECT_EQ(rows[1].at("rmse_flat_mm"), "");
  EXPECT_EQ(rows[1].at("median_depth"), "");
  EXPECT_EQ(rows[1].at("batch_rejected"), "0");
  EXPECT_EQ(rows[1].at("note"), "");
  fs::remove_all(folder);
}

TEST(MapDepthDrift, IsTheChangeOfTheMapNotGivenUpThatMovedMost) {
  MapDepthDrift drift;
  EXPECT_EQ(drift.Change().ratio, 0.0);
  EXPECT_EQ(drift.Change().Note(), "");
  drift.AddFrame(1, 0, 2.0);
  drift.AddFrame(1, 1, 0.0);  // no point reported: passed over
  drift.AddFrame(1, 2, 1.0);  // map 1: ×0.5
  drift.AddFrame(2, 3, 1.0);
  drift.AddFrame(2, 4, 50.0);  // beyond 10×, then back within it
  drift.AddFrame(2, 5, 3.0);   // map 2: ×3, its last over its first, not its largest
  EXPECT_DOUBLE_EQ(drift.Change().ratio, 3.0);
  EXPECT_EQ(drift.Change().beyond_from, -1);
  EXPECT_EQ(drift.Change().Note(), "");
  drift.AddFrame(3, 6, 100.0);
  drift.AddFrame(3, 7, 5.0);   // beyond
  drift.AddFrame(3, 8, 20.0);  // back within
  drift.AddFrame(3, 9, 1.0);   // beyond again, from here on
  drift.AddFrame(3, 10, 0.01);  // map 3: ×1e-4, the largest change either way
  const DepthChange most = drift.Change();
  EXPECT_DOUBLE_EQ(most.ratio, 1e-4);
  EXPECT_EQ(most.beyond_from, 9);
  EXPECT_EQ(most.Note().find("the map's median depth went ×0.0001 from its first tracked frame to its last, beyond "
                             "10× from frame 9 on"),
            0u)
      << most.Note();
  // A map given up for its depth change has a note of its own (GivenUpText): the change is
  // then of the maps not given up, and none when every map was.
  drift.GiveUp(3);
  EXPECT_DOUBLE_EQ(drift.Change().ratio, 3.0);
  EXPECT_EQ(drift.Change().Note(), "");
  drift.GiveUp(1);
  drift.GiveUp(2);
  EXPECT_EQ(drift.Change().ratio, 0.0);
  EXPECT_EQ(drift.Change().beyond_from, -1);
  drift.GiveUp(7);  // no depth recorded: nothing to give up, and no map made up
  drift.AddFrame(7, 11, 4.0);
  drift.AddFrame(7, 12, 2.0);
  EXPECT_DOUBLE_EQ(drift.Change().ratio, 0.5);
  EXPECT_EQ((DepthChange{25, 3}.Note().find("the map's median depth went ×25 from")), 0u);
  EXPECT_EQ(MedianDepth({}), 0.0);
  EXPECT_EQ(MedianDepth({{{0, 0}, 3.0}, {{1, 1}, 1.0}, {{2, 2}, 2.0}}), 2.0);
}

TEST_F(RunSequenceTest, TrajectoryErrorIsRecomputableFromTheTumFilesAndSmall) {
  const SequenceReader reader(*base_ / "sequence");
  TrajectorySegment map;
  double travel = 0;
  for (const StampedPose& pose : ReadTum(*base_ / "run" / "trajectory.tum")) {
    const auto frame = static_cast<size_t>(std::lround(pose.timestamp * reader.info().fps));
    map.estimated.push_back(pose.world_from_camera.translation);
    map.groundtruth.push_back(reader.groundtruth().at(frame).world_from_camera.translation);
    if (map.groundtruth.size() > 1) travel += (map.groundtruth.back() - map.groundtruth[map.groundtruth.size() - 2]).norm();
  }
  const TrajectoryError recomputed = AlignedTrajectoryError({map});
  nlohmann::json summary;
  std::ifstream(*base_ / "run" / "summary.json") >> summary;
  ASSERT_TRUE(recomputed.evaluated);
  EXPECT_NEAR(recomputed.rmse_mm, summary.at("ate_rmse_mm").get<double>(), 1e-5);
  EXPECT_NEAR(recomputed.scale, summary.at("ate_scale").get<double>(), 1e-5);
  EXPECT_EQ(summary.at("ate_frames").get<int>(), 40);
  std::cout << "trajectory error " << recomputed.rmse_mm << " mm over " << travel << " mm of travel, scale "
            << recomputed.scale << "\n";
  EXPECT_LT(recomputed.rmse_mm, 0.05 * travel);
  // Initialised from depth in mm: the map is already in mm.
  EXPECT_NEAR(recomputed.scale, 1.0, 0.1);
}

// Another system's output is scored as a run of ours: given this run's own points and
// trajectory as if they came from elsewhere, the scorer must reach the run's own figures, and
// its run folder must be one that the other tools read (here, the common-point comparison).
TEST_F(RunSequenceTest, ScoringTheRunsOwnOutputAsAnExternalResultGivesItsSummary) {
  ExternalResult external;
  external.estimates = *base_ / "run" / "points.csv";
  external.trajectory = *base_ / "run" / "trajectory.tum";
  external.name = "the run itself";
  const fs::path scored = *base_ / "scored";
  const RunSummary summary = ScoreExternalResult(*base_ / "sequence", external, EvaluationOptions{}, scored);
  EXPECT_EQ(summary.frames_tracked, summary_->frames_tracked);
  EXPECT_EQ(summary.init_frame, 0);
  EXPECT_EQ(summary.Status(), "ok");
  EXPECT_EQ(summary.frames_evaluated, summary_->frames_evaluated);
  EXPECT_NEAR(summary.rmse_mm, summary_->rmse_mm, 1e-5);
  EXPECT_NEAR(summary.rmse_flat_mm, summary_->rmse_flat_mm, 1e-5);
  EXPECT_NEAR(summary.rmse_map_scale_mm, summary_->rmse_map_scale_mm, 1e-5);
  EXPECT_NEAR(summary.rmse_median_scale_mm, summary_->rmse_median_scale_mm, 1e-5);
  EXPECT_NEAR(summary.map_depth.ratio, summary_->map_depth.ratio, 1e-7);
  ASSERT_TRUE(summary.trajectory_error.evaluated);
  EXPECT_NEAR(summary.trajectory_error.rmse_mm, summary_->trajectory_error.rmse_mm, 1e-4);
  for (const char* file : {"config.json", "points.csv", "metrics.csv", "summary.json", "trajectory.tum"}) {
    EXPECT_TRUE(fs::exists(scored / file)) << file;
  }
  EXPECT_TRUE(fs::exists(scored / "depth" / "000039.png"));
  nlohmann::json written;
  std::ifstream(scored / "summary.json") >> written;
  EXPECT_EQ(written.at("mode"), "external");
  EXPECT_NEAR(written.at("rmse_mm").get<double>(), summary_->rmse_mm, 1e-5);
  // The world positions it derives from pixel, depth and pose are the run's own, up to the
  // reprojection residual of a kept point (under 2.45 px: ~0.7 mm at these depths); a pose
  // taken the wrong way round would put them many millimetres off.
  const std::vector<CsvPoint> own = ReadPointsCsv(*base_ / "run" / "points.csv");
  const std::vector<CsvPoint> derived = ReadPointsCsv(scored / "points.csv");
  ASSERT_EQ(own.size(), derived.size());
  std::vector<double> offsets;
  for (size_t i = 0; i < own.size(); ++i) offsets.push_back((own[i].world - derived[i].world).norm());
  std::sort(offsets.begin(), offsets.end());
  EXPECT_LT(offsets[offsets.size() / 2], 0.1);
  EXPECT_LT(offsets.back(), 1.0);
  const CommonPointsComparison comparison = CompareRunFolders(*base_ / "run", scored);
  EXPECT_EQ(comparison.frames, summary_->frames_evaluated);
  EXPECT_NEAR(comparison.b_common.rmse_mm, summary_->rmse_mm, 1e-5);
  EXPECT_NEAR(CompareRunFolders(scored, *base_ / "run").a_own.rmse_mm, summary_->rmse_mm, 1e-5);
}

// Known answers: depth images that are the ground truth at half scale, for frames 0–9 but 5,
// score an RMSE of 0 at a scale of 2, and the frames without an image count as lost.
TEST_F(RunSequenceTest, ExternalDepthImagesScoreAsKnown) {
  const SequenceReader reader(*base_ / "sequence");
  const fs::path images = *base_ / "half_depth";
  fs::create_directories(images);
  setenv("OPENCV_IO_ENABLE_OPENEXR", "1", 0);
  for (int frame = 0; frame < 10; ++frame) {
    if (frame == 5) continue;
    cv::Mat half;
    reader.ReadDepthMm(frame).convertTo(half, CV_32F, 0.5);
    const std::string format = frame == 9 ? ".exr" : ".tiff";  // both kinds a depth network writes
    ASSERT_TRUE(cv::imwrite((images / ("estimate_" + std::to_string(frame) + format)).string(), half));
  }
  std::ofstream(images / "notes.txt") << "not an estimate\n";
  ExternalResult external;
  external.estimates = images;
  external.depth_stride_px = 4;
  const fs::path scored = *base_ / "scored_images";
  const RunSummary summary = ScoreExternalResult(*base_ / "sequence", external, EvaluationOptions{}, scored);
  EXPECT_EQ(summary.init_frame, 0);
  EXPECT_EQ(summary.frames_tracked, 9);
  EXPECT_EQ(summary.frames_lost, 31);
  EXPECT_EQ(summary.Status(), "lost");
  EXPECT_EQ(summary.stop_frame, 10);
  EXPECT_EQ(summary.frames_evaluated, 9);
  EXPECT_LT(summary.rmse_mm, 1e-6);
  EXPECT_GT(summary.rmse_flat_mm, 1.0);  // a shape was there to be recovered
  EXPECT_FALSE(summary.trajectory_error.evaluated);
  const std::vector<std::map<std::string, std::string>> metrics = ReadCsv(scored / "metrics.csv");
  ASSERT_EQ(metrics.size(), 40u);
  EXPECT_NEAR(Number(metrics[3], "scale"), 2.0, 1e-9);
  EXPECT_EQ(metrics[5].at("state"), "lost");
  EXPECT_GT(Number(metrics[3], "points"), 1000);  // 80×60 samples, those on the surface
  // Its ids number pixels, not points: nothing may pair them with a run's point ids, and no
  // point is born.
  EXPECT_THROW(CompareRunFolders(*base_ / "run", scored), Error);
  EXPECT_EQ(summary.births.births_evaluated, 0);
  EXPECT_EQ(summary.input.frames_depth_inverted, 0);
  // Inverse depth, as a depth network writes disparity, is scored but named for what it is.
  const fs::path inverse_images = *base_ / "inverse_depth";
  fs::create_directories(inverse_images);
  for (int frame = 0; frame < 10; ++frame) {
    cv::Mat inverse;
    cv::divide(1000.0, reader.ReadDepthMm(frame), inverse, CV_32F);  // 0 where the depth is 0
    ASSERT_TRUE(cv::imwrite((inverse_images / (std::to_string(frame) + ".tiff")).string(), inverse));
  }
  external.estimates = inverse_images;
  const RunSummary inverted = ScoreExternalResult(*base_ / "sequence", external, EvaluationOptions{}, scored);
  EXPECT_EQ(inverted.frames_evaluated, 10);
  EXPECT_EQ(inverted.input.frames_depth_inverted, 10);
  EXPECT_NE(DescribeSummary(inverted).find("10 scored frames have estimates that fall as the true depth rises"),
            std::string::npos) << DescribeSummary(inverted);
}

// An external result whose ids name points gets its births scored: the run's own points, plus
// one that appears at frame 10 a quarter too far, on the pixel of a point tracked there.
TEST_F(RunSequenceTest, ExternalPointsBornTooFarAreScoredSo) {
  const std::vector<CsvPoint> own = ReadPointsCsv(*base_ / "run" / "points.csv");
  const auto write = [&](const fs::path& file, bool with_ids) {
    std::ofstream csv(file);
    csv << (with_ids ? "frame,point_id,u,v,z_est\n" : "frame,u,v,z_est\n");
    std::optional<CsvPoint> added;
    for (const CsvPoint& p : own) {
      csv << p.frame << ',' << (with_ids ? std::to_string(p.id) + "," : "") << p.u << ',' << p.v << ',' << p.z << '\n';
      if (p.frame >= 10 && !added) added = CsvPoint{p.frame, 1000000, p.u, p.v, 1.25 * p.z, {}};
    }
    ASSERT_TRUE(added);
    csv << added->frame << ',' << (with_ids ? "1000000," : "") << added->u << ',' << added->v << ',' << added->z << '\n';
  };
  write(*base_ / "born_far.csv", true);
  write(*base_ / "born_far_no_ids.csv", false);
  ExternalResult external;
  external.estimates = *base_ / "born_far.csv";
  const RunSummary summary = ScoreExternalResult(*base_ / "sequence", external, EvaluationOptions{}, *base_ / "born_far");
  ASSERT_EQ(summary.births.births_evaluated, 1);
  // log 1.25 = 0.22, off by the tracked point's own depth error (well under 10 % here).
  EXPECT_NEAR(*summary.births.mean, std::log(1.25), 0.1);
  external.estimates = *base_ / "born_far_no_ids.csv";
  const RunSummary without_ids =
      ScoreExternalResult(*base_ / "sequence", external, EvaluationOptions{}, *base_ / "born_far_no_ids");
  EXPECT_EQ(without_ids.births.births_evaluated, 0);  // rows of a frame name no point
}

TEST_F(RunSequenceTest, BadExternalResultsGiveOneClearError) {
  const auto error_of = [&](const std::string& csv) {
    const fs::path file = *base_ / "bad.csv";
    std::ofstream(file) << csv;
    ExternalResult external;
    external.estimates = file;
    try {
      ScoreExternalResult(*base_ / "sequence", external, EvaluationOptions{}, *base_ / "scored_bad");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error_of("frame,u,v\n0,1,2\n").find("no column 'z'"), std::string::npos);
  EXPECT_NE(error_of("frame,u,v,z\n0,1,2,3\n0,1,x,3\n").find("bad.csv:3: 'x' (v) is not a number"), std::string::npos);
  EXPECT_NE(error_of("frame,u,v,z\n40,1,2,3\n").find("frame 40 is not a frame of the sequence"), std::string::npos);
  EXPECT_NE(error_of("frame,u,v,z\n0,1,2\n").find("3 fields, the header needs 4"), std::string::npos);
  EXPECT_NE(error_of("frame,point_id,u,v,z\n0,2.5,1,2,3\n").find("bad.csv:2: '2.5' (point_id) is not a whole number"),
            std::string::npos);
  EXPECT_NE(error_of("frame,point_id,u,v,z\n0,nan,1,2,3\n").find("'nan' (point_id) is not a whole number"),
            std::string::npos);
  EXPECT_NE(error_of("frame,point_id,u,v,z\n0,7,1,2,3\n1,7,1,2,3\n1,7,5,2,3\n")
                .find("bad.csv:4: point_id 7 a second time in frame 1"),
            std::string::npos);
  // An estimate a system failed to make (NaN, 0) is no estimate, not a broken file.
  EXPECT_EQ(error_of("frame,u,v,z\n0,10,20,nan\n1,10,20,0\n"), "no error");
  // Files as other programs write them: spaces after the commas, a spreadsheet's quoted header
  // and byte-order mark, Windows line ends.
  EXPECT_EQ(error_of("frame, u, v, z\n0, 10, 20, 30\n"), "no error");
  EXPECT_EQ(error_of("\xEF\xBB\xBF\"frame\",\"u\",\"v\",\"z\"\r\n0,10,20,30\r\n"), "no error");
  // Pixels that cannot be the image's: u and v swapped (2 of 10 beyond the 240 rows), or
  // normalised coordinates, would be scored against the wrong pixels' ground truth.
  const auto rows = [](int count, const std::function<std::string(int)>& row) {
    std::string csv = "frame,u,v,z\n";
    for (int i = 0; i < count; ++i) csv += row(i) + "\n";
    return csv;
  };
  ASSERT_EQ(SequenceReader(*base_ / "sequence").info().camera.height(), 240);
  const std::string swapped = error_of(rows(10, [](int i) { return "0,10," + std::to_string(30 * i) + ",30"; }));
  EXPECT_NE(swapped.find("2 of its 10 estimates lie outside the 320x240 image (u 10.0 … 10.0, v 0.0 … 270.0)"),
            std::string::npos) << swapped;
  const std::string normalised = error_of(rows(10, [](int i) { return "0,0." + std::to_string(i) + ",0.5,30"; }));
  EXPECT_NE(normalised.find("all 10 estimates lie within two pixels of each other"), std::string::npos) << normalised;
  EXPECT_NE(normalised.find("not normalised coordinates"), std::string::npos) << normalised;
  // One of twenty outside (a point leaving the view) is left out and noted.
  std::ofstream(*base_ / "one_outside.csv")
      << rows(20, [](int i) { return "0," + std::to_string(i == 0 ? 320 : 15 * i) + ",100,30"; });
  ExternalResult one_outside;
  one_outside.estimates = *base_ / "one_outside.csv";
  const RunSummary noted =
      ScoreExternalResult(*base_ / "sequence", one_outside, EvaluationOptions{}, *base_ / "scored_one_outside");
  EXPECT_EQ(noted.input.estimates_outside_image, 1);
  EXPECT_NE(DescribeSummary(noted).find("1 estimate lay outside the image and was left out"), std::string::npos)
      << DescribeSummary(noted);
  EXPECT_EQ(ReadPointsCsv(*base_ / "scored_one_outside" / "points.csv").size(), 19u);
  // A trajectory on a clock of its own (here the epoch's) is named as such.
  std::ofstream(*base_ / "epoch.tum") << "1600000000.0 0 0 0 0 0 0 1\n";
  one_outside.trajectory = *base_ / "epoch.tum";
  const std::string clock = ErrorMessage(
      [&] { ScoreExternalResult(*base_ / "sequence", one_outside, EvaluationOptions{}, *base_ / "scored_bad"); });
  EXPECT_NE(clock.find("no frame of the sequence is at that time; times are frame / fps, 0 … "), std::string::npos)
      << clock;
  ExternalResult images;
  images.estimates = *base_ / "wrong_size";
  fs::create_directories(images.estimates);
  cv::imwrite((images.estimates / "000000.png").string(), cv::Mat(10, 10, CV_16UC1, cv::Scalar(100)));
  EXPECT_THROW(ScoreExternalResult(*base_ / "sequence", images, EvaluationOptions{}, *base_ / "scored_bad"), Error);
  const fs::path empty = *base_ / "empty_folder";
  fs::create_directories(empty);
  images.estimates = empty;
  EXPECT_THROW(ScoreExternalResult(*base_ / "sequence", images, EvaluationOptions{}, *base_ / "scored_bad"), Error);
  images.estimates = *base_ / "missing";
  EXPECT_THROW(ScoreExternalResult(*base_ / "sequence", images, EvaluationOptions{}, *base_ / "scored_bad"), Error);
}

// A run folder's config.json repeats the run: the same options, and the same trajectory.
// A run compared with itself shares every point: the common-point score is its own summary's.
TEST_F(RunSequenceTest, ComparedWithItselfACommonPointScoreIsItsOwnSummary) {
  const CommonPointsComparison comparison = CompareRunFolders(*base_ / "run", *base_ / "run");
  EXPECT_EQ(comparison.frames, summary_->frames_evaluated);
  EXPECT_DOUBLE_EQ(comparison.mean_common_points, comparison.mean_points_a);
  // points.csv holds 6 significant digits: the scores match the summary to about that.
  EXPECT_NEAR(comparison.a_own.rmse_mm, summary_->rmse_mm, 1e-6);
  EXPECT_NEAR(comparison.a_common.rmse_mm, summary_->rmse_mm, 1e-6);
  EXPECT_NEAR(comparison.b_common.rmse_mm, summary_->rmse_mm, 1e-6);
  EXPECT_EQ(comparison.a_common.rmse_mm, comparison.a_own.rmse_mm);
  // Runs of different sequences are refused, not compared.
  const fs::path other = *base_ / "other_run";
  fs::create_directories(other);
  nlohmann::json config;
  std::ifstream(*base_ / "run" / "config.json") >> config;
  config["sequence"] = (*base_ / "elsewhere").string();
  std::ofstream(other / "config.json") << config.dump();
  fs::copy_file(*base_ / "run" / "points.csv", other / "points.csv");
  EXPECT_THROW(CompareRunFolders(*base_ / "run", other), Error);
}

TEST_F(RunSequenceTest, SavedConfigRepeatsTheRun) {
  const SystemOptions loaded = SystemOptionsFromFile(*base_ / "run" / "config.json");
  EXPECT_EQ(Json(loaded), Json(TrackingExperiment()));
  const RunSummary repeated = RunSequence(*base_ / "sequence", loaded, *base_ / "repeated");
  EXPECT_EQ(repeated.frames_tracked, summary_->frames_tracked);
  EXPECT_EQ(repeated.rmse_mm, summary_->rmse_mm);
  EXPECT_EQ(FileText(*base_ / "repeated" / "trajectory.tum"), FileText(*base_ / "run" / "trajectory.tum"));
}

// A run into the folder of an earlier, longer run leaves nothing of that run behind (a stale
// summary.json or depth map would pass for the new run's), but keeps files of the user's own.
TEST_F(RunSequenceTest, ARunIntoAnEarlierRunsFolderReplacesItsOutput) {
  const fs::path reused = *base_ / "reused";
  fs::remove_all(reused);
  fs::copy(*base_ / "run", reused, fs::copy_options::recursive);
  std::ofstream(reused / "notes.txt") << "mine";
  ASSERT_TRUE(fs::exists(reused / "depth" / "000039.png"));
  SystemOptions shorter = TrackingExperiment();
  shorter.run.last_frame = 5;
  const RunSummary summary = RunSequence(*base_ / "sequence", shorter, reused);
  EXPECT_EQ(summary.frames_tracked, 5);
  int depth_maps = 0;
  for (const auto& entry : fs::directory_iterator(reused / "depth")) {
    ++depth_maps;
    EXPECT_LT(std::stoi(entry.path().stem().string()), 5) << entry.path();
  }
  EXPECT_EQ(depth_maps, 5);
  EXPECT_EQ(SystemOptionsFromFile(reused / "config.json").run.last_frame, 5);
  EXPECT_TRUE(fs::exists(reused / "notes.txt"));
}

// How far each map point moved in the world between the first and the last frame it was reported in.
std::vector<double> PointMovementsMm(const fs::path& points_csv) {
  std::map<PointId, std::pair<Eigen::Vector3d, Eigen::Vector3d>> first_last;
  for (const CsvPoint& p : ReadPointsCsv(points_csv)) {
    const auto [it, added] = first_last.emplace(p.id, std::make_pair(p.world, p.world));
    it->second.second = p.world;
  }
  std::vector<double> movements;
  for (const auto& [id, ends] : first_last) movements.push_back((ends.second - ends.first).norm());
  return movements;
}

TEST_F(RunSequenceTest, StiffDisplacementPriorHoldsThePointsWhereTheyWere) {
  SystemOptions options = TrackingExperiment();
  options.tracking.displacement_prior_sigma = 1e-6;  // map-scale units: δ can hardly leave 0
  RunSequence(*base_ / "sequence", options, *base_ / "held");  // a frozen map may lose a deforming scene: fine
  const std::vector<double> held = PointMovementsMm(*base_ / "held" / "points.csv");
  const std::vector<double> free = PointMovementsMm(*base_ / "run" / "points.csv");
  ASSERT_FALSE(held.empty());
  EXPECT_LT(*std::max_element(held.begin(), held.end()), 1e-3);
  // Without the prior the same points follow the tissue (A = 5 mm).
  EXPECT_GT(std::accumulate(free.begin(), free.end(), 0.0) / free.size(), 0.5);
}

TEST_F(RunSequenceTest, MotionSeedStartsTheSolvesElsewhereAndStillTracks) {
  SystemOptions options = TrackingExperiment();
  options.tracking.deformation_motion_seed = true;
  const RunSummary seeded = RunSequence(*base_ / "sequence", options, *base_ / "seeded");
  EXPECT_EQ(seeded.frames_tracked, 40);
  EXPECT_LT(seeded.rmse_mm, 2.0);
  // The solves are not run to convergence, so a different start gives a different run.
  EXPECT_NE(seeded.rmse_mm, summary_->rmse_mm);
}

// Each regulariser can be switched off for an ablation, and tracking then solves another problem.
TEST_F(RunSequenceTest, RegularisersCanBeAblatedOneByOne) {
  for (const bool elastic : {false, true}) {
    SystemOptions options = TrackingExperiment();
    options.deformation.elastic = elastic;
    options.deformation.viscous = !elastic;
    const std::string name = elastic ? "elastic_only" : "viscous_only";
    const RunSummary ablated = RunSequence(*base_ / "sequence", options, *base_ / name);
    EXPECT_GT(ablated.frames_tracked, 0) << name;
    EXPECT_NE(ablated.rmse_mm, summary_->rmse_mm) << name;
    EXPECT_EQ(ReadJsonFile(*base_ / name / "config.json")["options"]["deformation"]["elastic"], elastic) << name;
  }
}

// With a cap on the joint solve the points it leaves out move with their solved neighbours
// (metrics.csv counts them among the propagated) and are still tracked and scored.
TEST_F(RunSequenceTest, AJointSolveCapLeavesPointsToTheirNeighboursAndStillTracks) {
  constexpr int kCap = 40;
  SystemOptions options = TrackingExperiment();
  options.tracking.joint_solve_max_points = kCap;
  const RunSummary capped = RunSequence(*base_ / "sequence", options, *base_ / "capped");
  EXPECT_EQ(capped.frames_tracked, 40);
  EXPECT_LT(capped.rmse_mm, 2.0);
  EXPECT_NE(capped.rmse_mm, summary_->rmse_mm);
  const auto propagated = [](const fs::path& run) {
    std::vector<int> counts;
    for (const auto& row : ReadCsv(run / "metrics.csv")) counts.push_back(std::stoi(row.at("propagated")));
    return counts;
  };
  const std::vector<int> capped_moves = propagated(*base_ / "capped"), free_moves = propagated(*base_ / "run");
  ASSERT_EQ(capped_moves.size(), free_moves.size());
  // On the first tracked frame nothing is lost or demoted yet, and ~200 points are in view:
  // all but the cap's are left to their neighbours, and they are still reported.
  const auto first = ReadCsv(*base_ / "capped" / "metrics.csv").at(1);
  EXPECT_EQ(free_moves.at(1), 0);
  EXPECT_GT(capped_moves.at(1), 3 * kCap);
  EXPECT_GT(std::stoi(first.at("points")), 3 * kCap);
  for (size_t frame = 1; frame < capped_moves.size(); ++frame) {
    EXPECT_GT(capped_moves[frame], free_moves[frame]) << "frame " << frame;
  }
  EXPECT_THROW(WithRunAssignments(SystemOptions{}, {"tracking.joint_solve_max_points=5"}), Error);
}

TEST(MotionSeed, TheCommonMotionIsRemovedAndTheRestKept) {
  const std::vector<Eigen::Vector3d> relative =
      WithoutCommonMotion({{1.0, 2.0, 3.0}, {3.0, 2.0, 1.0}, {2.0, 5.0, 2.0}});
  ASSERT_EQ(relative.size(), 3u);
  EXPECT_TRUE(relative[0].isApprox(Eigen::Vector3d(-1.0, -1.0, 1.0)));
  EXPECT_TRUE(relative[1].isApprox(Eigen::Vector3d(1.0, -1.0, -1.0)));
  EXPECT_TRUE(relative[2].isApprox(Eigen::Vector3d(0.0, 2.0, 0.0)));
  EXPECT_TRUE(WithoutCommonMotion({{4.0, -1.0, 7.0}})[0].isZero());  // one point: all of it is common
  EXPECT_TRUE(WithoutCommonMotion({}).empty());
}

TEST(SystemOptionsNames, UniqueLastNamesResolveToFullPaths) {
  EXPECT_EQ(ResolveRunAssignment("k=2"), "deformation.k=2");
  EXPECT_EQ(ResolveRunAssignment("max_degree_D=5"), "deformation.max_degree_D=5");
  EXPECT_EQ(ResolveRunAssignment("mapping.dba_window=7"), "mapping.dba_window=7");
  EXPECT_EQ(ResolveRunAssignment("camera={\"a\": 1}"), "run.camera={\"a\": 1}");  // only the name resolved
  EXPECT_THROW(ResolveRunAssignment("min_points=5"), Error);  // evaluation, initialisation and tracking
  EXPECT_THROW(ResolveRunAssignment("kk=2"), Error);
  // The paper's σ is sigma_factor times the initial map's depth spread: the name alone points there.
  try {
    ResolveRunAssignment("sigma=2");
    FAIL() << "'sigma' resolved";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("did you mean"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("deformation.sigma_factor"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find("deformation.k,"), std::string::npos) << "the whole list: " << e.what();
  }
  EXPECT_THROW(ResolveRunAssignment("k"), Error);
  // A command line's --set list: short names resolved, applied in order, values checked.
  const SystemOptions set = WithRunAssignments(SystemOptions{}, {"k=2", "mapping.dba_window=7", "k=3"});
  EXPECT_EQ(set.deformation.k, 3);
  EXPECT_EQ(set.mapping.dba_window, 7);
  EXPECT_THROW(WithRunAssignments(SystemOptions{}, {"kk=2"}), Error);
  EXPECT_THROW(WithRunAssignments(SystemOptions{}, {"displacement_prior_sigma=-1"}), Error);
}

TEST(SystemOptionsNames, AssignmentsOverTheDefaultsGiveTheOptionsBack) {
  SystemOptions options;
  options.deformation.k = 3;
  options.mapping.dba_window = 7;
  options.run.init = "depth";
  const std::vector<std::string> assignments = AssignmentsOverDefaults(options);
  EXPECT_EQ(assignments, (std::vector<std::string>{"deformation.k=3.0", "mapping.dba_window=7", "run.init=depth"}));
  EXPECT_EQ(Json(WithAssignments(SystemOptions{}, assignments)), Json(options));
  EXPECT_TRUE(AssignmentsOverDefaults(SystemOptions{}).empty());
}

TEST(SystemOptionsFile, PartialOptionsOverTheDefaultsAndUnknownKeysRejected) {
  const fs::path folder = UniqueTempFolder("nrslam_options_file");
  fs::create_directories(folder);
  std::ofstream(folder / "partial.json") << R"({"mapping": {"dba_window": 7}, "run": {"init": "depth"}})";
  const SystemOptions partial = SystemOptionsFromFile(folder / "partial.json");
  SystemOptions expected;
  expected.mapping.dba_window = 7;
  expected.run.init = "depth";
  EXPECT_EQ(Json(partial), Json(expected));
  std::ofstream(folder / "typo.json") << R"({"mapping": {"dba_widnow": 7}})";
  try {
    SystemOptionsFromFile(folder / "typo.json");
    ADD_FAILURE() << "an unknown key must be an error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("dba_widnow"), std::string::npos) << error.what();
  }
  std::ofstream(folder / "invalid.json") << R"({"mapping": {"dba_window": -1}})";
  EXPECT_THROW(SystemOptionsFromFile(folder / "invalid.json"), Error);
  std::ofstream(folder / "list.json") << "[1, 2]";
  EXPECT_THROW(SystemOptionsFromFile(folder / "list.json"), Error);
  EXPECT_THROW(SystemOptionsFromFile(folder / "missing.json"), Error);
  fs::remove_all(folder);
}

// The sum of a metrics.csv column over the frames.
double SumColumn(const fs::path& csv, const std::string& column) {
  std::ifstream file(csv);
  std::string line, field;
  std::getline(file, line);
  std::istringstream header(line);
  int index = 0, wanted = -1;
  while (std::getline(header, field, ',')) {
    if (field == column) wanted = index;
    ++index;
  }
  double sum = 0;
  while (wanted >= 0 && std::getline(file, line)) {
    std::istringstream fields(line);
    for (int i = 0; i <= wanted && std::getline(fields, field, ','); ++i) {
      if (i == wanted) sum += std::stod(field);
    }
  }
  return sum;
}

TEST_F(RunSequenceTest, RunFolderHoldsEveryOutput) {
  const fs::path run = *base_ / "run";
  for (const char* file : {"config.json", "trajectory.tum", "points.csv", "metrics.csv", "summary.json", "map.ply",
                           "run.log"}) {
    EXPECT_TRUE(fs::exists(run / file)) << file;
  }
  nlohmann::json config;
  std::ifstream(run / "config.json") >> config;
  EXPECT_EQ(config.at("options"), nlohmann::json(TrackingExperiment()));  // every resolved option
  // ... and the code that ran: a commit, with a hash of uncommitted edits, or "unknown".
  const std::string revision = config.at("nrslam_revision");
  EXPECT_EQ(revision, SourceRevision());
  EXPECT_TRUE(std::regex_match(revision, std::regex("[0-9a-f]{12}(-dirty-[0-9a-f]{8})?|unknown"))) << revision;
  const std::string code = config.at("nrslam_code");
  EXPECT_EQ(code, CodeFingerprint());
  EXPECT_TRUE(std::regex_match(code, std::regex("[0-9a-f]{12}"))) << code;
  EXPECT_EQ(ReadTum(run / "trajectory.tum").size(), 40u);
  EXPECT_TRUE(fs::exists(run / "depth" / "000039.png"));
  const std::string metrics = FileText(run / "metrics.csv");
  EXPECT_EQ(std::count(metrics.begin(), metrics.end(), '\n'), 41);  // header + one per frame
  // The solver timings are parts of the deformation stage's, which is what they break down.
  const double deformation = SumColumn(run / "metrics.csv", "ms_deformation");
  const double joint_solve = SumColumn(run / "metrics.csv", "ms_joint_solve");
  const double linear_solve = SumColumn(run / "metrics.csv", "ms_linear_solve");
  EXPECT_GT(linear_solve, 0.0);
  EXPECT_LE(linear_solve, joint_solve);
  EXPECT_LE(joint_solve, deformation);
  nlohmann::json summary;
  std::ifstream(run / "summary.json") >> summary;
  const nlohmann::json& per_frame = summary.at("ms_per_frame");
  EXPECT_NEAR(per_frame.at("tracking_linear_solve").get<double>(), linear_solve / 40.0,
              1e-4 * linear_solve);  // metrics.csv holds 6 significant digits
  EXPECT_LT(per_frame.at("tracking_linear_solve").get<double>(), per_frame.at("tracking").get<double>());
  // The process's peak memory: a test process holding images, pyramids and a Ceres problem
  // holds more than 10 MB, and far less than the machine.
  EXPECT_GT(summary.at("peak_memory_mb").get<double>(), 10.0);
  EXPECT_LT(summary.at("peak_memory_mb").get<double>(), 8192.0);
}

// The full system from the images alone (depth only for the evaluation), 60 frames (320x240
// unless said).
struct MonocularOutcome {
  RunSummary summary;
  int new_points = 0;     // tracked points that were not in the initial map
  int deformable_candidates = 0;  // summed over metrics.csv
  int rigid_dba = 0, deformable_dba = 0;  // windows after the warm-up, by the model selected (run.log)
  std::vector<std::map<std::string, std::string>> metrics;  // metrics.csv, a row per frame
  // log(s·z / true depth) of each new point on the frame it was first tracked, with s that
  // frame's median ratio of true to estimated depth (eval/birth_errors.h), from points.csv.
  std::vector<double> birth_log_errors;
  // How well new points are placed: the median of those errors' sizes, and the fraction off
  // by more than a factor of 2.
  double new_point_log_depth_error = 0;
  double new_point_gross_error_fraction = 0;
  // The first two tracked frames (reference-behaviour §9.2's keyframe-queue bug reset both to
  // the reference view): per frame, the median distance of the points' pixels from their
  // world positions projected through the frame's own pose, and through the reference view's.
  std::vector<double> first_frames_reprojection_px, first_frames_offset_from_reference_px;
  // Points reported twice in a frame: the same id, or two ids at one pixel (one track feeding
  // two map points, §9.2's re-triangulated track).
  int repeated_points = 0;
};

// log(s·z / true depth) of each new point on the frame it was first tracked, recomputed from
// points.csv as the evaluator does it for summary.json (eval/birth_errors.h).
std::vector<double> NewPointLogDepthErrors(const std::vector<CsvPoint>& points, const SequenceReader& sequence,
                                           int init_frame) {
  std::map<int, std::vector<const CsvPoint*>> by_frame;
  for (const CsvPoint& p : points) by_frame[p.frame].push_back(&p);
  BirthErrors births;
  for (const auto& [frame, frame_points] : by_frame) {
    std::vector<int64_t> ids;
    std::vector<DepthPoint> depth_points;
    for (const CsvPoint* p : frame_points) {
      ids.push_back(p->id);
      depth_points.push_back({{p->u, p->v}, p->z});
    }
    const cv::Mat depth = sequence.ReadDepthMm(frame);
    births.AddFrame(ids, depth_points, depth, EvaluateFrame(depth_points, depth, EvaluationOptions{}),
                    frame == init_frame);
  }
  return births.log_errors();
}

// Fills the outcome's pixel checks (the first two tracked frames, points reported twice) of a
// monocular run with one map, whose world frame is the reference camera's.
void FillPixelChecks(const std::vector<CsvPoint>& points, const fs::path& folder, int init_frame,
                     MonocularOutcome* outcome) {
  const SequenceReader sequence(folder / "sequence");
  const Camera& camera = sequence.info().camera;
  std::map<int, Rigid3> cam_from_world;
  for (const StampedPose& pose : ReadTum(folder / "run" / "trajectory.tum")) {
    cam_from_world[static_cast<int>(std::lround(pose.timestamp * sequence.info().fps))] = pose.world_from_camera.Inverse();
  }
  std::map<int, std::vector<double>> reprojection, offset;
  std::set<std::pair<int, PointId>> ids;
  std::set<std::tuple<int, double, double>> pixels;
  for (const CsvPoint& p : points) {
    outcome->repeated_points += !ids.emplace(p.frame, p.id).second || !pixels.emplace(p.frame, p.u, p.v).second;
    if (p.frame != init_frame && p.frame != init_frame + 1) continue;
    const Eigen::Vector2d pixel(p.u, p.v);
    const auto seen = camera.Project(cam_from_world.at(p.frame) * p.world);
    const auto from_reference = camera.Project(p.world);
    if (!seen || !from_reference) continue;
    reprojection[p.frame].push_back((*seen - pixel).norm());
    offset[p.frame].push_back((*from_reference - pixel).norm());
  }
  for (const auto& [frame, distances] : reprojection) {
    outcome->first_frames_reprojection_px.push_back(Median(distances));
    outcome->first_frames_offset_from_reference_px.push_back(Median(offset.at(frame)));
  }
}

MonocularOutcome RunMonocular(const std::string& preset, const SystemOptions& options, int width = 320,
                              int height = 240) {
  const fs::path folder = UniqueTempFolder("nrslam_monocular_" + preset);
  fs::remove_all(folder);
  SimulateSmall(preset, 60, width, height, folder / "sequence");
  MonocularOutcome outcome;
  outcome.summary = RunSequence(folder / "sequence", options, folder / "run");
  const std::vector<CsvPoint> points = ReadPointsCsv(folder / "run" / "points.csv");
  std::set<PointId> initial, later;
  for (const CsvPoint& p : points) (p.frame == outcome.summary.init_frame ? initial : later).insert(p.id);
  for (PointId id : later) outcome.new_points += initial.count(id) == 0;
  outcome.deformable_candidates = static_cast<int>(SumColumn(folder / "run" / "metrics.csv", "deformable_candidates"));
  outcome.metrics = ReadCsv(folder / "run" / "metrics.csv");
  outcome.birth_log_errors = NewPointLogDepthErrors(points, SequenceReader(folder / "sequence"), outcome.summary.init_frame);
  std::vector<double> errors;
  for (double error : outcome.birth_log_errors) errors.push_back(std::abs(error));
  if (!errors.empty()) {
    outcome.new_point_log_depth_error = Median(errors);
    outcome.new_point_gross_error_fraction =
        static_cast<double>(std::count_if(errors.begin(), errors.end(), [](double e) { return e > std::log(2.0); })) /
        static_cast<double>(errors.size());
  }
  FillPixelChecks(points, folder, outcome.summary.init_frame, &outcome);
  outcome.rigid_dba = CountLines(folder / "run" / "run.log", "DBA rigid");
  outcome.deformable_dba = CountLines(folder / "run" / "run.log", "DBA deformable");
  std::cout << preset << " monocular " << width << "x" << height << ": init at " << outcome.summary.init_frame << ", " << outcome.new_points
            << " new points, RMSE " << outcome.summary.rmse_mm << " mm (a flat map: " << outcome.summary.rmse_flat_mm
            << " mm), DBA windows rigid / deformable: " << outcome.rigid_dba << " / " << outcome.deformable_dba
            << "; first two tracked frames, median px from their own pose's projection / the reference view's:";
  for (size_t i = 0; i < outcome.first_frames_reprojection_px.size(); ++i) {
    std::cout << " " << outcome.first_frames_reprojection_px[i] << " / " << outcome.first_frames_offset_from_reference_px[i];
  }
  std::cout << "\n";
  fs::remove_all(folder);
  return outcome;
}

void ExpectInitialisedAndTrackedToTheEnd(const RunSummary& summary) {
  ASSERT_GE(summary.init_frame, 1);
  EXPECT_LE(summary.init_frame, 30);
  EXPECT_EQ(summary.maps, 1);
  EXPECT_EQ(summary.frames_lost, 0);
  EXPECT_EQ(summary.frames_tracked, 60 - summary.init_frame);
}

// reference-behaviour §9.2: the reference's keyframe queue reset the first two tracked frames
// to the reference view (its identity pose and its pixels), and a track demoted from 3D could
// be triangulated into a second map point.
void ExpectTheFirstFramesTheirOwnAndEachPointOnce(const MonocularOutcome& outcome) {
  ASSERT_EQ(outcome.first_frames_reprojection_px.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_LT(outcome.first_frames_reprojection_px[i], 1.0) << "tracked frame " << i;
    EXPECT_GT(outcome.first_frames_offset_from_reference_px[i], 2.0) << "tracked frame " << i;
  }
  EXPECT_EQ(outcome.repeated_points, 0);
}

TEST(MonocularRun, RigidSceneGivesAnAccurateGrowingMap) {
  // 320x240 has about a quarter of the corners of 640x480: the count thresholds scale down.
  SystemOptions options;
  options.initialisation.min_tracks = 50;
  options.initialisation.min_points = 50;
  const MonocularOutcome outcome = RunMonocular("sim-0", options);
  ExpectInitialisedAndTrackedToTheEnd(outcome.summary);
  EXPECT_GE(outcome.new_points, 20);
  // Measured: 1.6 mm against 9.7 mm for the flat map.
  EXPECT_LT(outcome.summary.rmse_mm, 0.3 * outcome.summary.rmse_flat_mm);
  // A still scene fits one shape: after the warm-up every DBA window is adjusted rigidly.
  EXPECT_GT(outcome.rigid_dba, 0);
  EXPECT_EQ(outcome.deformable_dba, 0);
  ExpectTheFirstFramesTheirOwnAndEachPointOnce(outcome);
}

// sim-0 (60 frames, 320x240) rendered through a calibration file and run through the whole
// monocular system: the model's projection, its Jacobian and its unprojection are all on the path.
RunSummary RunThroughCalibratedLens(const std::string& name, SimCameraOptions camera, const Camera& lens) {
  const fs::path folder = UniqueTempFolder("nrslam_monocular_" + name);
  fs::remove_all(folder);
  fs::create_directories(folder);
  SimOptions sim = SimPreset("sim-0");
  sim.frames = 60;
  sim.camera = camera;
  std::ofstream(folder / "lens.json") << nlohmann::json(lens).dump();
  sim.camera.calibration = (folder / "lens.json").string();
  SimulateSequence(sim, "sim-0-" + name, folder / "sequence");
  EXPECT_EQ(SequenceReader(folder / "sequence").info().camera.model(), lens.model());
  SystemOptions options;  // 320x240: the count thresholds scale down, as for the pinhole run above
  options.initialisation.min_tracks = 50;
  options.initialisation.min_points = 50;
  const RunSummary summary = RunSequence(folder / "sequence", options, folder / "run");
  std::cout << "sim-0 through the " << lens.model_name() << " lens, 320x240: init at " << summary.init_frame
            << ", RMSE " << summary.rmse_mm << " mm (a flat map: " << summary.rmse_flat_mm << " mm)\n";
  fs::remove_all(folder);
  return summary;
}

// The simulator's fisheye rewritten as OCamCalib's model, which the simulator then renders with.
TEST(MonocularRun, AnOcamCalibratedLensIsTrackedToTheEnd) {
  SimCameraOptions fisheye;
  fisheye.model = "fisheye";
  fisheye.width = 320;
  fisheye.height = 240;
  const RunSummary summary = RunThroughCalibratedLens("ocam", fisheye, OcamFromKannalaBrandt(MakeSimCamera(fisheye)));
  ExpectInitialisedAndTrackedToTheEnd(summary);
  EXPECT_LT(summary.rmse_mm, 0.3 * summary.rmse_flat_mm);
}

// A laparoscope calibrated with OpenCV (the fixture's strong barrel, at half its resolution).
TEST(MonocularRun, AnOpenCvCalibratedLensIsTrackedToTheEnd) {
  const Camera full = OpenCvLaparoscope();
  const std::vector<double>& p = full.params();
  const Camera half = Camera::OpenCv(320, 240, p[0] / 2, p[1] / 2, (p[2] + 0.5) / 2 - 0.5, (p[3] + 0.5) / 2 - 0.5,
                                     std::vector<double>(p.begin() + OpenCvModel::kDistortionOffset, p.begin() + 9));
  const RunSummary summary = RunThroughCalibratedLens("opencv", SimCameraOptions(), half);
  ExpectInitialisedAndTrackedToTheEnd(summary);
  EXPECT_LT(summary.rmse_mm, 0.3 * summary.rmse_flat_mm);
}

TEST(MonocularRun, DeformingSceneIsTrackedToTheEnd) {
  // sim-3: A = 5 mm, ω = 2.5 rad/s. The deformation's apparent motion is as large as the
  // camera's early on, so the two-view map is poor (docs/mapping.md): only tracking and
  // map growth are pinned here, not accuracy.
  const MonocularOutcome outcome = RunMonocular("sim-3", SystemOptions{});
  ExpectInitialisedAndTrackedToTheEnd(outcome.summary);
  // The new points come from deformable triangulation: the rigidity gate keeps rigid
  // triangulation out of a deforming scene (without it: no new points, and the track is lost).
  EXPECT_GT(outcome.deformable_candidates, 0);
  EXPECT_GE(outcome.new_points, 20);
  // Model selection leaves the DBA deformable where one shape does not fit (measured: 4 of 7
  // windows after the warm-up).
  EXPECT_GT(outcome.deformable_dba, 0);
  // summary.json's birth errors are those of the points points.csv says were new.
  ASSERT_FALSE(outcome.birth_log_errors.empty());
  EXPECT_EQ(outcome.summary.births.births_evaluated, static_cast<int>(outcome.birth_log_errors.size()));
  ASSERT_TRUE(outcome.summary.births.mean && outcome.summary.births.median);
  EXPECT_NEAR(*outcome.summary.births.mean, Mean(outcome.birth_log_errors), 1e-6);
  EXPECT_NEAR(*outcome.summary.births.median, Median(outcome.birth_log_errors), 1e-6);
  ExpectTheFirstFramesTheirOwnAndEachPointOnce(outcome);
}

// run.restart_on_depth_change gives a map up on the first frame its median depth moves beyond
// the factor, and a new map is started from the images while the old one goes on tracking, so
// that no frame is left untracked. A factor of 1.2 is far tighter than a real run would take
// (docs/mapping.md: 10 spares every 120-frame run), so that the 60 frames of sim-3 hold a restart.
TEST(MonocularRun, AMapWhoseDepthMovesBeyondTheFactorIsReplacedByANewOne) {
  const fs::path folder = UniqueTempFolder("nrslam_monocular_restart");
  fs::remove_all(folder);
  SimulateSmall("sim-3", 60, 320, 240, folder / "sequence");
  SystemOptions options;
  options.run.restart_on_depth_change = 1.2;
  const RunSummary summary = RunSequence(folder / "sequence", options, folder / "run");
  EXPECT_GE(summary.maps, 2);
  // Each map's frames: within the factor of its first until the one it was given up on; after
  // that it tracks on, for at least one frame, until the next map starts.
  std::map<int, double> first_depth, last_depth;
  std::set<int> given_up_maps;
  std::map<int, int> frames_after_given_up;  // by map
  int tracked = 0;
  for (const auto& row : ReadCsv(folder / "run" / "metrics.csv")) {
    const int frame = std::stoi(row.at("frame"));
    if (frame < summary.init_frame) continue;
    EXPECT_EQ(row.at("state"), "tracking") << "frame " << frame << ": a new map starts beside the old one";
    if (row.at("state") != "tracking") continue;
    ++tracked;
    const int map = std::stoi(row.at("map"));
    EXPECT_TRUE(given_up_maps.count(map - 1) || map == 1) << "frame " << frame << ": map " << map;
    if (given_up_maps.count(map)) {
      ++frames_after_given_up[map];
      continue;
    }
    const double depth = std::stod(row.at("median_depth"));
    last_depth[map] = depth;
    const double change = std::abs(std::log(depth / first_depth.emplace(map, depth).first->second));
    if (row.at("note").find("given up") != std::string::npos) {
      given_up_maps.insert(map);
      EXPECT_GT(change, std::log(1.2)) << "frame " << frame;
    } else {
      EXPECT_LE(change, std::log(1.2)) << "frame " << frame;
    }
  }
  const int given_up = static_cast<int>(given_up_maps.size());
  EXPECT_EQ(tracked, summary.frames_total - summary.init_frame);
  EXPECT_EQ(summary.Status(), "ok");
  for (int map : given_up_maps) {
    if (map < summary.maps) {
      EXPECT_GE(frames_after_given_up[map], 1) << "map " << map;
    }
  }
  EXPECT_EQ(CountLines(folder / "run" / "run.log", "given up: its median depth"), given_up);
  EXPECT_EQ(CountLines(folder / "run" / "run.log", ", replacing map "), summary.maps - 1);
  EXPECT_EQ(summary.maps_given_up, given_up);
  EXPECT_NE(DescribeSummary(summary).find(GivenUpText(given_up)), std::string::npos) << DescribeSummary(summary);
  // Every map but the last was given up; the last one too if the run ended before another began.
  EXPECT_TRUE(given_up == summary.maps - 1 || given_up == summary.maps) << given_up << " of " << summary.maps;
  // The given-up maps have their note; the drift figure is the last map's, or none.
  if (given_up == summary.maps) {
    EXPECT_EQ(summary.map_depth.ratio, 0.0);
  } else {
    EXPECT_NEAR(summary.map_depth.ratio, last_depth.at(summary.maps) / first_depth.at(summary.maps), 1e-6);
  }
  EXPECT_THROW(WithRunAssignments(SystemOptions{}, {"run.restart_on_depth_change=1"}), Error);
  EXPECT_THROW(WithRunAssignments(SystemOptions{}, {"run.restart_on_depth_change=-2"}), Error);
  fs::remove_all(folder);
}

TEST(MonocularRun, ShortestGateSpanAdmitsMoreDeformablePoints) {
  // Over a track's oldest and newest observations a deforming surface has moved enough for the
  // rigid rays to miss; the shortest span with enough parallax lets more candidates through,
  // on every frame ("shortest") or only on frames where the map has thinned (the default).
  SystemOptions oldest, shortest;
  oldest.mapping.shortest_gate_below_fraction = 0;
  shortest.mapping.deformable_gate_span = "shortest";
  const MonocularOutcome reference = RunMonocular("sim-3", oldest);
  const MonocularOutcome adaptive = RunMonocular("sim-3", SystemOptions{});
  const MonocularOutcome outcome = RunMonocular("sim-3", shortest);
  ExpectInitialisedAndTrackedToTheEnd(outcome.summary);
  std::cout << "deformable candidates oldest / adaptive / shortest: " << reference.deformable_candidates << " / "
            << adaptive.deformable_candidates << " / " << outcome.deformable_candidates << "\n";
  EXPECT_GT(outcome.deformable_candidates, reference.deformable_candidates);
  EXPECT_GT(adaptive.deformable_candidates, reference.deformable_candidates);
  EXPECT_GT(adaptive.new_points, reference.new_points);
}

TEST(MonocularRun, StarvingMapDropsTheTwoRayCheck) {
  // Even over the shortest span, the tissue moves about as far as the camera, so many
  // candidates' rigid rays miss each other; a starving map (here: every frame, fraction 1)
  // gates on parallax alone and leaves the rest to the deformable fit's own checks.
  // (The epipolar gate, which turns many of the same tracks away, is off in both runs, and so
  // is the batch depth check, which turns batches of these loosely gated points away and so
  // changes which candidates later frames have.)
  SystemOptions checked, parallax_only;
  checked.mapping.shortest_gate_below_fraction = parallax_only.mapping.shortest_gate_below_fraction = 1;
  checked.mapping.starving_max_epipolar_ratio = parallax_only.mapping.starving_max_epipolar_ratio = 0;
  checked.mapping.max_batch_depth_bias = parallax_only.mapping.max_batch_depth_bias = 0;
  checked.mapping.starving_two_ray_check = true;
  parallax_only.mapping.starving_two_ray_check = false;
  const MonocularOutcome reference = RunMonocular("sim-3", checked);
  const MonocularOutcome outcome = RunMonocular("sim-3", parallax_only);
  ExpectInitialisedAndTrackedToTheEnd(outcome.summary);
  std::cout << "deformable candidates with / without the two-ray check: " << reference.deformable_candidates << " / "
            << outcome.deformable_candidates << "\n";
  EXPECT_GT(outcome.deformable_candidates, reference.deformable_candidates);
}

TEST(MonocularRun, AgreementGateKeepsNewPointsThatMatchTheirTwoRayDepth) {
  // A deformable fit whose depth disagrees with the two-ray depth got it from its seed, the
  // neighbours' distance: far points down the lumen come out too near. Keeping only fits
  // that agree leaves fewer new points, placed closer to the true depth. (The epipolar gate,
  // which turns many of the same tracks away, is off in both runs.)
  SystemOptions off, on;
  off.mapping.deformable_agreement_ratio = 0;
  for (SystemOptions* options : {&off, &on}) {
    options->mapping.deformable_max_epipolar_ratio = options->mapping.starving_max_epipolar_ratio = 0;
  }
  const MonocularOutcome reference = RunMonocular("sim-3", off);
  const MonocularOutcome outcome = RunMonocular("sim-3", on);  // the default agreement gate
  ExpectInitialisedAndTrackedToTheEnd(outcome.summary);
  std::cout << "new points without / with the gate: " << reference.new_points << " / " << outcome.new_points
            << ", median |log depth error| " << reference.new_point_log_depth_error << " / "
            << outcome.new_point_log_depth_error << "\n";
  EXPECT_GT(outcome.new_points, 0);
  EXPECT_LT(outcome.deformable_candidates, reference.deformable_candidates);
  EXPECT_LT(outcome.new_point_log_depth_error, 0.8 * reference.new_point_log_depth_error);
}

TEST(MonocularRun, EpipolarGateKeepsFewerGrosslyMisplacedNewPoints) {
  // What the tissue moves a track across its epipolar planes it also moves along them, and
  // that false parallax puts the point too near. Fitting only tracks whose rays stay near
  // those planes leaves fewer new points, and fewer of them off by more than 2x (measured:
  // 18 % of 218 without the gate, 13 % of 190 with it; 8 % of 171 at a ratio of 0.1). At
  // 640x480: at 320x240, where a pixel of tracking noise is twice the angle and the run makes
  // few new points, it did not show (9 % of 75 without, 13 % of 64 with).
  SystemOptions off;
  off.mapping.deformable_max_epipolar_ratio = off.mapping.starving_max_epipolar_ratio = 0;
  const MonocularOutcome reference = RunMonocular("sim-3", off, 640, 480);
  const MonocularOutcome outcome = RunMonocular("sim-3", SystemOptions{}, 640, 480);  // the default gate
  ExpectInitialisedAndTrackedToTheEnd(outcome.summary);
  std::cout << "new points without / with the gate: " << reference.new_points << " / " << outcome.new_points
            << ", off by more than 2x: " << reference.new_point_gross_error_fraction << " / "
            << outcome.new_point_gross_error_fraction << ", median |log depth error| "
            << reference.new_point_log_depth_error << " / " << outcome.new_point_log_depth_error << "\n";
  EXPECT_GT(outcome.new_points, 0);
  EXPECT_LT(outcome.deformable_candidates, reference.deformable_candidates);
  EXPECT_LT(outcome.new_point_gross_error_fraction, 0.8 * reference.new_point_gross_error_fraction);
}

TEST(MonocularRun, BatchDepthCheckTurnsAwayExactlyTheBatchesOutsideItsBound) {
  // A bound this tight turns away some batches of an ordinary run: every frame's chosen new
  // points are either all added, with their median depth ratio to their neighbours within
  // the bound, or none, with it outside. (Every batch is checked here, however small.)
  SystemOptions options;
  options.mapping.max_batch_depth_bias = 1.03;
  options.mapping.batch_check_min_points = 1;
  const MonocularOutcome outcome = RunMonocular("sim-3", options);
  ExpectInitialisedAndTrackedToTheEnd(outcome.summary);
  int added = 0, rejected = 0;
  for (const auto& row : outcome.metrics) {
    const double bias = std::stod(row.at("new_point_depth_bias"));
    const int new_points = std::stoi(row.at("new_points"));
    if (row.at("batch_rejected") == "1") {
      ++rejected;
      EXPECT_EQ(new_points, 0) << "frame " << row.at("frame");
      EXPECT_TRUE(bias > 1.03 || bias * 1.03 < 1) << "frame " << row.at("frame") << ": " << bias;
    } else if (new_points > 0) {
      ++added;
      EXPECT_LE(bias, 1.03) << "frame " << row.at("frame");
      EXPECT_GE(bias * 1.03, 1.0) << "frame " << row.at("frame");
    }
  }
  std::cout << "batches added / turned away: " << added << " / " << rejected << "\n";
  EXPECT_GT(added, 0);
  EXPECT_GT(rejected, 0);
}

// The shading prior (frontend/shading.h) with its companions, as the colonoscopy
// configuration data_manifests/paper-sim-monocular-shading.json sets them: brightness-
// corrected initial and new deformable points, and a rigid warm-up kept only where one shape
// fits.
SystemOptions ShadingConfiguration() {
  SystemOptions options;
  options.initialisation.shading_weight = 1;
  options.mapping.new_point_shading_weight = 0.5;
  options.mapping.rigid_warmup_min_inliers = 0.99;
  return options;
}

TEST(MonocularRun, ShadingPriorCorrectsTheTwoViewMapOfADeformingColon) {
  // sim-3: two views a few frames apart of tissue that moves as far as the camera give poor
  // depths (docs/mapping.md); the brightness of a tube lit from the tip does not depend on
  // the motion.
  const MonocularOutcome reference = RunMonocular("sim-3", SystemOptions{}, 640, 480);
  const MonocularOutcome outcome = RunMonocular("sim-3", ShadingConfiguration(), 640, 480);
  ExpectInitialisedAndTrackedToTheEnd(outcome.summary);
  EXPECT_EQ(outcome.summary.init_frame, reference.summary.init_frame);
  std::cout << "sim-3 RMSE without / with the shading prior: " << reference.summary.rmse_mm << " / "
            << outcome.summary.rmse_mm << " mm\n";
  EXPECT_LT(outcome.summary.rmse_mm, 0.7 * reference.summary.rmse_mm);
  // The warm-up's rigid fit leaves too many observations out: its windows are deformable.
  EXPECT_GT(outcome.deformable_dba, reference.deformable_dba);
}

TEST(MonocularRun, GatedWarmupStaysRigidInAStillScene) {
  SystemOptions options;
  options.initialisation.min_tracks = options.initialisation.min_points = 50;  // 320x240, as above
  options.mapping.rigid_warmup_min_inliers = 0.99;
  const MonocularOutcome outcome = RunMonocular("sim-0", options);
  ExpectInitialisedAndTrackedToTheEnd(outcome.summary);
  EXPECT_GT(outcome.rigid_dba, 0);
  EXPECT_EQ(outcome.deformable_dba, 0);
}

// New points are triangulated on every core (mapper.cc); the map must not depend on how many.
TEST(MonocularRun, TriangulationOnTwoThreadsGivesTheSameRunAsOne) {
  omp_set_num_threads(1);
  const MonocularOutcome one = RunMonocular("sim-3", SystemOptions{});
  omp_set_num_threads(2);
  const MonocularOutcome two = RunMonocular("sim-3", SystemOptions{});
  ASSERT_GT(one.deformable_candidates, 0);
  EXPECT_EQ(two.deformable_candidates, one.deformable_candidates);
  EXPECT_EQ(two.new_points, one.new_points);
  EXPECT_EQ(two.summary.map_points, one.summary.map_points);
  EXPECT_EQ(two.summary.rmse_mm, one.summary.rmse_mm);  // exactly: the same points, the same order
}

// The runner hands the tracker each next frame to run its KLT ahead (tracking.klt_lookahead);
// with mapping, candidates and their promotion to map points in between, the run is the same.
TEST(MonocularRun, KltLookaheadGivesTheSameRunAsWithout) {
  SystemOptions options;
  options.tracking.klt_lookahead = false;
  const MonocularOutcome without = RunMonocular("sim-3", options);
  const MonocularOutcome with = RunMonocular("sim-3", SystemOptions{});
  ASSERT_GT(without.new_points, 0);
  EXPECT_EQ(with.summary.frames_tracked, without.summary.frames_tracked);
  EXPECT_EQ(with.deformable_candidates, without.deformable_candidates);
  EXPECT_EQ(with.new_points, without.new_points);
  EXPECT_EQ(with.summary.map_points, without.summary.map_points);
  EXPECT_EQ(with.summary.rmse_mm, without.summary.rmse_mm);  // exactly: the same points, the same order
}

// A DBA left to run beside tracking is applied on a fixed frame, so runs repeat exactly; the
// motion tracked meanwhile is kept on top of its result, so a still scene stays accurate.
TEST(MonocularRun, LaggedDbaIsRepeatableAndKeepsARigidSceneAccurate) {
  SystemOptions options;
  options.initialisation.min_tracks = 50;
  options.initialisation.min_points = 50;
  const MonocularOutcome immediate = RunMonocular("sim-0", options);
  options.mapping.dba_lag_frames = 2;
  const MonocularOutcome first = RunMonocular("sim-0", options);
  const MonocularOutcome second = RunMonocular("sim-0", options);
  ExpectInitialisedAndTrackedToTheEnd(first.summary);
  EXPECT_GT(first.rigid_dba, 0);
  EXPECT_LT(first.summary.rmse_mm, 0.3 * first.summary.rmse_flat_mm);
  // Measured: 1.34 mm lagged, 1.63 mm at once; 2.94 mm when the camera is snapped back to the
  // keyframe's adjusted pose instead of keeping its tracked motion since.
  EXPECT_LT(first.summary.rmse_mm, 1.5 * immediate.summary.rmse_mm);
  EXPECT_EQ(second.summary.rmse_mm, first.summary.rmse_mm);
  EXPECT_EQ(second.summary.map_points, first.summary.map_points);
  EXPECT_NE(first.summary.rmse_mm, immediate.summary.rmse_mm);  // the lag took effect
}

TEST(DepthMappingRun, StarvingMapRuleLeavesItAlone) {
  // A map from depth starts accurate: the looser gate is for monocular maps only, so even a
  // rule that holds on every frame (fraction 1) must leave a depth-initialised run unchanged.
  SystemOptions never, always;
  never.run.init = always.run.init = "depth";
  never.mapping.shortest_gate_below_fraction = 0;
  always.mapping.shortest_gate_below_fraction = 1;
  const MonocularOutcome reference = RunMonocular("sim-3", never);
  const MonocularOutcome outcome = RunMonocular("sim-3", always);
  EXPECT_EQ(outcome.summary.frames_tracked, reference.summary.frames_tracked);
  EXPECT_EQ(outcome.deformable_candidates, reference.deformable_candidates);
  EXPECT_EQ(outcome.new_points, reference.new_points);
  EXPECT_DOUBLE_EQ(outcome.summary.rmse_mm, reference.summary.rmse_mm);
}

// At 320x240 a rigid fit of deforming sim-3's windows passes the DBA's pixel inlier test, and
// the rigid windows turn the deformation into depth error; tracking's δ, measured in 3D, tell
// the windows deform. A still scene's windows stay rigid. Measured: 4.45 mm ungated (2 rigid
// windows) against 1.04 mm gated (none); sim-0 0.71 mm either way with 7 rigid windows.
TEST(DepthMappingRun, WindowsTrackedAsDeformingAreNotAdjustedRigidly) {
  SystemOptions gated, ungated;
  gated.run.init = ungated.run.init = "depth";
  ungated.mapping.rigid_dba_max_deformation = 0;
  const MonocularOutcome deforming = RunMonocular("sim-3", gated);
  const MonocularOutcome deforming_ungated = RunMonocular("sim-3", ungated);
  ASSERT_GT(deforming_ungated.rigid_dba, 0);  // the case this test is about
  EXPECT_EQ(deforming.rigid_dba, 0);
  EXPECT_EQ(deforming.summary.frames_tracked, 60);
  EXPECT_LT(deforming.summary.rmse_mm, 0.5 * deforming_ungated.summary.rmse_mm);
  const MonocularOutcome still = RunMonocular("sim-0", gated);
  EXPECT_GT(still.rigid_dba, still.deformable_dba);
  EXPECT_EQ(still.summary.frames_tracked, 60);
}

// A plain video with a calibration and nothing else (no depth, no poses) runs end to end:
// initialised from the images, tracked, with nothing to evaluate.
TEST(MonocularRun, PlainVideoWithoutGroundTruth) {
  const fs::path folder = UniqueTempFolder("nrslam_plain_video");
  fs::remove_all(folder);
  SimulateSmall("sim-0", 40, 320, 240, folder / "sim");
  const SequenceReader simulated(folder / "sim");
  {
    cv::VideoWriter video((folder / "clip.avi").string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 30,
                          cv::Size(320, 240));
    ASSERT_TRUE(video.isOpened());
    for (int i = 0; i < simulated.frame_count(); ++i) video.write(simulated.ReadRgb(i));
  }
  std::ofstream(folder / "camera.json") << nlohmann::json(simulated.info().camera).dump();
  ImportOptions import;
  import.format = "images";
  import.input = folder / "clip.avi";
  import.calibration = folder / "camera.json";
  ImportDataset(import, folder / "video");
  SystemOptions options;
  options.initialisation.min_tracks = 50;  // 320x240: about a quarter of 640x480's corners
  options.initialisation.min_points = 50;
  const RunSummary summary = RunSequence(folder / "video", options, folder / "run");
  EXPECT_GE(summary.init_frame, 1);
  EXPECT_LE(summary.init_frame, 30);
  EXPECT_EQ(summary.frames_tracked, 40 - summary.init_frame);
  EXPECT_EQ(summary.frames_evaluated, 0);
  EXPECT_EQ(ReadTum(folder / "run" / "trajectory.tum").size(), static_cast<size_t>(summary.frames_tracked));
  fs::remove_all(folder);
}

// run.camera replaces the sequence's calibration (e.g. a better one than the dataset's); it
// must fit the images, and the run records which camera it used.
TEST(RunSequenceCamera, OverrideIsUsedAndMustFitTheImages) {
  const fs::path folder = UniqueTempFolder("nrslam_camera_override");
  fs::remove_all(folder);
  SimulateSmall("sim-1", 10, 320, 240, folder / "sequence");
  const Camera own = SequenceReader(folder / "sequence").info().camera;
  const Camera wrong_focal = Camera::Pinhole(320, 240, 1.3 * own.fx(), 1.3 * own.fy(), own.cx(), own.cy());
  std::ofstream(folder / "focal.json") << nlohmann::json(wrong_focal).dump();
  std::ofstream(folder / "size.json") << nlohmann::json(Camera::Pinhole(640, 480, 300, 300, 319.5, 239.5)).dump();

  SystemOptions options = TrackingExperiment();
  const RunSummary baseline = RunSequence(folder / "sequence", options, folder / "own");
  options.run.camera = (folder / "focal.json").string();
  const RunSummary overridden = RunSequence(folder / "sequence", options, folder / "focal");
  EXPECT_NE(baseline.rmse_mm, overridden.rmse_mm);  // the other calibration was really used
  std::ifstream config_stream(folder / "focal" / "config.json");
  const nlohmann::json config = nlohmann::json::parse(config_stream);
  EXPECT_DOUBLE_EQ(config.at("camera").at("fx").get<double>(), wrong_focal.fx());

  options.run.camera = (folder / "size.json").string();
  try {
    RunSequence(folder / "sequence", options, folder / "size");
    FAIL() << "ran with a camera for other images";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("is for 640x480 images, the sequence's are 320x240"), std::string::npos)
        << e.what();
  }
  fs::remove_all(folder);
}

TEST(RunSequenceErrors, BadInputGivesOneClearError) {
  EXPECT_THROW(RunSequence("/nonexistent/sequence", SystemOptions{}, "/tmp/nrslam_never"), Error);
  const fs::path folder = UniqueTempFolder("nrslam_no_depth");
  fs::remove_all(folder);
  SimulateSmall("sim-0", 2, 64, 48, folder);
  // Given the sequence's own folder as the run folder, the run would have replaced the ground
  // truth in depth/ with its estimates (it did, before the check).
  const std::string sequence_depth = FileText(folder / "depth" / FrameFileName(1));
  EXPECT_EQ(ErrorMessage([&] { RunSequence(folder, SystemOptions{}, folder); }),
            folder.string() + " holds a sequence (sequence.json): a run written there would replace its depth/ with "
                              "the run's estimates; write the run to another folder");
  EXPECT_EQ(FileText(folder / "depth" / FrameFileName(1)), sequence_depth);
  fs::remove_all(folder / "depth");
  try {
    RunSequence(folder, TrackingExperiment(), folder / "run");
    FAIL() << "ran without depth";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no depth/"), std::string::npos) << e.what();
  }
  SystemOptions past_the_end;
  past_the_end.run.first_frame = 2;
  EXPECT_EQ(ErrorMessage([&] { RunSequence(folder, past_the_end, folder / "run"); }),
            "run.first_frame 2 is past the last frame of " + folder.string() + " (2 frames, 0 to 1)");
  // Monocular needs no depth: two frames are too few to initialise, a recorded outcome.
  const RunSummary monocular = RunSequence(folder, SystemOptions{}, folder / "run");
  EXPECT_EQ(monocular.init_frame, -1);
  EXPECT_EQ(monocular.frames_tracked, 0);
  EXPECT_EQ(monocular.frames_total, 2);
  EXPECT_EQ(monocular.Status(), "not_initialised");
  EXPECT_EQ(monocular.stop_reason.rfind("initialising: ", 0), 0u) << monocular.stop_reason;
  // The sequence has ground truth; the run has nothing to score.
  EXPECT_NE(DescribeSummary(monocular).find("no frame tracked, no RMSE"), std::string::npos) << DescribeSummary(monocular);
  EXPECT_EQ(monocular.input.frames_past_end, 0);
  // A range past the end runs to the end, and says so.
  SystemOptions beyond_the_end;
  beyond_the_end.run.last_frame = 5;
  const RunSummary to_the_end = RunSequence(folder, beyond_the_end, folder / "beyond");
  EXPECT_EQ(to_the_end.frames_total, 2);
  EXPECT_EQ(to_the_end.input.frames_past_end, 3);
  EXPECT_NE(DescribeSummary(to_the_end).find("3 frames of the range asked for (run.last_frame) lie past the sequence's end"),
            std::string::npos)
      << DescribeSummary(to_the_end);
  EXPECT_EQ(ReadJsonFile(folder / "beyond" / "summary.json").at("frames_past_end"), 3);
  EXPECT_NE(FileText(folder / "beyond" / "run.log").find("3 frames of the range asked for"), std::string::npos);
  fs::remove_all(folder);
}

// A first frame the map cannot start from says whether the image or its depth fell short: a
// blank image has no corners, a depth map of holes leaves the corners without depth. The run
// starts on the next frame.
TEST(RunSequenceErrors, AFirstFrameWithoutCornersOrDepthSaysWhich) {
  const fs::path folder = UniqueTempFolder("nrslam_blank_first_frame");
  fs::remove_all(folder);
  SimulateSmall("sim-0", 3, 160, 120, folder);
  const fs::path first_image = folder / "rgb" / FrameFileName(0), first_depth = folder / "depth" / FrameFileName(0);
  const cv::Mat image = cv::imread(first_image.string()), depth = cv::imread(first_depth.string(), cv::IMREAD_UNCHANGED);
  ASSERT_TRUE(cv::imwrite(first_image.string(), cv::Mat::zeros(image.size(), image.type())));
  const RunSummary blank = RunSequence(folder, TrackingExperiment(), folder / "run");
  EXPECT_EQ(blank.init_frame, 1);
  const auto blank_rows = ReadCsv(folder / "run" / "metrics.csv");
  EXPECT_NE(blank_rows.at(0).at("note").find("(0 of 0 corners found)"), std::string::npos) << blank_rows.at(0).at("note");

  ASSERT_TRUE(cv::imwrite(first_image.string(), image));
  ASSERT_TRUE(cv::imwrite(first_depth.string(), cv::Mat::zeros(depth.size(), depth.type())));
  const RunSummary holes = RunSequence(folder, TrackingExperiment(), folder / "run");
  EXPECT_EQ(holes.init_frame, 1);
  const std::string note = ReadCsv(folder / "run" / "metrics.csv").at(0).at("note");
  EXPECT_TRUE(std::regex_search(note, std::regex(R"(\(0 of [1-9][0-9]* corners found\))"))) << note;
  fs::remove_all(folder);
}

// Frames are read ahead of the tracker and depth maps written behind it (run_sequence.cc): a
// frame that cannot be read must still be the one recorded as failed, and the run go on.
std::vector<std::string> FileLines(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

TEST(RunSequenceErrors, CorruptFrameMidRunIsRecordedAndTheRunGoesOn) {
  const fs::path folder = UniqueTempFolder("nrslam_corrupt_frame");
  fs::remove_all(folder);
  SimulateSmall("sim-0", 10, 320, 240, folder);
  // Truncated after its header: the sequence opens (headers are checked up front), and only
  // decoding the frame fails.
  const fs::path broken = folder / "rgb" / "000006.png";
  fs::resize_file(broken, 200);
  SystemOptions options = TrackingExperiment();
  options.run.reinitialise_after_loss = true;
  const RunSummary summary = RunSequence(folder, options, folder / "run");
  EXPECT_EQ(summary.frames_tracked, 9);
  EXPECT_EQ(summary.frames_lost, 1);
  EXPECT_EQ(summary.input.frames_unreadable, 1);
  EXPECT_EQ(summary.input.frames_unreadable_after_init, 1);  // the map started on frame 0
  EXPECT_NE(DescribeSummary(summary).find("1 frame unreadable (lost); metrics.csv names the files"), std::string::npos)
      << DescribeSummary(summary);
  const std::vector<std::string> rows = FileLines(folder / "run" / "metrics.csv");
  ASSERT_EQ(rows.size(), 11u);
  for (int frame = 0; frame < 10; ++frame) {
    const std::string& row = rows[static_cast<size_t>(frame) + 1];
    EXPECT_EQ(row.rfind(std::to_string(frame) + (frame == 6 ? ",lost," : ",tracking,"), 0), 0u) << row;
    EXPECT_EQ(fs::exists(folder / "run" / "depth" / FrameFileName(frame)), frame != 6) << frame;
  }
  EXPECT_NE(rows[7].find("000006.png"), std::string::npos) << rows[7];
  EXPECT_EQ(summary.Status(), "ok");  // tracking again after the bad frame
  EXPECT_EQ(summary.stop_frame, -1);
  EXPECT_TRUE(ReadJsonFile(folder / "run" / "summary.json").at("stop_reason").is_null());
  fs::remove_all(folder);
}

// A damaged ground-truth depth map costs its frame the score and nothing else: the frame is
// tracked as from the whole sequence, and the run, an external scoring of it and a comparison
// all leave that frame out and say so. Where depth is the input (the map from depth), the frame
// cannot start a map, and the next one does.
TEST(RunSequenceErrors, UnreadableGroundTruthCostsItsFrameTheScoreOnly) {
  const fs::path folder = UniqueTempFolder("nrslam_unreadable_groundtruth");
  fs::remove_all(folder);
  SimulateSmall("sim-1", 10, 320, 240, folder / "whole");
  fs::copy(folder / "whole", folder / "damaged", fs::copy_options::recursive);
  fs::resize_file(folder / "damaged" / "depth" / "000006.png", 200);  // header intact, data cut
  const RunSummary whole = RunSequence(folder / "whole", TrackingExperiment(), folder / "whole_run");
  const RunSummary damaged = RunSequence(folder / "damaged", TrackingExperiment(), folder / "damaged_run");
  EXPECT_EQ(damaged.frames_tracked, 10);
  EXPECT_EQ(damaged.frames_lost, 0);
  EXPECT_EQ(whole.frames_evaluated, 10);
  EXPECT_EQ(damaged.frames_evaluated, 9);
  EXPECT_EQ(whole.input.frames_groundtruth_unreadable, 0);
  EXPECT_EQ(damaged.input.frames_groundtruth_unreadable, 1);
  for (const char* file : {"trajectory.tum", "points.csv"}) {
    EXPECT_EQ(FileLines(folder / "damaged_run" / file), FileLines(folder / "whole_run" / file)) << file;
  }
  const std::vector<std::string> metrics = FileLines(folder / "damaged_run" / "metrics.csv");
  ASSERT_EQ(metrics.size(), 11u);
  EXPECT_EQ(metrics[7].rfind("6,tracking,", 0), 0u) << metrics[7];
  EXPECT_NE(metrics[7].find("not scored: cannot decode"), std::string::npos) << metrics[7];
  EXPECT_NE(metrics[7].find("000006.png"), std::string::npos) << metrics[7];
  EXPECT_EQ(ReadJsonFile(folder / "damaged_run" / "summary.json").at("frames_groundtruth_unreadable"), 1);
  EXPECT_NE(DescribeSummary(damaged).find("ground-truth depth unreadable on 1 tracked frame (not scored)"),
            std::string::npos)
      << DescribeSummary(damaged);
  EXPECT_EQ(damaged.input.frames_unreadable, 0);

  ExternalResult external;
  external.estimates = folder / "whole_run" / "points.csv";
  external.trajectory = folder / "whole_run" / "trajectory.tum";
  const RunSummary scored = ScoreExternalResult(folder / "damaged", external, EvaluationOptions{}, folder / "scored");
  EXPECT_EQ(scored.frames_tracked, 10);
  EXPECT_EQ(scored.frames_evaluated, 9);
  EXPECT_EQ(scored.input.frames_groundtruth_unreadable, 1);
  EXPECT_NEAR(scored.rmse_mm, damaged.rmse_mm, 1e-5);
  EXPECT_EQ(CompareRunFolders(folder / "damaged_run", folder / "damaged_run").frames, 9);

  fs::resize_file(folder / "damaged" / "depth" / "000000.png", 200);
  const RunSummary late = RunSequence(folder / "damaged", TrackingExperiment(), folder / "late_run");
  EXPECT_EQ(late.init_frame, 1);
  EXPECT_EQ(late.frames_tracked, 9);
  EXPECT_EQ(late.input.frames_unreadable, 1);  // where the map starts, depth is input
  EXPECT_EQ(late.input.frames_unreadable_after_init, 0);  // before the map: counted in init_frame
  const std::vector<std::string> late_metrics = FileLines(folder / "late_run" / "metrics.csv");
  ASSERT_EQ(late_metrics.size(), 11u);
  EXPECT_NE(late_metrics[1].find("000000.png"), std::string::npos) << late_metrics[1];
  fs::remove_all(folder);
}

// Ground truth read but valid under too few of a frame's points (depth missing over most of the
// view) costs that frame its score, and the run says so: in metrics.csv, the summary line and
// summary.json. A run with no frame scored for that reason does not claim to have no ground truth.
TEST(RunSequenceErrors, GroundTruthTooSparseToScoreIsNotedNotMistakenForNone) {
  const fs::path folder = UniqueTempFolder("nrslam_sparse_groundtruth");
  fs::remove_all(folder);
  SimulateSmall("sim-1", 10, 320, 240, folder / "whole");
  fs::copy(folder / "whole", folder / "sparse", fs::copy_options::recursive);
  const auto keep_one_pixel = [&](int frame) {
    const fs::path file = folder / "sparse" / "depth" / FrameFileName(frame);
    const cv::Mat depth = cv::imread(file.string(), cv::IMREAD_UNCHANGED);
    cv::Mat sparse = cv::Mat::zeros(depth.size(), depth.type());
    depth(cv::Rect(160, 120, 1, 1)).copyTo(sparse(cv::Rect(160, 120, 1, 1)));
    ASSERT_TRUE(cv::imwrite(file.string(), sparse));
  };
  for (int frame : {4, 5, 6}) keep_one_pixel(frame);
  const RunSummary whole = RunSequence(folder / "whole", TrackingExperiment(), folder / "whole_run");
  const RunSummary sparse = RunSequence(folder / "sparse", TrackingExperiment(), folder / "sparse_run");
  EXPECT_EQ(sparse.frames_tracked, 10);
  EXPECT_EQ(whole.frames_evaluated, 10);
  EXPECT_EQ(sparse.frames_evaluated, 7);
  EXPECT_EQ(whole.input.frames_sparse_groundtruth, 0);
  EXPECT_EQ(sparse.input.frames_sparse_groundtruth, 3);
  EXPECT_EQ(sparse.input.frames_groundtruth_unreadable, 0);
  EXPECT_EQ(FileLines(folder / "sparse_run" / "points.csv"), FileLines(folder / "whole_run" / "points.csv"));
  const std::vector<std::string> metrics = FileLines(folder / "sparse_run" / "metrics.csv");
  ASSERT_EQ(metrics.size(), 11u);
  EXPECT_TRUE(std::regex_search(metrics[5], std::regex(R"(not scored: 0 of its \d+ points on valid ground truth)")))
      << metrics[5];
  EXPECT_EQ(metrics[4].find("not scored"), std::string::npos) << metrics[4];
  EXPECT_EQ(ReadJsonFile(folder / "sparse_run" / "summary.json").at("frames_sparse_groundtruth"), 3);
  const std::string described = DescribeSummary(sparse);
  EXPECT_NE(described.find("RMSE mean"), std::string::npos) << described;
  EXPECT_NE(described.find("3 tracked frames not scored: too few of their points on valid ground truth"),
            std::string::npos)
      << described;

  // Scored from outside, with every frame's ground truth that sparse: no RMSE, and why.
  for (int frame = 0; frame < 10; ++frame) keep_one_pixel(frame);
  ExternalResult external;
  external.estimates = folder / "whole_run" / "points.csv";
  external.trajectory = folder / "whole_run" / "trajectory.tum";
  const RunSummary scored = ScoreExternalResult(folder / "sparse", external, EvaluationOptions{}, folder / "scored");
  EXPECT_EQ(scored.frames_tracked, 10);
  EXPECT_EQ(scored.frames_evaluated, 0);
  EXPECT_EQ(scored.input.frames_sparse_groundtruth, 10);
  EXPECT_NE(DescribeSummary(scored).find("no RMSE: the ground truth is too sparse to score any frame"),
            std::string::npos)
      << DescribeSummary(scored);
  EXPECT_EQ(DescribeSummary(scored).find("no ground truth"), std::string::npos) << DescribeSummary(scored);
  fs::remove_all(folder);
}

// A disk that fills during a run ends it with an error that says so, within a few frames, and
// leaves no summary.json: a run folder without one is not a finished run (nrslam_eval runs it
// again) rather than a finished run with short files. Needs a small filesystem of its own,
// which root can mount.
TEST(RunSequenceErrors, AFullDiskEndsTheRunWithAnErrorAndNoSummary) {
  const fs::path folder = UniqueTempFolder("nrslam_full_disk");
  fs::remove_all(folder);
  fs::create_directories(folder / "small");
  if (geteuid() != 0 || std::system(("mount -t tmpfs -o size=96k tmpfs " + (folder / "small").string() +
                                     " > /dev/null 2>&1").c_str()) != 0) {
    fs::remove_all(folder);
    GTEST_SKIP() << "cannot mount a small filesystem here";
  }
  SimulateSmall("sim-0", 30, 160, 120, folder / "sequence");
  try {
    RunSequence(folder / "sequence", TrackingExperiment(), folder / "small" / "run");
    ADD_FAILURE() << "the run ended as if its files were whole";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("(is the disk full?)"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(folder / "small" / "run" / "summary.json"));
  EXPECT_EQ(std::system(("umount " + (folder / "small").string()).c_str()), 0);
  fs::remove_all(folder);
}

// Lost in two black frames, the run starts a second map from depth once the view is back (the
// `map` column counts 2 by the last frame). Each map numbers its points from 0; points.csv
// numbers the second map's after the first's, so an id names one point of the run
// (nrslam_eval compare relies on it).
TEST(RunSequenceErrors, ASecondMapNumbersItsPointsAfterTheFirst) {
  const fs::path folder = UniqueTempFolder("nrslam_second_map");
  fs::remove_all(folder);
  SimulateSmall("sim-0", 10, 320, 240, folder);
  BlankFrames(folder, 5, 7, cv::Scalar(0, 0, 0));
  SystemOptions options = TrackingExperiment();
  options.run.reinitialise_after_loss = true;
  options.tracking.max_dropout_frames = 0;  // lost on the first black frame, not skipped
  RunSequence(folder, options, folder / "run");
  std::set<int64_t> first_map, second_map;
  for (const auto& row : ReadCsv(folder / "run" / "points.csv")) {
    const int frame = static_cast<int>(std::stod(row.at("frame")));
    (frame < 5 ? first_map : second_map).insert(std::stoll(row.at("point_id")));
  }
  const auto metrics = ReadCsv(folder / "run" / "metrics.csv");
  ASSERT_EQ(metrics.size(), 10u);
  EXPECT_EQ(metrics[9].at("map"), "2");
  ASSERT_FALSE(first_map.empty());
  ASSERT_FALSE(second_map.empty());
  EXPECT_LT(*first_map.rbegin(), *second_map.begin());
  fs::remove_all(folder);
}

// A view that goes black (the light off, the lens covered) for good ends the run lost from its
// first black frame: no patch is matched on a flat image, and the frames skipped as dropouts
// before the loss are lost too. The summary says where and why.
TEST(RunSequenceErrors, ABlackedOutViewIsLostWithWhereAndWhy) {
  const fs::path folder = UniqueTempFolder("nrslam_black_end");
  fs::remove_all(folder);
  SimulateSmall("sim-0", 10, 320, 240, folder);
  BlankFrames(folder, 7, 10, cv::Scalar(0, 0, 0));
  SystemOptions options = TrackingExperiment();
  options.tracking.max_dropout_frames = 1;
  const RunSummary stopped = RunSequence(folder, options, folder / "stopped");
  EXPECT_EQ(stopped.frames_tracked, 7);
  EXPECT_EQ(stopped.input.frames_dropout, 1);
  EXPECT_EQ(stopped.Status(), "lost");
  EXPECT_EQ(stopped.stop_frame, 7);
  EXPECT_NE(stopped.stop_reason.find("points tracked: skipped as an image dropout"), std::string::npos)
      << stopped.stop_reason;
  const Json written = ReadJsonFile(folder / "stopped" / "summary.json");
  EXPECT_EQ(written.at("status"), "lost");
  EXPECT_EQ(written.at("stop_frame"), 7);
  EXPECT_EQ(written.at("stop_reason"), stopped.stop_reason);
  EXPECT_EQ(written.at("frames_dropout"), 1);
  const auto metrics = ReadCsv(folder / "stopped" / "metrics.csv");
  ASSERT_EQ(metrics.size(), 10u);
  EXPECT_NE(metrics[7].at("note").find("(1 of at most 1 in a row)"), std::string::npos) << metrics[7].at("note");
  EXPECT_EQ(metrics[8].at("note"), "only 0 points tracked");  // the second black frame: LOST
  fs::remove_all(folder);
}

// The tracking experiment on `folder`/sequence with `options` (a dropout rule turned off) ends at
// `frame`, the first spoiled one, having tracked every frame before it.
void ExpectLostFromFrame(const fs::path& folder, const SystemOptions& options, int frame) {
  const RunSummary stopped = RunSequence(folder / "sequence", options, folder / "stopped");
  EXPECT_EQ(stopped.Status(), "lost");
  EXPECT_EQ(stopped.stop_frame, frame);
  EXPECT_EQ(stopped.frames_tracked, frame);
  EXPECT_EQ(stopped.input.frames_dropout, 0);
}

// A few blank frames in the middle of a run (a flush, the lens against the tissue) are skipped
// with the map kept: tracking picks up where it left off, on the same points, about as accurate
// as without the gap. Without the skip (the reference), the tracking experiment ends there.
TEST_F(RunSequenceTest, AShortImageDropoutIsSkippedWithTheMapKept) {
  const fs::path folder = CopyOfSequence("dropout");
  BlankFrames(folder / "sequence", 15, 18, cv::Scalar(128, 128, 128));

  const RunSummary skipped = RunSequence(folder / "sequence", TrackingExperiment(), folder / "skipped");
  EXPECT_EQ(skipped.Status(), "ok");
  EXPECT_EQ(skipped.maps, 1);
  EXPECT_EQ(skipped.frames_tracked, 37);
  EXPECT_EQ(skipped.frames_lost, 3);
  EXPECT_EQ(skipped.input.frames_dropout, 3);
  EXPECT_EQ(skipped.input.frames_unreadable, 0);
  EXPECT_NE(DescribeSummary(skipped).find("3 frames skipped as image dropouts (lost; the map kept)"), std::string::npos)
      << DescribeSummary(skipped);
  const auto metrics = ReadCsv(folder / "skipped" / "metrics.csv");
  ASSERT_EQ(metrics.size(), 40u);
  for (int frame = 0; frame < 40; ++frame) {
    const bool blank = frame >= 15 && frame < 18;
    EXPECT_EQ(metrics[static_cast<size_t>(frame)].at("state"), blank ? "lost" : "tracking") << frame;
  }
  // The points after the gap are the map's from before it.
  std::set<PointId> before, after;
  for (const CsvPoint& p : ReadPointsCsv(folder / "skipped" / "points.csv")) {
    if (p.frame == 14) before.insert(p.id);
    if (p.frame == 18) after.insert(p.id);
  }
  ASSERT_GE(after.size(), 50u);
  EXPECT_GE(std::count_if(after.begin(), after.end(), [&](PointId id) { return before.count(id) > 0; }),
            static_cast<std::ptrdiff_t>(after.size() * 9 / 10));
  EXPECT_LT(skipped.rmse_mm, 1.25 * summary_->rmse_mm) << "without the gap: " << summary_->rmse_mm << " mm";

  SystemOptions reference = TrackingExperiment();
  reference.tracking.max_dropout_frames = 0;
  ExpectLostFromFrame(folder, reference, 15);
}

// A frame of noise (garbled data) is a dropout too, by the share of the map's tracks the KLT
// finds on it: a dozen lock onto chance patterns, enough to pass min_points, and no pose fits
// them. Without the share rule the tracking experiment ends there.
TEST_F(RunSequenceTest, AFrameOfNoiseIsSkippedAsADropout) {
  const fs::path folder = CopyOfSequence("noise");
  cv::Mat noise(240, 320, CV_8UC3);
  cv::RNG(7).fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::imwrite((folder / "sequence" / "rgb" / FrameFileName(15)).string(), noise);

  const RunSummary skipped = RunSequence(folder / "sequence", TrackingExperiment(), folder / "skipped");
  EXPECT_EQ(skipped.Status(), "ok");
  EXPECT_EQ(skipped.frames_tracked, 39);
  EXPECT_EQ(skipped.input.frames_dropout, 1);
  const auto metrics = ReadCsv(folder / "skipped" / "metrics.csv");
  ASSERT_EQ(metrics.size(), 40u);
  EXPECT_GE(std::stoi(metrics[15].at("klt_tracked")), TrackingOptions{}.min_points);  // the count alone would pass it
  EXPECT_NE(metrics[15].at("note").find("skipped as an image dropout"), std::string::npos) << metrics[15].at("note");
  EXPECT_LT(skipped.rmse_mm, 1.25 * summary_->rmse_mm) << "without the noise: " << summary_->rmse_mm << " mm";

  SystemOptions count_only = TrackingExperiment();
  count_only.tracking.min_tracked_fraction = 0;
  ExpectLostFromFrame(folder, count_only, 15);
}

// Paints an on-screen display's two lines of grey text on the first `frames` frames of
// `sequence` (the fixture's 40: every frame); returns the strokes.
cv::Mat PaintDisplay(const fs::path& sequence, int frames = 40) {
  cv::Mat strokes(240, 320, CV_8UC1, cv::Scalar(0));
  cv::putText(strokes, "CV-190  ID 0042", {20, 40}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255), 2);
  cv::putText(strokes, "Eh:A3 Cm:1", {20, 205}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255), 2);
  for (int frame = 0; frame < frames; ++frame) {
    const fs::path file = sequence / "rgb" / FrameFileName(frame);
    cv::Mat image = cv::imread(file.string());
    image.setTo(cv::Scalar(150, 225, 150), strokes);
    cv::imwrite(file.string(), image);
  }
  return strokes;
}

// Gives `sequence` another frame rate: sequence.json's, and its ground truth's clock with it.
void SetFrameRate(const fs::path& sequence, double fps) {
  nlohmann::json info = ReadJsonFile(sequence / "sequence.json");
  info["fps"] = fps;
  std::ofstream(sequence / "sequence.json") << info.dump(2);
  std::vector<StampedPose> poses = ReadTum(sequence / "groundtruth.tum");
  for (size_t index = 0; index < poses.size(); ++index) poses[index].timestamp = static_cast<double>(index) / fps;
  WriteTum(sequence / "groundtruth.tum", poses);
}

// An endoscope's on-screen display (grey text, not bright enough to pass for a highlight) on
// every frame: corners on it would be tracked as points that move with the camera. The run finds
// it static from 24 of its frames and leaves it out; with that off, the display is tracked. (The
// fixture's 1.3 s are let pass for a long enough sequence; on it nothing else stays put.)
TEST_F(RunSequenceTest, AnOnScreenDisplayIsLeftOutNotTracked) {
  const fs::path folder = CopyOfSequence("display");
  const cv::Mat strokes = PaintDisplay(folder / "sequence");
  cv::Mat near_strokes;
  cv::dilate(strokes, near_strokes, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(7, 7)));
  const auto points_on_display = [&](const fs::path& run, int frame) {
    int count = 0;
    for (const CsvPoint& p : ReadPointsCsv(run / "points.csv")) {
      count += p.frame == frame && near_strokes.at<uint8_t>(cvRound(p.v), cvRound(p.u)) != 0;
    }
    return count;
  };

  SystemOptions checked = TrackingExperiment();
  checked.frontend.masks.static_min_seconds = 1;
  const RunSummary left_out = RunSequence(folder / "sequence", checked, folder / "left_out");
  EXPECT_EQ(left_out.frames_tracked, 40);
  EXPECT_GT(left_out.input.static_fraction, 0.02);
  EXPECT_EQ(ReadJsonFile(folder / "left_out" / "summary.json").at("static_fraction"), left_out.input.static_fraction);
  const cv::Mat static_mask = cv::imread((folder / "left_out" / "static_mask.png").string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(static_mask.empty());
  EXPECT_EQ(cv::countNonZero(static_mask & strokes), cv::countNonZero(strokes));
  for (int frame = 0; frame < 40; ++frame) EXPECT_EQ(points_on_display(folder / "left_out", frame), 0) << frame;
  EXPECT_NE(DescribeSummary(left_out).find("never changed"), std::string::npos) << DescribeSummary(left_out);
  EXPECT_LT(left_out.rmse_mm, 1.1 * summary_->rmse_mm) << "without the display: " << summary_->rmse_mm << " mm";
  // nrslam_eval's report shows it on the run's first frame.
  RunResult result;
  result.sequence = "display";
  result.status = "ok";
  result.input.static_fraction = left_out.input.static_fraction;
  result.run_folder = (folder / "left_out").string();
  WriteReport({result}, {}, {}, folder / "report");
  const std::string html = FileText(folder / "report" / "index.html");
  EXPECT_NE(html.find("what the run left out as never changing"), std::string::npos);
  EXPECT_NE(html.find("never changed (an on-screen display"), std::string::npos);
  EXPECT_TRUE(fs::exists(folder / "report" / "display_static.png"));

  SystemOptions kept = TrackingExperiment();
  kept.frontend.masks.static_frames = 0;
  const RunSummary tracked = RunSequence(folder / "sequence", kept, folder / "tracked");
  EXPECT_EQ(tracked.input.static_fraction, 0);
  EXPECT_GE(points_on_display(folder / "tracked", 39), 5);
  EXPECT_GT(tracked.rmse_mm, 1.1 * left_out.rmse_mm);
}

// A still camera over a still scene (every frame the first): all of it never changes, which is
// a still view, not a display; leaving it all out would leave nothing to track.
TEST_F(RunSequenceTest, AStillViewIsNotLeftOut) {
  const fs::path folder = CopyOfSequence("still");
  const fs::path sequence = folder / "sequence";
  for (int frame = 1; frame < 40; ++frame) {
    fs::copy_file(sequence / "rgb" / FrameFileName(0), sequence / "rgb" / FrameFileName(frame),
                  fs::copy_options::overwrite_existing);
  }
  SystemOptions checked = TrackingExperiment();
  checked.frontend.masks.static_min_seconds = 1;
  const RunSummary still = RunSequence(sequence, checked, folder / "run");
  EXPECT_EQ(still.input.static_fraction, 0);
  EXPECT_FALSE(fs::exists(folder / "run" / "static_mask.png"));
  EXPECT_EQ(still.frames_tracked, 40);
  EXPECT_EQ(CountLines(folder / "run" / "run.log", "a still view rather than a display"), 1);
}

// A run of a few frames is checked over its whole sequence: the display is found from all 40
// frames (4 s at 10 fps), and the run of the first 12 leaves it out.
TEST_F(RunSequenceTest, AShortRunIsCheckedForADisplayOverItsWholeSequence) {
  const fs::path folder = CopyOfSequence("display_short_run");
  const fs::path sequence = folder / "sequence";
  const cv::Mat strokes = PaintDisplay(sequence);
  SetFrameRate(sequence, 10.0);
  SystemOptions first_frames = TrackingExperiment();
  first_frames.run.last_frame = 12;
  const RunSummary run = RunSequence(sequence, first_frames, folder / "run");
  EXPECT_EQ(run.frames_total, 12);
  EXPECT_GT(run.input.static_fraction, 0.02);
  const cv::Mat static_mask = cv::imread((folder / "run" / "static_mask.png").string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(static_mask.empty());
  EXPECT_EQ(cv::countNonZero(static_mask & strokes), cv::countNonZero(strokes));
}

// A display shown for the first half of a sequence only is static in half its frames, too few
// for the check over the whole sequence; in windows of 8 s (the fixture's 40 frames at 2.5 fps:
// 16 s) the first window is all display, and its frames leave it out while the later frames,
// without it, keep the whole view.
TEST_F(RunSequenceTest, ADisplayShownForAWhileIsLeftOutOfItsFramesOnly) {
  const fs::path folder = CopyOfSequence("display_for_a_while");
  const fs::path sequence = folder / "sequence";
  const cv::Mat strokes = PaintDisplay(sequence, 20);
  SetFrameRate(sequence, 2.5);
  const SequenceReader reader(sequence);
  const MaskOptions masks;
  EXPECT_EQ(StaticWindows(40, 2.5, masks), (std::vector<std::pair<int, int>>{{0, 20}, {10, 30}, {20, 40}}));
  std::ostringstream log;
  const StaticRegions found = StaticRegions::OfSequence(reader, masks, 0, 40, log);
  for (int frame : {0, 10, 19}) {
    ASSERT_FALSE(found.At(frame).empty()) << frame;
    EXPECT_EQ(cv::countNonZero(found.At(frame) & strokes), cv::countNonZero(strokes)) << frame;
  }
  for (int frame : {20, 39}) EXPECT_TRUE(found.At(frame).empty()) << frame;
  EXPECT_EQ(cv::countNonZero(found.Union() & strokes), cv::countNonZero(strokes));
  EXPECT_NE(log.str().find("frames 0-19: "), std::string::npos) << log.str();
  // A run of the last frames looks at the windows that hold them only.
  std::ostringstream late_log;
  EXPECT_EQ(StaticRegions::OfSequence(reader, masks, 30, 40, late_log).Fraction(), 0);
  EXPECT_EQ(late_log.str().find("frames 0-19: "), std::string::npos) << late_log.str();

  const RunSummary run = RunSequence(sequence, TrackingExperiment(), folder / "run");
  EXPECT_EQ(run.frames_tracked, 40);
  EXPECT_NEAR(run.input.static_fraction, found.Fraction(), 1e-12);
  EXPECT_GT(run.input.static_fraction, 0.02);
  EXPECT_EQ(CountLines(folder / "run" / "run.log", "frames 0-19: "), 1);

  // On screen throughout, it is left out of every frame, each window's find kept in parts.
  const fs::path throughout = folder / "throughout";
  fs::copy(sequence, throughout, fs::copy_options::recursive);
  PaintDisplay(throughout, 40);
  const StaticRegions everywhere = StaticRegions::OfSequence(SequenceReader(throughout), masks, 0, 40, log);
  for (int frame = 0; frame < 40; ++frame) {
    ASSERT_FALSE(everywhere.At(frame).empty()) << frame;
    EXPECT_EQ(cv::countNonZero(everywhere.At(frame) & strokes), cv::countNonZero(strokes)) << frame;
  }

  // One window over the whole sequence, as before windows: half the frames are too few.
  SystemOptions whole = TrackingExperiment();
  whole.frontend.masks.static_window_seconds = 16;
  EXPECT_EQ(RunSequence(sequence, whole, folder / "whole").input.static_fraction, 0);
}

// Windows of static_window_seconds, half a window apart, the last one ending with the sequence;
// one window over a sequence no longer than one; none when the check is off or the sequence short.
TEST(StaticWindows, CoverTheSequenceHalfAWindowApart) {
  const MaskOptions masks;  // 8 s windows, sequences of 3.5 s or more
  using Windows = std::vector<std::pair<int, int>>;
  EXPECT_EQ(StaticWindows(120, 30, masks), (Windows{{0, 120}}));
  EXPECT_EQ(StaticWindows(240, 30, masks), (Windows{{0, 240}}));
  EXPECT_EQ(StaticWindows(300, 30, masks), (Windows{{0, 240}, {60, 300}}));
  EXPECT_EQ(StaticWindows(1000, 30, masks),
            (Windows{{0, 240}, {120, 360}, {240, 480}, {360, 600}, {480, 720}, {600, 840}, {720, 960}, {760, 1000}}));
  EXPECT_TRUE(StaticWindows(100, 30, masks).empty());  // 3.3 s
  // At 1 fps 8 s are 8 frames, too few to tell: windows of 10.
  EXPECT_EQ(StaticWindows(30, 1, masks), (Windows{{0, 10}, {5, 15}, {10, 20}, {15, 25}, {20, 30}}));
  MaskOptions off;
  off.static_frames = 0;
  EXPECT_TRUE(StaticWindows(1000, 30, off).empty());
}

// Over a short sequence the tissue near the lumen's far end barely changes: 12 frames of sim-2
// at 160x120 left two thirds of the image out as never changing, and tracking then lost the map.
// Such a sequence is not checked.
TEST(RunSequenceShortSequence, IsNotCheckedForDisplays) {
  const fs::path folder = UniqueTempFolder("nrslam_short_run_test");
  fs::remove_all(folder);
  SimulateSmall("sim-2", 12, 160, 120, folder / "sequence");
  const RunSummary short_run = RunSequence(folder / "sequence", TrackingExperiment(), folder / "run");
  EXPECT_EQ(short_run.input.static_fraction, 0);
  EXPECT_EQ(short_run.frames_tracked, 12);
  EXPECT_EQ(CountLines(folder / "run" / "run.log", "the sequence spans 0.4 s, under static_min_seconds"), 1);
  SystemOptions unguarded = TrackingExperiment();
  unguarded.frontend.masks.static_min_seconds = 0;
  const RunSummary checked = RunSequence(folder / "sequence", unguarded, folder / "checked");
  EXPECT_GT(checked.input.static_fraction, 0.3) << "the check would mistake this tissue for a display";
  EXPECT_LT(checked.frames_tracked, 12);
  fs::remove_all(folder);
}

// Frames 15–22 cut out of the recording: the tissue moves as far at once as over 9 frames. The
// frame after the cut is tracked and noted as a jump of the view, and no other is.
TEST_F(RunSequenceTest, FramesMissingFromTheRecordingAreNotedAsAJump) {
  const fs::path folder = CopyOfSequence("cut");
  const fs::path sequence = folder / "sequence";
  constexpr int kCutFrom = 15, kCut = 8, kFrames = 40;
  std::vector<StampedPose> poses = ReadTum(sequence / "groundtruth.tum");
  poses.erase(poses.begin() + kCutFrom, poses.begin() + kCutFrom + kCut);
  for (size_t i = 0; i < poses.size(); ++i) poses[i].timestamp = static_cast<double>(i) / 30;
  WriteTum(sequence / "groundtruth.tum", poses);
  for (int frame = kCutFrom + kCut; frame < kFrames; ++frame) {
    for (const char* images : {"rgb", "depth"}) {
      fs::rename(sequence / images / FrameFileName(frame), sequence / images / FrameFileName(frame - kCut));
    }
  }
  nlohmann::json info = ReadJsonFile(sequence / "sequence.json");
  info["frame_count"] = kFrames - kCut;
  std::ofstream(sequence / "sequence.json") << info.dump(2);

  const RunSummary cut = RunSequence(sequence, TrackingExperiment(), folder / "run");
  EXPECT_EQ(cut.frames_tracked, kFrames - kCut);
  EXPECT_EQ(cut.input.view_jumps, 1);
  EXPECT_EQ(ReadJsonFile(folder / "run" / "summary.json").at("view_jumps"), 1);
  const auto metrics = ReadCsv(folder / "run" / "metrics.csv");
  ASSERT_EQ(metrics.size(), static_cast<size_t>(kFrames - kCut));
  EXPECT_NE(metrics[kCutFrom].at("note").find("the view jumped"), std::string::npos) << metrics[kCutFrom].at("note");
  EXPECT_EQ(CountLines(folder / "run" / "metrics.csv", "the view jumped"), 1);
  EXPECT_NE(DescribeSummary(cut).find("1 jump of the view"), std::string::npos) << DescribeSummary(cut);
  SystemOptions unnoted = TrackingExperiment();
  unnoted.tracking.jump_flow_ratio = 0;
  EXPECT_EQ(RunSequence(sequence, unnoted, folder / "unnoted").input.view_jumps, 0);
}

// An instrument over most of the view hides more than half of the map's tracks, but those it
// leaves match as on an intact frame: the frames are tracked on the visible part, and the first
// one's note says so. With every frame under the share taken for a dropout, they are skipped.
TEST_F(RunSequenceTest, AnInstrumentOverMostOfTheViewIsNotADropout) {
  const fs::path folder = CopyOfSequence("instrument");
  PaintInstrument(folder / "sequence", 15, 18);

  const RunSummary tracked = RunSequence(folder / "sequence", TrackingExperiment(), folder / "tracked");
  EXPECT_EQ(tracked.Status(), "ok");
  EXPECT_EQ(tracked.input.frames_dropout, 0);
  EXPECT_EQ(tracked.frames_tracked, 40);
  EXPECT_EQ(tracked.input.sudden_occlusions, 1);  // counted once, on the frame it came
  EXPECT_EQ(ReadJsonFile(folder / "tracked" / "summary.json").at("sudden_occlusions"), 1);
  const auto metrics = ReadCsv(folder / "tracked" / "metrics.csv");
  ASSERT_EQ(metrics.size(), 40u);
  for (int frame = 15; frame < 18; ++frame) EXPECT_EQ(metrics[static_cast<size_t>(frame)].at("state"), "tracking");
  // Only the first such frame is under the share: the tracks it hid are lost from then on.
  EXPECT_NE(metrics[15].at("note").find("the view partly hidden, the frame used"), std::string::npos)
      << metrics[15].at("note");
  EXPECT_EQ(metrics[14].at("note"), "");
  // The instrument hid more than half of the tracks.
  EXPECT_LT(2 * std::stoi(metrics[15].at("klt_tracked")), std::stoi(metrics[14].at("points")));
  SystemOptions strict = TrackingExperiment();
  strict.tracking.dropout_min_match_ssim = 1;
  const RunSummary skipped = RunSequence(folder / "sequence", strict, folder / "skipped");
  EXPECT_EQ(skipped.input.frames_dropout, 3);
  EXPECT_EQ(skipped.input.sudden_occlusions, 0);
}

// An instrument hides most of the view for ten frames while the tissue under it goes on
// moving: its points come back far from where they were left. Looked for only within the gate
// of their projections, few are found again; with the consensus of their neighbours' offsets
// (reassociation_consensus_k) most are.
TEST_F(RunSequenceTest, PointsAnInstrumentHidAreFoundAgainWhereTheirNeighboursMoved) {
  const fs::path folder = CopyOfSequence("long_instrument");
  PaintInstrument(folder / "sequence", 15, 25);
  const auto found_again = [&](const std::string& name, int k) {
    SystemOptions options = TrackingExperiment();
    options.tracking.reassociation_consensus_k = k;
    const auto [count, summary] = FoundAgain(folder, name, options, 25, 28);
    EXPECT_LT(summary.rmse_mm, 2.0) << name;
    return count;
  };
  // Measured: 32 by the gate, 82 with the consensus, over the three frames after the instrument.
  const int by_gate = found_again("gate", 0);
  const int by_consensus = found_again("consensus", 4);
  EXPECT_GE(by_consensus, 2 * by_gate) << by_gate << " found again by the gate alone";
}

// The instrument slides in over 6 frames, 40 px a frame, stays 4 and leaves the same way: no
// frame loses most of the view at once, but the points it covers are lost in a band that moves
// across it. They are hidden (MarkHiddenLosses), and found again as they were above.
TEST_F(RunSequenceTest, PointsAnInstrumentSlidingInHidAreFoundAgainToo) {
  const fs::path folder = CopyOfSequence("sliding_instrument");
  const int first = 12, steps = 6, hold = 4;
  for (int step = 0; step < steps; ++step) {
    const int tip_x = 320 - 40 * (step + 1);
    PaintShaft(folder / "sequence", first + step, tip_x);
    PaintShaft(folder / "sequence", first + 2 * steps + hold - 1 - step, tip_x);
  }
  for (int frame = first + steps; frame < first + steps + hold; ++frame) PaintShaft(folder / "sequence", frame, 80);
  const int gone = first + 2 * steps + hold;
  const auto found_again = [&](const std::string& name, int recent_frames) {
    SystemOptions options = TrackingExperiment();
    options.tracking.hidden_recent_frames = recent_frames;
    const auto [count, summary] = FoundAgain(folder, name, options, gone - steps, gone + 3);
    EXPECT_EQ(summary.input.sudden_occlusions, 0) << name;
    return count;
  };
  const int by_gate = found_again("gate", 0);
  const int hidden = found_again("hidden", TrackingExperiment().tracking.hidden_recent_frames);
  // Measured: 7 by the gate, 31 with the hidden points' consensus, from the frame it starts to leave.
  EXPECT_GE(hidden, 2 * by_gate) << by_gate << " found again by the gate alone";
}

// Where nothing hid the view, the consensus looks for no point beyond the gate: a point lost to
// the KLT alone that comes back far from its projection more often has a stale map position
// than neighbours that moved with it. The run is the same as with the gate alone.
TEST_F(RunSequenceTest, TheConsensusLooksOnlyForPointsTheViewHid) {
  ASSERT_GT(TrackingExperiment().tracking.reassociation_consensus_k, 0);
  SystemOptions gate_only = TrackingExperiment();
  gate_only.tracking.reassociation_consensus_k = 0;
  const RunSummary by_gate = RunSequence(*base_ / "sequence", gate_only, *base_ / "gate_only");
  EXPECT_EQ(by_gate.rmse_mm, summary_->rmse_mm);
  const auto with_consensus = ReadCsv(*base_ / "run" / "metrics.csv");
  const auto without = ReadCsv(*base_ / "gate_only" / "metrics.csv");
  ASSERT_EQ(with_consensus.size(), without.size());
  int found_again = 0;
  for (size_t frame = 0; frame < without.size(); ++frame) {
    EXPECT_EQ(with_consensus[frame].at("reassociated"), without[frame].at("reassociated")) << "frame " << frame;
    found_again += std::stoi(without[frame].at("reassociated"));
  }
  EXPECT_GT(found_again, 0);  // re-association was at work
}

// The same in the full monocular system: the mapper goes on with the map it had, where the
// reference starts a new one.
TEST(MonocularRun, AShortImageDropoutKeepsTheMap) {
  const fs::path folder = UniqueTempFolder("nrslam_monocular_dropout");
  fs::remove_all(folder);
  SimulateSmall("sim-1", 40, 320, 240, folder / "sequence");
  const cv::Mat grey(240, 320, CV_8UC3, cv::Scalar(128, 128, 128));
  for (int frame = 25; frame < 27; ++frame) {
    cv::imwrite((folder / "sequence" / "rgb" / FrameFileName(frame)).string(), grey);
  }
  const RunSummary summary = RunSequence(folder / "sequence", SystemOptions{}, folder / "run");
  ASSERT_GE(summary.init_frame, 0);
  EXPECT_LT(summary.init_frame, 25);
  EXPECT_EQ(summary.Status(), "ok");
  EXPECT_EQ(summary.maps, 1);
  EXPECT_EQ(summary.input.frames_dropout, 2);
  EXPECT_EQ(summary.frames_tracked, 40 - summary.init_frame - 2);
  SystemOptions reference;
  reference.tracking.max_dropout_frames = 0;
  const RunSummary restarted = RunSequence(folder / "sequence", reference, folder / "reference");
  EXPECT_EQ(restarted.maps, 2);  // lost on the first blank frame, a new map from the images after
  EXPECT_EQ(restarted.input.frames_dropout, 0);
  fs::remove_all(folder);
}

// While the map is being made from two views, a frame of noise is skipped the same way: the
// initialiser keeps its reference and tracks. Without the rule the noise cuts most tracks, the
// reference restarts on the noise frame itself, and the map comes later from a later reference.
TEST(MonocularRun, ANoiseFrameWhileInitialisingKeepsTheReference) {
  const fs::path folder = UniqueTempFolder("nrslam_monocular_init_noise");
  fs::remove_all(folder);
  SimulateSmall("sim-1", 40, 320, 240, folder / "sequence");
  cv::Mat noise(240, 320, CV_8UC3);
  cv::RNG(9).fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::imwrite((folder / "sequence" / "rgb" / FrameFileName(2)).string(), noise);
  const RunSummary skipped = RunSequence(folder / "sequence", SystemOptions{}, folder / "skipped");
  const auto metrics = ReadCsv(folder / "skipped" / "metrics.csv");
  ASSERT_EQ(metrics.size(), 40u);
  EXPECT_NE(metrics[2].at("note").find("tracks found ("), std::string::npos) << metrics[2].at("note");
  EXPECT_NE(metrics[2].at("note").find("): skipped as an image dropout"), std::string::npos) << metrics[2].at("note");
  const auto log = FileLines(folder / "skipped" / "run.log");
  EXPECT_TRUE(std::any_of(log.begin(), log.end(), [](const std::string& line) {
    return line.find("initialised from frames 0 and") != std::string::npos;
  }));
  SystemOptions count_only;
  count_only.tracking.min_tracked_fraction = 0;
  const RunSummary restarted = RunSequence(folder / "sequence", count_only, folder / "restarted");
  const auto restarted_metrics = ReadCsv(folder / "restarted" / "metrics.csv");
  ASSERT_EQ(restarted_metrics.size(), 40u);
  EXPECT_NE(restarted_metrics[2].at("note").find("new reference"), std::string::npos) << restarted_metrics[2].at("note");
  ASSERT_GE(skipped.init_frame, 0);
  EXPECT_LT(skipped.init_frame, restarted.init_frame);
  EXPECT_GT(skipped.frames_tracked, restarted.frames_tracked);
  fs::remove_all(folder);
}

}  // namespace
}  // namespace nrslam
