// Mapping: DBSCAN, the Deformable Bundle Adjustment on synthetic keyframes with a known
// answer, and monocular initialisation on a simulated colonoscopy against its ground truth,
// including the reference's compacted-index bug (reference-behaviour §9.2).
#include <gtest/gtest.h>

#include <functional>
#include <optional>
#include <set>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <utility>

#include "temp_folder.h"
#include "nrslam/camera/reprojection_cost.h"
#include "nrslam/deformation/deformation_graph.h"
#include "nrslam/eval/depth_evaluation.h"
#include "nrslam/io/sequence_reader.h"
#include "nrslam/io/tum.h"
#include "nrslam/mapping/deformable_ba.h"
#include "nrslam/mapping/monocular_initialiser.h"
#include "nrslam/sim/simulate.h"
#include "nrslam/util/median.h"
#include "nrslam/util/random.h"

namespace nrslam {
namespace {
namespace fs = std::filesystem;

TEST(Dbscan, TwoClustersAndNoise) {
  Eigen::MatrixXd points(25, 2);
  for (int i = 0; i < 12; ++i) points.row(i) << 0.01 * i, 0.0;           // cluster along x near 0
  for (int i = 12; i < 24; ++i) points.row(i) << 5.0, 0.01 * (i - 12);  // cluster along y near x = 5
  points.row(24) << 2.5, 2.5;                                           // alone
  const std::vector<int> labels = Dbscan(points, 0.05, 3);
  for (int i = 1; i < 12; ++i) EXPECT_EQ(labels[i], labels[0]);
  for (int i = 13; i < 24; ++i) EXPECT_EQ(labels[i], labels[12]);
  EXPECT_NE(labels[0], labels[12]);
  EXPECT_GE(labels[0], 0);
  EXPECT_GE(labels[12], 0);
  EXPECT_EQ(labels[24], -1);
}

// Four keyframes looking at a rigid patch from a sideways-moving camera: exact pixels, the
// first pose right, the others and every per-keyframe position perturbed.
struct DbaScene {
  Camera camera = Camera::Pinhole(320, 240, 200, 200, 159.5, 119.5);
  DeformationModelOptions options;
  std::vector<Eigen::Vector3d> truth;
  std::vector<Rigid3> poses;
  std::vector<Keyframe> keyframes;
  DeformationGraph graph{options};

  DbaScene() {
    Rng rng(11);
    for (int i = 0; i < 60; ++i) truth.emplace_back(rng.Uniform(-1.5, 1.5), rng.Uniform(-1, 1), 4 + rng.Uniform(-0.3, 0.3));
    for (int k = 0; k < 4; ++k) poses.push_back(Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.02 * k, Eigen::Vector3d::UnitY())),
                                                       Eigen::Vector3d(-0.15 * k, 0.02 * k, 0)));
    graph.set_sigma(3.0);
    std::vector<PointId> ids;
    for (int i = 0; i < 60; ++i) ids.push_back(i);
    graph.ConnectCovisible(ids, {}, [&](PointId id) -> std::optional<Eigen::Vector3d> { return truth[id]; });
    for (int k = 0; k < 4; ++k) {
      Keyframe keyframe;
      keyframe.frame = 6 * k;
      keyframe.cam_from_world = poses[k];
      if (k > 0) {
        keyframe.cam_from_world = Rigid3(poses[k].rotation * Eigen::Quaterniond(Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitX())),
                                         poses[k].translation + Eigen::Vector3d(0.03, -0.02, 0.05));
      }
      for (int i = 0; i < 60; ++i) {
        keyframe.ids.push_back(i);
        keyframe.pixels.push_back(*camera.Project(poses[k] * truth[i]));
        keyframe.positions.push_back(truth[i] + Eigen::Vector3d(rng.Uniform(-0.05, 0.05), rng.Uniform(-0.05, 0.05),
                                                                rng.Uniform(-0.1, 0.1)));
      }
      keyframes.push_back(keyframe);
    }
  }
  std::vector<Keyframe*> Window() {
    std::vector<Keyframe*> window;
    for (Keyframe& keyframe : keyframes) window.push_back(&keyframe);
    return window;
  }
  // Mean |d − d0| / d0 over every pair of points, per keyframe.
  double MeanStrain() const {
    double sum = 0;
    int count = 0;
    for (const Keyframe& keyframe : keyframes) {
      for (int i = 0; i < 60; ++i) {
        for (int j = i + 1; j < 60; ++j) {
          const double rest = (truth[i] - truth[j]).norm();
          sum += std::abs((keyframe.positions[i] - keyframe.positions[j]).norm() - rest) / rest;
          ++count;
        }
      }
    }
    return sum / count;
  }
  double MaxReprojectionPx() const {
    double worst = 0;
    for (const Keyframe& keyframe : keyframes) {
      for (size_t i = 0; i < keyframe.ids.size(); ++i) {
        worst = std::max(worst, (*camera.Project(keyframe.cam_from_world * keyframe.positions[i]) - keyframe.pixels[i]).norm());
      }
    }
    return worst;
  }
};

