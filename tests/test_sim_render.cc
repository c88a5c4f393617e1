// Rendered images: identical for identical inputs, trackable like mucosa, lit from the tip.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include <filesystem>
#include <fstream>

#include "camera_fixtures.h"
#include "temp_folder.h"
#include "nrslam/io/sequence_reader.h"
#include "nrslam/sim/renderer.h"
#include "nrslam/sim/simulate.h"
#include "nrslam/util/error.h"
#include "nrslam/util/text_file.h"

namespace nrslam {
namespace {
namespace fs = std::filesystem;

SimOptions Small(const std::string& preset) {
  SimOptions options = SimPreset(preset);
  options.camera.width = 160;
  options.camera.height = 120;
  options.frames = 3;
  return options;
}

TEST(SimRender, SameSeedAndOptionsGiveIdenticalFiles) {
  const fs::path base = UniqueTempFolder("nrslam_determinism");
  fs::remove_all(base);
  SimOptions options = Small("sim-4");
  options.camera.stereo = true;
  options.seed = 7;
  SimulateSequence(options, "a", base / "a");
  options.threads = 1;  // thread count must not matter either
  SimulateSequence(options, "a", base / "b");
  int files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(base / "a")) {
    if (!entry.is_regular_file()) continue;
    const fs::path relative = fs::relative(entry.path(), base / "a");
    if (relative == "sequence.json") continue;  // records the thread count
    EXPECT_EQ(FileText(entry.path()), FileText(base / "b" / relative)) << relative;
    ++files;
  }
  EXPECT_EQ(files, 3 * 3 + 1);  // rgb, depth, right per frame + groundtruth.tum
  options.seed = 8;
  SimulateSequence(options, "a", base / "c");
  EXPECT_NE(FileText(base / "a" / "rgb" / "000001.png"), FileText(base / "c" / "rgb" / "000001.png"));
  fs::remove_all(base);
}

TEST(SimRender, Sim0IsTrackableLikeMucosa) {
  Renderer renderer(SimPreset("sim-0"));  // 640x480
  cv::Mat previous;
  for (int index = 0; index < 4; ++index) {
    cv::Mat grey;
    cv::cvtColor(renderer.Render(index).left.bgr, grey, cv::COLOR_BGR2GRAY);
    if (!previous.empty()) {
      std::vector<cv::Point2f> corners, tracked;
      cv::goodFeaturesToTrack(previous, corners, 0, 0.01, 10);
      EXPECT_GE(corners.size(), 300u) << "frame " << index - 1;
      std::vector<uchar> status;
      std::vector<float> error;
      cv::calcOpticalFlowPyrLK(previous, grey, corners, tracked, status, error);
      const double kept = std::count(status.begin(), status.end(), 1) / static_cast<double>(corners.size());
      EXPECT_GE(kept, 0.8) << "frame " << index - 1 << " -> " << index;
    }
    previous = grey;
  }
}

TEST(SimRender, ImageDarkensWithDepthBecauseTheLightIsOnTheTip) {
  Renderer renderer(Small("sim-2"));
  const double edges[] = {10, 20, 40, 80, 160};
  double sum[4] = {0, 0, 0, 0};
  int count[4] = {0, 0, 0, 0};
  for (int index = 0; index < 3; ++index) {
    const RenderedFrame frame = renderer.Render(index);
    cv::Mat grey;
    cv::cvtColor(frame.left.bgr, grey, cv::COLOR_BGR2GRAY);
    for (int y = 0; y < grey.rows; ++y) {
      for (int x = 0; x < grey.cols; ++x) {
        const float depth = frame.left.depth_mm.at<float>(y, x);
        for (int bin = 0; bin < 4; ++bin) {
          if (depth >= edges[bin] && depth < edges[bin + 1]) {
            sum[bin] += grey.at<uint8_t>(y, x);
            ++count[bin];
          }
        }
      }
    }
  }
  for (int bin = 0; bin + 1 < 4; ++bin) {
    ASSERT_GT(count[bin], 50);
    ASSERT_GT(count[bin + 1], 50);
    EXPECT_GT(sum[bin] / count[bin], sum[bin + 1] / count[bin + 1] + 5) << "depth bin " << bin;
  }
}

TEST(SimRender, FisheyeWritesItsImageCircleMask) {
  const fs::path folder = UniqueTempFolder("nrslam_fisheye");
  SimOptions options = Small("sim-1");
  options.camera.model = "fisheye";
  SimulateSequence(options, "fisheye", folder);
  SequenceReader reader(folder);
  EXPECT_EQ(reader.info().camera.model(), CameraModelId::kKannalaBrandt);
  const cv::Mat mask = reader.ReadMask(0);
  ASSERT_FALSE(mask.empty());
  EXPECT_EQ(mask.at<uint8_t>(60, 80), 255);  // centre
  EXPECT_EQ(mask.at<uint8_t>(0, 0), 0);      // corner, outside the circle
  const cv::Mat depth = reader.ReadDepthMm(0);
  EXPECT_EQ(depth.at<float>(0, 0), 0.f);
  EXPECT_GT(depth.at<float>(60, 80), 0.f);
  fs::remove_all(folder);
}

// The simulator's fisheye rewritten in OCamCalib's terms and given as a calibration file: the
// same rays, so the same depths; its image reaches past the simulator's 85° circle, up to the
// model's widest ray, and rays 90° or more off the axis have no z-depth.
TEST(SimRender, ACalibrationFileIsTheLensRenderedWith) {
  const fs::path folder = UniqueTempFolder("nrslam_calibrated");
  fs::create_directories(folder);
  SimOptions fisheye = Small("sim-1");
  fisheye.camera.model = "fisheye";
  const Camera ocam = OcamFromKannalaBrandt(MakeSimCamera(fisheye.camera));
  std::ofstream(folder / "ocam.json") << nlohmann::json(ocam).dump();
  SimOptions calibrated = Small("sim-1");
  calibrated.camera.calibration = (folder / "ocam.json").string();

  Renderer lens(fisheye), file(calibrated);
  EXPECT_EQ(file.camera().model(), CameraModelId::kOcam);
  const RenderedFrame a = lens.Render(5), b = file.Render(5);
  ASSERT_EQ(a.left.depth_mm.size(), b.left.depth_mm.size());
  int compared = 0, beyond_circle = 0;
  for (int y = 0; y < a.left.depth_mm.rows; ++y) {
    for (int x = 0; x < a.left.depth_mm.cols; ++x) {
      const float inside = a.left.depth_mm.at<float>(y, x), calibrated_depth = b.left.depth_mm.at<float>(y, x);
      if (inside > 0) {
        ASSERT_NEAR(calibrated_depth, inside, 1e-3) << x << ", " << y;
        ++compared;
      } else {
        beyond_circle += calibrated_depth > 0;
      }
      EXPECT_GE(calibrated_depth, 0.f);
    }
  }
  EXPECT_GT(compared, 160 * 120 / 2);
  EXPECT_GT(beyond_circle, 0);
  EXPECT_GT(ocam.max_theta(), M_PI / 2);  // so some rays have no z-depth, and none went negative

  calibrated.camera.calibration = (folder / "none.json").string();
  EXPECT_THROW(Renderer{calibrated}, Error);
  fs::remove_all(folder);
}

TEST(SimRender, LapLobesSeenFrom50To135mm) {
  Renderer renderer(Small("lap-lobes"));
  const RenderedFrame frame = renderer.Render(0);
  double lowest, highest;
  cv::minMaxLoc(frame.left.depth_mm, &lowest, &highest);
  EXPECT_GT(lowest, 50.0);
  EXPECT_LT(highest, 135.0);
  EXPECT_EQ(cv::countNonZero(frame.left.depth_mm > 0), 160 * 120);  // background fills the view
}

}  // namespace
}  // namespace nrslam
