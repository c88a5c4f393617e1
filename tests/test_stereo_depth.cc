// Stereo ground truth: depth from a rendered rectified pair against the renderer's exact depth.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "nrslam/datasets/stereo_depth.h"
#include "nrslam/io/sequence_reader.h"
#include "nrslam/sim/renderer.h"
#include "nrslam/util/error.h"
#include "nrslam/util/json_options.h"
#include "nrslam/util/text_file.h"
#include "temp_folder.h"

namespace nrslam {
namespace {

TEST(StereoDepth, MatchesTheRenderersExactDepth) {
  SimOptions sim = SimPreset("sim-3");
  sim.camera.stereo = true;
  Renderer renderer(sim);
  std::vector<double> errors;
  size_t with_truth = 0;
  for (int index : {0, 40, 80}) {
    const RenderedFrame frame = renderer.Render(index);
    const cv::Mat depth = StereoDepthMm(frame.left.bgr, frame.right->bgr, renderer.camera().fx(),
                                        sim.camera.baseline_mm, StereoDepthOptions{});
    for (int y = 0; y < depth.rows; ++y) {
      for (int x = 0; x < depth.cols; ++x) {
        const float truth = frame.left.depth_mm.at<float>(y, x);
        if (!(truth > 0)) continue;
        ++with_truth;
        if (depth.at<float>(y, x) > 0) errors.push_back(std::abs(depth.at<float>(y, x) - truth));
      }
    }
  }
  ASSERT_GT(with_truth, 0u);
  const double coverage = static_cast<double>(errors.size()) / with_truth;
  std::sort(errors.begin(), errors.end());
  const double median = errors[errors.size() / 2], p90 = errors[errors.size() * 9 / 10];
  RecordProperty("coverage_percent", std::to_string(100 * coverage));
  RecordProperty("median_abs_error_mm", std::to_string(median));
  RecordProperty("p90_abs_error_mm", std::to_string(p90));
  std::printf("stereo depth: coverage %.1f %%, median |error| %.3f mm, 90th percentile %.3f mm\n", 100 * coverage,
              median, p90);
  // Measured: 84.8 % of the pixels with a surface get a depth, median error 0.26 mm, 90th
  // percentile 0.92 mm (sim-3, 640×480, 5 mm baseline, depths 12–230 mm).
  EXPECT_GT(coverage, 0.75);
  EXPECT_LT(median, 0.4);
  EXPECT_LT(p90, 1.5);
}

// The tool on a rendered stereo sequence without its exact depth: it writes a stereo depth
// that stays close to the exact one; it refuses a sequence without a right camera or one with depth.
TEST(StereoDepth, ToolWritesTheSequencesDepth) {
  const auto folder = UniqueTempFolder("stereo_tool");
  const std::string tools = NRSLAM_TOOLS_DIR;
  ASSERT_EQ(std::system((tools + "/nrslam_simulate --preset sim-2 --stereo --frames 3 --width 320 --height 240 --quiet --out " +
                         (folder / "seq").string() + " > /dev/null").c_str()),
            0);
  std::vector<cv::Mat> truth;
  {
    const SequenceReader exact(folder / "seq");
    for (int i = 0; i < 3; ++i) truth.push_back(exact.ReadDepthMm(i));
  }
  std::filesystem::remove_all(folder / "seq" / "depth");
  const std::string tool = tools + "/nrslam_stereo_gt --quiet " + (folder / "seq").string() + " > /dev/null 2>&1";
  ASSERT_EQ(std::system(tool.c_str()), 0);
  EXPECT_NE(std::system(tool.c_str()), 0);  // depth/ exists now: not without --overwrite
  const SequenceReader sequence(folder / "seq");
  ASSERT_TRUE(sequence.has_depth());
  std::vector<double> errors;
  for (int i = 0; i < 3; ++i) {
    const cv::Mat stereo = sequence.ReadDepthMm(i);
    for (int y = 0; y < stereo.rows; ++y) {
      for (int x = 0; x < stereo.cols; ++x) {
        const float exact = truth[i].at<float>(y, x), estimate = stereo.at<float>(y, x);
        if (exact > 0 && estimate > 0) errors.push_back(std::abs(exact - estimate));
      }
    }
  }
  ASSERT_GT(errors.size(), 3u * 320 * 240 / 2);
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  EXPECT_LT(errors[errors.size() / 2], 0.6);  // half the resolution of the test above: coarser
  // A damaged image costs its frame's depth only: that frame gets none (0), the others theirs,
  // sequence.json names it, and the replaced depth leaves nothing half-done behind.
  std::filesystem::resize_file(folder / "seq" / "right" / "000001.png", 200);  // header intact, data cut
  ASSERT_EQ(std::system((tools + "/nrslam_stereo_gt --quiet --overwrite " + (folder / "seq").string() +
                         " > /dev/null 2>&1").c_str()),
            0);
  const SequenceReader redone(folder / "seq");
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(cv::countNonZero(redone.ReadDepthMm(i)) == 0, i == 1) << i;
  }
  EXPECT_EQ(ReadJsonFile(folder / "seq" / "sequence.json")["provenance"]["depth"]["frames_without_input"],
            nlohmann::json::array({1}));
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(folder / "seq"), {}), 5);  // no staging folder left
  // A distorted lens is refused, not matched as if rectified: its disparities are not depth.
  {
    nlohmann::json description = ReadJsonFile(folder / "seq" / "sequence.json");
    for (nlohmann::json* camera : {&description["camera"], &description["stereo"]["right_camera"]}) {
      (*camera)["model"] = "opencv";
      (*camera)["distortion"] = {-0.02, 0.0, 0.0, 0.0, 0.0};
    }
    std::ofstream(folder / "seq" / "sequence.json") << description.dump(2);
  }
  EXPECT_NE(std::system((tools + "/nrslam_stereo_gt --quiet --overwrite " + (folder / "seq").string() + " > " +
                         (folder / "distorted.log").string() + " 2>&1").c_str()),
            0);
  const std::string log = FileText(folder / "distorted.log");
  EXPECT_NE(log.find("needs a rectified pair with a pinhole camera"), std::string::npos) << log;
  EXPECT_NE(log.find("nrslam_import --format stereo"), std::string::npos) << log;  // the way out
  // A mono sequence is refused with a message, not a crash.
  ASSERT_EQ(std::system((tools + "/nrslam_simulate --preset sim-0 --frames 2 --width 160 --height 120 --quiet --out " +
                         (folder / "mono").string() + " > /dev/null").c_str()),
            0);
  EXPECT_NE(std::system((tools + "/nrslam_stereo_gt --quiet " + (folder / "mono").string() + " > /dev/null 2>&1").c_str()), 0);
  std::filesystem::remove_all(folder);
}

TEST(StereoDepth, RejectsBadInput) {
  const cv::Mat image(48, 64, CV_8UC1, cv::Scalar(0));
  EXPECT_THROW(StereoDepthMm(image, cv::Mat(), 50, 5, {}), Error);
  EXPECT_THROW(StereoDepthMm(image, image, 50, 0, {}), Error);
  StereoDepthOptions even;
  even.block_size = 4;
  EXPECT_THROW(StereoDepthMm(image, image, 50, 5, even), Error);
}

}  // namespace
}  // namespace nrslam