TEST(DeformableBundleAdjustment, RestoresEachKeyframesShapeAndKeepsTheOldestPoseFixed) {
  // Each keyframe's shape and pose share a rigid-motion ambiguity (the viscous terms see only
  // relative motion), so the known answer is the shape — edge lengths back at their rest
  // lengths — with every observation reprojected, not the poses themselves.
  DbaScene scene;
  const double strain_before = scene.MeanStrain();
  const DbaReport report = DeformableBundleAdjustment(
      scene.camera, scene.options, WindowRegularisers(scene.graph, scene.Window()), 1.0, 30, false, scene.Window());
  EXPECT_EQ(report.keyframes, 4);
  EXPECT_EQ(report.points, 60);
  EXPECT_LT(report.final_cost, 0.01 * report.initial_cost);
  EXPECT_LT(scene.MaxReprojectionPx(), 0.5);
  EXPECT_LT(scene.MeanStrain(), 0.1 * strain_before);
  EXPECT_LT(scene.keyframes.front().cam_from_world.translation.norm(), 1e-12);
  EXPECT_LT(scene.keyframes.front().cam_from_world.rotation.angularDistance(Eigen::Quaterniond::Identity()), 1e-12);
  // The oldest keyframe's pose is right and fixed, so its shape is the true one.
  double first_error = 0;
  for (int i = 0; i < 60; ++i) first_error += (scene.keyframes[0].positions[i] - scene.truth[i]).norm() / 60;
  EXPECT_LT(first_error, 0.01);
}

// The ablation switches drop exactly their own terms: one elastic block per pair and keyframe,
// one viscous block per pair between consecutive keyframes. Without the springs nothing
// restores the shapes' edge lengths: the reprojections still fit, but the strain stays.
TEST(DeformableBundleAdjustment, AblationsDropTheirOwnTerms) {
  const auto run = [](bool elastic, bool viscous, double* strain_after) {
    DbaScene scene;
    scene.options.elastic = elastic;
    scene.options.viscous = viscous;
    const std::vector<std::vector<DbaPair>> regularisers = WindowRegularisers(scene.graph, scene.Window());
    const DbaReport report =
        DeformableBundleAdjustment(scene.camera, scene.options, regularisers, 1.0, 30, false, scene.Window());
    *strain_after = scene.MeanStrain();
    EXPECT_LT(scene.MaxReprojectionPx(), 0.5);
    return report.residual_blocks;
  };
  double strain_both = 0, strain_viscous = 0, strain_elastic = 0, strain_none = 0;
  const int both = run(true, true, &strain_both);
  const int viscous_only = run(false, true, &strain_viscous);
  const int elastic_only = run(true, false, &strain_elastic);
  const int neither = run(false, false, &strain_none);
  DbaScene scene;
  const std::vector<std::vector<DbaPair>> regularisers = WindowRegularisers(scene.graph, scene.Window());
  int pairs = 0, links = 0;
  for (const auto& keyframe_pairs : regularisers) {
    for (const DbaPair& pair : keyframe_pairs) {
      ++pairs;
      links += pair.next_i >= 0;
    }
  }
  ASSERT_GT(links, 0);
  EXPECT_EQ(neither, 4 * 60);  // the reprojections alone
  EXPECT_EQ(both - viscous_only, pairs);
  EXPECT_EQ(both - elastic_only, links);
  EXPECT_EQ(both, neither + pairs + links);
  EXPECT_LT(strain_both, 0.5 * strain_viscous);
  EXPECT_LT(strain_elastic, 0.5 * strain_none);
}

