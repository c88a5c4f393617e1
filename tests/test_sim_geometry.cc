// Geometry of the simulator: depth against analytic answers, and the deformation law.
#include <gtest/gtest.h>

#include <filesystem>
#include <optional>

#include "temp_folder.h"
#include "nrslam/io/sequence_reader.h"
#include "nrslam/sim/colon_scene.h"
#include "nrslam/sim/lobes_scene.h"
#include "nrslam/sim/renderer.h"
#include "nrslam/sim/simulate.h"

namespace nrslam {
namespace {

SimOptions StraightCylinder() {
  SimOptions options;
  options.frames = 1;
  options.colon.straight = true;
  options.colon.wobble_lateral_mm = 0;
  options.colon.wobble_rotation_deg = 0;
  options.appearance.vessel_density = 0.2;  // appearance is irrelevant here; keep it quick
  return options;
}

// z-depth of the ray through `bearing` from a camera on the axis of an infinite cylinder of
// radius r looking along it; nullopt where the meshed tube has ended.
std::optional<double> CylinderDepth(const Eigen::Vector3d& bearing, const SimOptions& options) {
  const double rho = bearing.head<2>().norm();
  if (rho < 1e-9) return std::nullopt;
  const double distance = options.colon.radius_mean_mm / rho;
  if (bearing.z() * distance > options.colon.view_ahead_mm - 2.0) return std::nullopt;
  return distance * bearing.z();
}

TEST(SimGeometry, StraightCylinderDepthMatchesTheAnalyticDepth) {
  const SimOptions options = StraightCylinder();
  Renderer renderer(options);
  const RenderedFrame frame = renderer.Render(0);
  const Camera& camera = renderer.camera();
  double max_error = 0.0;
  int compared = 0;
  for (int y = 0; y < camera.height(); ++y) {
    for (int x = 0; x < camera.width(); ++x) {
      const auto expected = CylinderDepth(camera.Unproject(Eigen::Vector2d(x, y)), options);
      if (!expected) continue;
      const float rendered = frame.left.depth_mm.at<float>(y, x);
      ASSERT_GT(rendered, 0.f) << "pixel " << x << "," << y << " hit nothing";
      max_error = std::max(max_error, std::abs(rendered - *expected));
      ++compared;
    }
  }
  EXPECT_GT(compared, camera.width() * camera.height() * 9 / 10);
  EXPECT_LT(max_error, 0.01) << "over " << compared << " pixels";
  RecordProperty("max_depth_error_mm", std::to_string(max_error));
}

TEST(SimGeometry, StoredDepthPngAddsOnlyQuantisation) {
  const SimOptions options = StraightCylinder();
  const auto folder = UniqueTempFolder("nrslam_cylinder");
  SimulateSequence(options, "cylinder", folder);
  SequenceReader reader(folder);
  const cv::Mat depth = reader.ReadDepthMm(0);
  const Camera& camera = reader.info().camera;
  double max_error = 0.0;
  for (int y = 0; y < camera.height(); y += 2) {
    for (int x = 0; x < camera.width(); x += 2) {
      const auto expected = CylinderDepth(camera.Unproject(Eigen::Vector2d(x, y)), options);
      if (expected) max_error = std::max(max_error, std::abs(depth.at<float>(y, x) - *expected));
    }
  }
  // Rendered error (< 0.01 above) plus half a depth unit of rounding.
  EXPECT_LT(max_error, 0.01 + 0.5 * options.depth_unit_mm);
  std::filesystem::remove_all(folder);
}

TEST(SimGeometry, ColonFollowsTheWaveLaw) {
  const SimOptions options = SimPreset("sim-6");  // A = 10 mm, ω = 5 rad/s
  const ColonScene scene(options);
  const double a = options.deformation.amplitude_mm, w = options.deformation.omega_rad_s;
  const double lambda = options.deformation.lambda_mm;
  for (double s : {5.0, 33.3, 71.0}) {
    for (double theta : {0.0, 1.3, 4.0}) {
      const Eigen::Vector3d rest = scene.RestPosition(0, s, theta);
      for (double t : {0.0, 0.1, 0.37, 1.0, 2.5}) {
        const Eigen::Vector3d moved = scene.Position(0, s, theta, t);
        EXPECT_DOUBLE_EQ(moved.x(), rest.x());
        EXPECT_DOUBLE_EQ(moved.z(), rest.z());
        EXPECT_NEAR(moved.y(), rest.y() + a * std::sin(w * t + (rest.x() + rest.y() + rest.z()) / lambda), 1e-12);
      }
    }
  }
  // sim-0 does not move.
  const ColonScene still(SimPreset("sim-0"));
  EXPECT_EQ(still.Position(0, 40.0, 2.0, 0.0), still.Position(0, 40.0, 2.0, 3.0));
}

TEST(SimGeometry, RenderedDepthIsTheDeformedSurfaceSeenFromTheTruePose) {
  SimOptions options = SimPreset("sim-6");
  options.camera.width = 160;
  options.camera.height = 120;
  options.appearance.vessel_density = 0.2;
  Renderer renderer(options);
  const int frame_index = 17;
  const RenderedFrame frame = renderer.Render(frame_index);
  const double time = renderer.TimeOf(frame_index);
  const Rigid3 camera_from_world = frame.world_from_camera.Inverse();
  int checked = 0;
  for (int y = 5; y < 120; y += 10) {
    for (int x = 5; x < 160; x += 10) {
      const Eigen::Vector3d bearing = renderer.camera().Unproject(Eigen::Vector2d(x, y));
      const SurfaceHit hit = renderer.caster().Cast(frame.world_from_camera.translation,
                                                    frame.world_from_camera.rotation * bearing);
      if (!hit.valid) continue;
      // The material point hit, moved by the law to this frame's time, is where the ray ends.
      const Eigen::Vector3d surface = renderer.scene().Position(hit.patch, hit.material.x(), hit.material.y(), time);
      EXPECT_LT((surface - hit.position).norm(), 0.2);
      const Eigen::Vector3d in_camera = camera_from_world * surface;
      EXPECT_NEAR(in_camera.z(), frame.left.depth_mm.at<float>(y, x), 0.2);
      const auto pixel = renderer.camera().Project(in_camera);
      ASSERT_TRUE(pixel.has_value());
      EXPECT_LT((*pixel - Eigen::Vector2d(x, y)).norm(), 0.5);
      ++checked;
    }
  }
  EXPECT_GT(checked, 150);
}

TEST(SimGeometry, LobesBreatheOutOfPhaseAndTheBackgroundStays) {
  const SimOptions options = SimPreset("lap-lobes");
  const LobesScene scene(options);
  const double quarter = M_PI / 2 / options.deformation.omega_rad_s;
  const Eigen::Vector3d a = scene.LobeDisplacement(LobesScene::kLobeA, quarter);
  const Eigen::Vector3d b = scene.LobeDisplacement(LobesScene::kLobeB, quarter);
  EXPECT_NEAR(a.norm(), options.deformation.amplitude_mm, 1e-9);
  EXPECT_GT((a - b).norm(), options.deformation.amplitude_mm);  // they slide against each other
  EXPECT_EQ(scene.LobeDisplacement(LobesScene::kBackground, quarter), Eigen::Vector3d::Zero());
  const Eigen::Vector3d rim_rest = scene.RestPosition(LobesScene::kLobeA, 0.95, 0.2);
  EXPECT_LT((scene.Position(LobesScene::kLobeA, 0.95, 0.2, quarter) - rim_rest - a).norm(), 0.2);
}

}  // namespace
}  // namespace nrslam
