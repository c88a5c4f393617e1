// Mid-term re-association: map points lost behind an occluder (a mask over part of the image,
// as a tool would be masked) are found again by a KLT seeded at their projection once the
// occluder has gone, and where they are found is where the surface point truly is.
#include <gtest/gtest.h>

#include <map>
#include <set>

#include "nrslam/sim/renderer.h"
#include "nrslam/tracking/tracker.h"

namespace nrslam {
namespace {

struct OccluderRun {
  int frames_tracked = 0;
  std::set<PointId> lost_under_occluder;  // tracked before the occluder, not once its mask is in the reference
  std::set<PointId> found_again;          // re-associated after it has gone
  double worst_found_error_px = 0.0;      // of those, distance to the true projection
};

// Frames 0..29 of sim-1 (deforming) at 320×240; the left half of the image is masked over
// frames 4..13, which spans a reference refresh.
OccluderRun RunWithOccluder(bool reassociation, int consensus_k = 0) {
  SimOptions sim = SimPreset("sim-1");
  sim.camera.width = 320;
  sim.camera.height = 240;
  Renderer renderer(sim);
  TrackingOptions options;
  options.reassociation = reassociation;
  options.reassociation_consensus_k = consensus_k;
  Tracker tracker(renderer.camera(), FrontendOptions{}, DeformationModelOptions{}, options);
  OccluderRun run;
  RenderedFrame frame = renderer.Render(0);
  const FrameResult first = tracker.InitialiseFromDepth(0, frame.left.bgr, frame.left.depth_mm, {});
  if (first.state != TrackingState::kTracking) return run;
  // Ground truth of each map point: the surface point under its pixel at frame 0.
  std::map<PointId, SurfaceHit> surface;
  for (const TrackedPoint& point : first.points) {
    const Eigen::Vector3d bearing = renderer.camera().Unproject(Eigen::Vector2d(point.pixel.x, point.pixel.y));
    surface[point.id] =
        renderer.caster().Cast(frame.world_from_camera.translation, frame.world_from_camera.rotation * bearing);
  }

  cv::Mat occluded(sim.camera.height, sim.camera.width, CV_8UC1, cv::Scalar(255));
  occluded.colRange(0, sim.camera.width / 2).setTo(0);
  std::set<PointId> before, during;
  for (int index = 1; index < 30; ++index) {
    frame = renderer.Render(index);
    const bool occluder = index >= 4 && index < 14;
    const FrameResult result = tracker.Track(index, frame.left.bgr, occluder ? occluded : cv::Mat());
    run.frames_tracked += result.state == TrackingState::kTracking;
    const Rigid3 camera_from_world = frame.world_from_camera.Inverse();
    for (const TrackedPoint& point : result.points) {
      if (index < 4) before.insert(point.id);
      if (index > 6 && occluder) during.insert(point.id);  // after the reference refresh at frame 6
      if (occluder || !point.reassociated) continue;
      run.found_again.insert(point.id);
      const SurfaceHit& hit = surface.at(point.id);
      const Eigen::Vector3d world =
          renderer.scene().Position(hit.patch, hit.material.x(), hit.material.y(), renderer.TimeOf(index));
      const auto truth = renderer.camera().Project(camera_from_world * world);
      const double error = truth ? (*truth - Eigen::Vector2d(point.pixel.x, point.pixel.y)).norm() : 1e9;
      run.worst_found_error_px = std::max(run.worst_found_error_px, error);
    }
  }
  for (PointId id : before) {
    if (!during.count(id)) run.lost_under_occluder.insert(id);
  }
  return run;
}

TEST(Reassociation, PointsLostBehindAnOccluderAreFoundAgainWhereTheyAre) {
  const OccluderRun run = RunWithOccluder(true);
  EXPECT_EQ(run.frames_tracked, 29);
  RecordProperty("lost_under_occluder", static_cast<int>(run.lost_under_occluder.size()));
  RecordProperty("found_again", static_cast<int>(run.found_again.size()));
  ASSERT_GE(run.lost_under_occluder.size(), 30u) << "the occluder should hide a good part of the map";
  size_t recovered = 0;
  for (PointId id : run.lost_under_occluder) recovered += run.found_again.count(id);
  // Measured: 38 of 116 (33 %). The rest drifted more than the 2.45 px gate from their
  // propagated projection while half the map was hidden; a dead re-association finds none.
  EXPECT_GE(recovered, run.lost_under_occluder.size() / 4)
      << recovered << " of " << run.lost_under_occluder.size() << " occluded points found again";
  EXPECT_LT(run.worst_found_error_px, 3.0);
}

// Points found beyond the gate, taken where their neighbours moved the same way: more of the
// hidden points come back, and each one where the surface point truly is.
TEST(Reassociation, TheConsensusOfNeighboursFindsMoreOfThemWhereTheyAre) {
  const auto recovered = [](const OccluderRun& run) {
    size_t count = 0;
    for (PointId id : run.lost_under_occluder) count += run.found_again.count(id);
    return count;
  };
  const OccluderRun by_gate = RunWithOccluder(true);
  const OccluderRun run = RunWithOccluder(true, 4);
  EXPECT_EQ(run.frames_tracked, 29);
  ASSERT_GE(run.lost_under_occluder.size(), 30u);
  // Measured: 58 of 116 against 38 by the gate alone, the worst 1.4 px from the truth.
  EXPECT_GE(4 * recovered(run), 5 * recovered(by_gate))
      << recovered(run) << " against " << recovered(by_gate) << " of " << run.lost_under_occluder.size();
  EXPECT_LT(run.worst_found_error_px, 3.0);
}

TEST(Reassociation, OffMeansOccludedPointsStayLost) {
  const OccluderRun run = RunWithOccluder(false);
  EXPECT_EQ(run.frames_tracked, 29);
  EXPECT_GE(run.lost_under_occluder.size(), 30u);
  EXPECT_TRUE(run.found_again.empty());
}

}  // namespace
}  // namespace nrslam