TEST(DeformableBundleAdjustment, RigidModeSharesOnePositionPerPoint) {
  DbaScene scene;
  const DbaReport report = DeformableBundleAdjustment(scene.camera, scene.options, {}, 1.0, 30, true, scene.Window());
  EXPECT_LT(report.final_cost, 0.01 * report.initial_cost);
  EXPECT_LT(scene.MaxReprojectionPx(), 0.5);
  for (int i = 0; i < 60; ++i) {
    EXPECT_EQ(scene.keyframes[0].positions[i], scene.keyframes[3].positions[i]) << i;
  }
}

TEST(DeformableBundleAdjustment, RigidModeLeavesOutObservationsBehindTheCamera) {
  // A shared position is seeded from the newest keyframe that sees the point; tissue that moved
  // can put it behind another keyframe's camera. Its residual would fail Ceres's first
  // evaluation and with it the whole solve (the model-selection trial on sim-6 did).
  DbaScene scene;
  scene.keyframes.back().positions[0] = Eigen::Vector3d(0, 0, -1);
  const DbaReport report = DeformableBundleAdjustment(scene.camera, scene.options, {}, 1.0, 30, true, scene.Window());
  EXPECT_EQ(report.points, 59);
  EXPECT_LT(report.final_cost, 0.01 * report.initial_cost);
  for (const Keyframe& keyframe : scene.keyframes) {
    for (size_t i = 1; i < keyframe.ids.size(); ++i) {
      EXPECT_LT(std::sqrt(SquaredReprojectionError(scene.camera, keyframe.cam_from_world, keyframe.positions[i],
                                                   keyframe.pixels[i])),
                0.5);
    }
  }
}

class MonocularInitialiserTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    folder_ = new fs::path(UniqueTempFolder("nrslam_mapping_test"));
    fs::remove_all(*folder_);
    SimOptions sim = SimPreset("sim-0");
    sim.frames = 31;
    sim.camera.width = 320;
    sim.camera.height = 240;
    SimulateSequence(sim, "sim-0-small", *folder_);
  }
  static void TearDownTestSuite() {
    fs::remove_all(*folder_);
    delete folder_;
  }

  // Feeds frames until the initialiser succeeds; `spoil_mask` may change each frame's mask first.
  static InitialisationAttempt Initialise(int* frame, const std::function<void(int, cv::Mat&)>& spoil_mask = {},
                                          double point_min_parallax_snr = 0, double shading_weight = 0) {
    const SequenceReader reader(*folder_);
    // 320x240 has about a quarter of the corners of 640x480: the count thresholds scale down.
    InitialisationOptions options;
    options.min_tracks = 50;
    options.min_points = 50;
    options.point_min_parallax_snr = point_min_parallax_snr;
    options.shading_weight = shading_weight;
    MonocularInitialiser initialiser(reader.info().camera, FrontendOptions{}, TrackingOptions{}, options);
    for (*frame = 0; *frame < reader.frame_count(); ++*frame) {
      const cv::Mat bgr = reader.ReadRgb(*frame);
      cv::Mat mask = reader.ReadMask(*frame);
      if (mask.empty()) mask = cv::Mat(bgr.size(), CV_8UC1, cv::Scalar(255));
      if (spoil_mask) spoil_mask(*frame, mask);
      InitialisationAttempt attempt = initialiser.Add(*frame, bgr, mask);
      if (attempt.success) return attempt;
    }
    return {};
  }
  // Depth RMSE (mm, scale fitted) of the initial points in the frame the map was made on.
  static FrameEvaluation Evaluate(const InitialMap& map, int frame) {
    const SequenceReader reader(*folder_);
    std::vector<DepthPoint> points;
    for (size_t i = 0; i < map.seed.points.size(); ++i) {
      const double z = (map.seed.cam_from_world * map.seed.points[i]).z();
      points.push_back({cv::Point2d(map.seed.pixels[i].x, map.seed.pixels[i].y), z});
    }
    return EvaluateFrame(points, reader.ReadDepthMm(frame), EvaluationOptions{});
  }
  static fs::path* folder_;
};
fs::path* MonocularInitialiserTest::folder_ = nullptr;

