// The KLT look-ahead (tracking.klt_lookahead): a frame's KLT run during the previous frame's
// solve must leave every result as it is without it, to the last bit, also when tracks are
// re-associated or dropped in between, when the reference is refreshed, and when the image
// handed ahead is not the one that comes.
#include <gtest/gtest.h>

#include <vector>

#include "nrslam/sim/renderer.h"
#include "nrslam/tracking/tracker.h"

namespace nrslam {
namespace {

enum class Ahead { kOff, kNextFrame, kWrongImage };

struct TrackedRun {
  std::vector<FrameResult> frames;
  std::vector<Eigen::Vector3d> map;  // every map point's position at the end
  int frames_served_ahead = 0;       // frames whose KLT (some of it) ran ahead
};

// sim-1 (deforming) at 320×240 over 40 frames (six reference refreshes); the left half of the
// image is masked over frames 4..13, so that points are lost there and found again later.
TrackedRun RunTracker(const std::vector<RenderedFrame>& rendered, const Camera& camera, Ahead ahead) {
  TrackingOptions options;
  options.klt_lookahead = ahead != Ahead::kOff;
  Tracker tracker(camera, FrontendOptions{}, DeformationModelOptions{}, options);
  TrackedRun run;
  run.frames.push_back(tracker.InitialiseFromDepth(0, rendered[0].left.bgr, rendered[0].left.depth_mm, {}));
  const cv::Mat& any_image = rendered[0].left.bgr;
  cv::Mat occluded(any_image.rows, any_image.cols, CV_8UC1, cv::Scalar(255));
  occluded.colRange(0, any_image.cols / 2).setTo(0);
  for (size_t index = 1; index < rendered.size(); ++index) {
    cv::Mat next;
    if (ahead != Ahead::kOff && index + 1 < rendered.size()) {
      next = rendered[index + 1].left.bgr.clone();
      // One grey level off at one pixel (the KLT sees grey): nothing computed from it may be
      // used for the frame that comes.
      if (ahead == Ahead::kWrongImage) {
        cv::Vec3b& pixel = next.at<cv::Vec3b>(next.rows / 2, next.cols / 2);
        const int step = pixel[0] < 255 && pixel[1] < 255 && pixel[2] < 255 ? 1 : -1;
        for (int channel = 0; channel < 3; ++channel) pixel[channel] = cv::saturate_cast<uchar>(pixel[channel] + step);
      }
    }
    const bool occluder = index >= 4 && index < 14;
    run.frames.push_back(tracker.Track(static_cast<int>(index), rendered[index].left.bgr,
                                       occluder ? occluded : cv::Mat(), next));
    run.frames_served_ahead += run.frames.back().ms_klt_ahead > 0;
  }
  for (const MapPoint& point : tracker.map().points()) run.map.push_back(point.position);
  return run;
}

void ExpectSameRun(const TrackedRun& run, const TrackedRun& reference) {
  ASSERT_EQ(run.frames.size(), reference.frames.size());
  for (size_t f = 0; f < run.frames.size(); ++f) {
    const FrameResult& a = run.frames[f];
    const FrameResult& b = reference.frames[f];
    ASSERT_EQ(a.state, b.state) << "frame " << f;
    EXPECT_EQ(a.klt_tracked, b.klt_tracked) << "frame " << f;
    EXPECT_EQ(a.reassociated, b.reassociated) << "frame " << f;
    EXPECT_EQ(a.keyframe, b.keyframe) << "frame " << f;
    EXPECT_EQ(a.cam_from_world.ToParams(), b.cam_from_world.ToParams()) << "frame " << f;
    ASSERT_EQ(a.points.size(), b.points.size()) << "frame " << f;
    for (size_t i = 0; i < a.points.size(); ++i) {
      EXPECT_EQ(a.points[i].id, b.points[i].id) << "frame " << f;
      EXPECT_EQ(a.points[i].pixel, b.points[i].pixel) << "frame " << f;
    }
  }
  ASSERT_EQ(run.map.size(), reference.map.size());
  for (size_t i = 0; i < run.map.size(); ++i) EXPECT_EQ(run.map[i], reference.map[i]) << "point " << i;
}

class KltLookahead : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    SimOptions sim = SimPreset("sim-1");
    sim.camera.width = 320;
    sim.camera.height = 240;
    renderer_ = new Renderer(sim);
    for (int i = 0; i < 40; ++i) rendered_.push_back(renderer_->Render(i));
    reference_ = new TrackedRun(RunTracker(rendered_, renderer_->camera(), Ahead::kOff));
  }
  static void TearDownTestSuite() {
    delete reference_;
    delete renderer_;
    rendered_.clear();
  }
  static Renderer* renderer_;
  static std::vector<RenderedFrame> rendered_;
  static TrackedRun* reference_;
};
Renderer* KltLookahead::renderer_ = nullptr;
std::vector<RenderedFrame> KltLookahead::rendered_;
TrackedRun* KltLookahead::reference_ = nullptr;

TEST_F(KltLookahead, ChangesNoResult) {
  // The run this is compared with must exercise what the look-ahead has to survive.
  int tracked = 0, reassociated = 0, keyframes = 0;
  for (const FrameResult& frame : reference_->frames) {
    tracked += frame.state == TrackingState::kTracking;
    reassociated += frame.reassociated;
    keyframes += frame.keyframe;
  }
  EXPECT_EQ(tracked, 40);
  EXPECT_GT(reassociated, 0);
  EXPECT_GE(keyframes, 6);
  EXPECT_EQ(reference_->frames_served_ahead, 0);

  const TrackedRun run = RunTracker(rendered_, renderer_->camera(), Ahead::kNextFrame);
  ExpectSameRun(run, *reference_);
  // It did run ahead: on every frame after the first tracked one (after a refresh, for its
  // pyramid only).
  EXPECT_EQ(run.frames_served_ahead, 38);
}

TEST_F(KltLookahead, AnImageThatIsNotTheNextOneIsNotUsed) {
  const TrackedRun run = RunTracker(rendered_, renderer_->camera(), Ahead::kWrongImage);
  ExpectSameRun(run, *reference_);
  EXPECT_EQ(run.frames_served_ahead, 0);
}

}  // namespace
}  // namespace nrslam