TEST_F(MonocularInitialiserTest, BuildsAScaledMapThatMatchesTheGroundTruth) {
  int frame = -1;
  const InitialisationAttempt attempt = Initialise(&frame);
  ASSERT_TRUE(attempt.success);
  EXPECT_LE(frame, 30);
  EXPECT_EQ(attempt.map.reference_frame, 0);
  EXPECT_GE(attempt.map.seed.points.size(), 50u);
  // Scaled so that the median reference depth is 3.
  std::vector<double> depths;
  for (const auto& p : attempt.map.seed.points) depths.push_back(p.z());
  std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
  EXPECT_NEAR(depths[depths.size() / 2], 3.0, 1e-9);
  const FrameEvaluation evaluation = Evaluate(attempt.map, frame);
  ASSERT_TRUE(evaluation.evaluated);
  const double flat = evaluation.flat_rmse_mm;
  std::cout << "initialised on frame " << frame << " with " << attempt.map.seed.points.size() << " points, depth RMSE "
            << evaluation.rmse_mm << " mm (a flat map: " << flat << " mm)\n";
  // Measured: 2.0 mm against 8.7 mm for the flat map (4.1 mm without the pose refinement).
  EXPECT_LT(evaluation.rmse_mm, 0.5 * flat);
}

TEST_F(MonocularInitialiserTest, PairsStayAlignedWhenReferenceCornersAreLost) {
  // From the second frame on, the sequence's mask hides the left third, which drops the tracks
  // there. The reference read pixels from the full list with indices of the compacted one
  // (§9.2), pairing the reference pixel of one point with the current pixel of another. sim-0
  // is rigid, so the ground truth says exactly where each reference pixel must be now.
  int frame = -1;
  const auto hide_left = [](int index, cv::Mat& mask) {
    if (index > 0) mask(cv::Rect(0, 0, mask.cols / 3, mask.rows)).setTo(0);
  };
  const InitialisationAttempt attempt = Initialise(&frame, hide_left);
  ASSERT_TRUE(attempt.success);
  const InitialMap& map = attempt.map;
  for (const cv::Point2f& pixel : map.seed.pixels) EXPECT_GE(pixel.x, 320 / 3);

  const SequenceReader reader(*folder_);
  const std::vector<StampedPose> truth = ReadTum(*folder_ / "groundtruth.tum");
  const Rigid3 current_from_reference =
      truth[frame].world_from_camera.Inverse() * truth[map.reference_frame].world_from_camera;
  const cv::Mat depth = reader.ReadDepthMm(map.reference_frame);
  std::vector<double> errors;
  for (size_t i = 0; i < map.reference_pixels.size(); ++i) {
    const cv::Point2f& r = map.reference_pixels[i];
    const float z = depth.at<float>(cvRound(r.y), cvRound(r.x));
    if (z <= 0) continue;
    const Eigen::Vector3d ray = reader.info().camera.Unproject(Eigen::Vector2d(r.x, r.y));
    const auto expected = reader.info().camera.Project(current_from_reference * (ray * (z / ray.z())));
    ASSERT_TRUE(expected);
    errors.push_back((*expected - Eigen::Vector2d(map.seed.pixels[i].x, map.seed.pixels[i].y)).norm());
  }
  ASSERT_GE(errors.size(), 40u);
  std::sort(errors.begin(), errors.end());
  std::cout << "with the left third masked: frame " << frame << ", " << map.seed.points.size()
            << " points, pair error median " << errors[errors.size() / 2] << " px, 3rd quartile "
            << errors[errors.size() * 3 / 4] << " px\n";
  // Mis-paired corners are tens of pixels apart, and with the reference's bug every pair after
  // the first dropped track is mis-paired. Aligned pairs err by KLT noise and depth rounding,
  // except a few tracks on fold edges (measured: median 0.35 px, 42 of 52 under 1.5 px; the
  // unmasked map has a few such tracks too).
  EXPECT_LT(errors[errors.size() / 2], 0.5);
  EXPECT_LT(errors[errors.size() * 3 / 4], 2.0);
  // And the map still has structure: better than all points at one depth.
  const FrameEvaluation evaluation = Evaluate(map, frame);
  EXPECT_LT(evaluation.rmse_mm, evaluation.flat_rmse_mm);
}

// The shading prior moves each initial point along its own ray and nothing else: the same
// points, pixels and frame, the median depth still the target. At weight 1 the map's shape is
// the brightness's alone, at 0.5 halfway (in log distance) between that and the two views'.
// On this still scene the two views are good, so the brightness map is the worse one, but it
// still has the scene's structure.
TEST_F(MonocularInitialiserTest, ShadingPriorMovesPointsAlongTheirRays) {
  int frame = -1;
  const InitialisationAttempt plain = Initialise(&frame);
  ASSERT_TRUE(plain.success);
  int shaded_frame = -1, half_frame = -1;
  const InitialisationAttempt shaded = Initialise(&shaded_frame, {}, 0, 1.0);
  const InitialisationAttempt half = Initialise(&half_frame, {}, 0, 0.5);
  ASSERT_TRUE(shaded.success && half.success);
  EXPECT_EQ(shaded_frame, frame);
  EXPECT_EQ(half_frame, frame);
  const auto& points = plain.map.seed.points;
  ASSERT_EQ(shaded.map.seed.points.size(), points.size());
  ASSERT_EQ(half.map.seed.points.size(), points.size());
  std::vector<double> depths, log_offsets;
  int moved = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d& p = points[i];
    const Eigen::Vector3d& s = shaded.map.seed.points[i];
    EXPECT_EQ(shaded.map.seed.pixels[i], plain.map.seed.pixels[i]);
    EXPECT_LT(p.normalized().cross(s.normalized()).norm(), 1e-12);
    depths.push_back(s.z());
    // Halfway in log distance, up to the one factor each map is scaled by.
    log_offsets.push_back(std::log(half.map.seed.points[i].norm()) - 0.5 * (std::log(p.norm()) + std::log(s.norm())));
    moved += std::abs(std::log(s.norm() / p.norm())) > 0.05;
  }
  EXPECT_NEAR(Median(depths), 3.0, 1e-9);
  for (double offset : log_offsets) EXPECT_NEAR(offset, log_offsets.front(), 1e-9);
  EXPECT_GT(moved, static_cast<int>(points.size()) / 4);
  const FrameEvaluation evaluation = Evaluate(shaded.map, frame);
  std::cout << "shading prior, weight 1: depth RMSE " << evaluation.rmse_mm << " mm against "
            << Evaluate(plain.map, frame).rmse_mm << " mm from two views (a flat map: " << evaluation.flat_rmse_mm
            << " mm)\n";
  EXPECT_LT(evaluation.rmse_mm, 0.8 * evaluation.flat_rmse_mm);
}

// The parallax gate relative to the epipolar error keeps a subset of the points the plain gate
// keeps, fewer the stricter it is and never fewer than min_points; when too few would pass, it
// keeps them all. It does not change when the map is accepted.
TEST_F(MonocularInitialiserTest, RelativeParallaxGateKeepsFewerOfTheSamePoints) {
  int frame = -1;
  const InitialisationAttempt plain = Initialise(&frame);
  ASSERT_TRUE(plain.success);
  const size_t all = plain.map.seed.points.size();
  std::set<std::pair<float, float>> plain_pixels;
  for (const cv::Point2f& pixel : plain.map.seed.pixels) plain_pixels.emplace(pixel.x, pixel.y);
  size_t fewest = all;
  int gates_that_dropped = 0;
  for (const double snr : {4.0, 8.0, 12.0, 16.0, 20.0, 1e9}) {
    int gated_frame = -1;
    const InitialisationAttempt gated = Initialise(&gated_frame, {}, snr);
    ASSERT_TRUE(gated.success) << snr;
    EXPECT_EQ(gated_frame, frame) << snr;
    const size_t kept = gated.map.seed.points.size();
    std::cout << "point_min_parallax_snr " << snr << ": " << kept << " of " << all << " points\n";
    for (const cv::Point2f& pixel : gated.map.seed.pixels) EXPECT_TRUE(plain_pixels.count({pixel.x, pixel.y})) << snr;
    if (kept == all) continue;
    EXPECT_LE(kept, fewest) << snr;
    EXPECT_GE(kept, 50u) << snr;
    fewest = kept;
    ++gates_that_dropped;
  }
  EXPECT_GE(gates_that_dropped, 2);  // measured: 62 and 52 of 70 points at 12 and 16
  int frame_beyond = -1;
  EXPECT_EQ(Initialise(&frame_beyond, {}, 1e9).map.seed.points.size(), all);  // none would pass
}

}  // namespace
}  // namespace nrslam
