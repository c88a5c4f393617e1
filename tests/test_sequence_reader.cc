// The reader must reject each kind of broken sequence with a message that names the problem.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>

#include "error_message.h"
#include "temp_folder.h"
#include "nrslam/io/depth_encoding.h"
#include "nrslam/io/sequence_reader.h"
#include "nrslam/io/sequence_writer.h"
#include "nrslam/util/error.h"

namespace nrslam {
namespace {
namespace fs = std::filesystem;

constexpr int kFrames = 40;

class SequenceReaderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = UniqueTempFolder("nrslam_reader_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(folder_);
    info_.camera = Camera::Pinhole(40, 30, 30, 30, 19.5, 14.5);
    info_.frame_count = kFrames;
    SequenceWriter writer(folder_, info_, true);
    std::vector<StampedPose> poses;
    for (int i = 0; i < kFrames; ++i) {
      writer.WriteRgb(i, cv::Mat(30, 40, CV_8UC3, cv::Scalar(i, 2 * i, 3 * i)));
      writer.WriteDepthMm(i, cv::Mat(30, 40, CV_32F, cv::Scalar(50.0 + i)));
      poses.push_back({i / info_.fps, Rigid3()});
    }
    writer.WriteGroundtruth(poses);
  }
  void TearDown() override { fs::remove_all(folder_); }

  std::string ErrorOf() {
    return ErrorMessage([&] { SequenceReader reader(folder_); });
  }
  void RewriteJson(const std::function<void(nlohmann::json&)>& edit) {
    nlohmann::json json = info_;
    edit(json);
    std::ofstream(folder_ / "sequence.json") << json.dump();
  }

  fs::path folder_;
  SequenceInfo info_;
};

#define EXPECT_ERROR_MENTIONS(text) EXPECT_NE(ErrorOf().find(text), std::string::npos) << "got: " << ErrorOf()

TEST_F(SequenceReaderTest, ValidSequenceReadsBack) {
  SequenceReader reader(folder_);
  EXPECT_EQ(reader.frame_count(), kFrames);
  EXPECT_TRUE(reader.has_depth());
  EXPECT_TRUE(reader.has_groundtruth());
  EXPECT_EQ(reader.ReadRgb(7).at<cv::Vec3b>(3, 3), cv::Vec3b(7, 14, 21));
  EXPECT_NEAR(reader.ReadDepthMm(7).at<float>(3, 3), 57.0f, 1e-3);
  EXPECT_THROW(reader.ReadRgb(kFrames), Error);
}

// A new sequence is never written over an old one, whose frames past the new one's end (or
// whose depth, when the new one has none) would be read as its own; adding to one is allowed.
TEST_F(SequenceReaderTest, ANewSequenceIsNotWrittenOverAnOldOne) {
  SequenceInfo shorter = info_;
  shorter.frame_count = 5;
  try {
    SequenceWriter(folder_, shorter, false);
    ADD_FAILURE() << "written over the old sequence";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("already holds a sequence"), std::string::npos) << e.what();
  }
  EXPECT_EQ(SequenceReader(folder_).frame_count(), kFrames);  // untouched
  const SequenceWriter more(folder_, info_, true, SequenceWriter::Target::kExistingSequence);
  more.WriteDepthMm(0, cv::Mat(30, 40, CV_32F, cv::Scalar(70.0)));
  EXPECT_FLOAT_EQ(SequenceReader(folder_).ReadDepthMm(0).at<float>(0, 0), 70.0f);
  // Removed, it leaves only what is not the sequence's; then a new one goes in.
  std::ofstream(folder_ / "notes.txt") << "mine";
  std::ofstream(folder_ / "mask.png") << "not a mask";
  fs::create_directories(folder_ / "masks");  // per-frame masks, which the reader would read
  std::ofstream(folder_ / "masks" / FrameFileName(0)) << "old";
  RewriteJson([](nlohmann::json& json) { json["mask"] = "mask.png"; });
  RemoveSequence(folder_);
  std::vector<std::string> left;
  for (const auto& entry : fs::directory_iterator(folder_)) left.push_back(entry.path().filename().string());
  EXPECT_EQ(left, std::vector<std::string>{"notes.txt"});
  SequenceWriter(folder_, shorter, false).WriteRgb(0, cv::Mat(30, 40, CV_8UC3, cv::Scalar(1, 2, 3)));
  RemoveSequence(folder_);
  RemoveSequence(folder_);  // no sequence: nothing to do
  EXPECT_TRUE(fs::exists(folder_ / "notes.txt"));
  ASSERT_EQ(std::distance(fs::directory_iterator(folder_), fs::directory_iterator()), 1);
}

TEST_F(SequenceReaderTest, MissingFrameIsNamed) {
  fs::remove(folder_ / "rgb" / "000037.png");
  EXPECT_ERROR_MENTIONS("missing frame 37 in rgb/");
}

TEST_F(SequenceReaderTest, MissingRunOfFramesIsOneLine) {
  for (int i = 10; i < 20; ++i) fs::remove(folder_ / "depth" / FrameFileName(i));
  EXPECT_ERROR_MENTIONS("missing frames 10-19 in depth/");
}

TEST_F(SequenceReaderTest, DepthSizeMismatch) {
  cv::imwrite((folder_ / "depth" / "000012.png").string(), cv::Mat(15, 20, CV_16UC1, cv::Scalar(100)));
  EXPECT_ERROR_MENTIONS("depth/000012.png is 20x15 but the camera is 40x30 (size mismatch)");
}

TEST_F(SequenceReaderTest, DepthMustBe16Bit) {
  cv::imwrite((folder_ / "depth" / "000003.png").string(), cv::Mat(30, 40, CV_8UC1, cv::Scalar(100)));
  EXPECT_ERROR_MENTIONS("depth/000003.png must be 16-bit single-channel");
}

TEST_F(SequenceReaderTest, CorruptImage) {
  std::ofstream(folder_ / "rgb" / "000005.png") << "not a png at all";
  EXPECT_ERROR_MENTIONS("rgb/000005.png is not a readable PNG");
}

TEST_F(SequenceReaderTest, UnknownCameraModel) {
  RewriteJson([](nlohmann::json& j) { j["camera"]["model"] = "orthographic"; });
  EXPECT_ERROR_MENTIONS("unknown camera model 'orthographic'");
}

TEST_F(SequenceReaderTest, NegativeFocalLength) {
  RewriteJson([](nlohmann::json& j) { j["camera"]["fx"] = -30.0; });
  EXPECT_ERROR_MENTIONS("negative or zero focal length");
}

TEST_F(SequenceReaderTest, EmptySequence) {
  RewriteJson([](nlohmann::json& j) { j["frame_count"] = 0; });
  EXPECT_ERROR_MENTIONS("the sequence is empty");
}

TEST_F(SequenceReaderTest, MalformedJson) {
  std::ofstream(folder_ / "sequence.json") << "{\"camera\": ";
  EXPECT_ERROR_MENTIONS("sequence.json is not valid JSON");
}

TEST_F(SequenceReaderTest, MissingField) {
  RewriteJson([](nlohmann::json& j) { j.erase("fps"); });
  EXPECT_ERROR_MENTIONS("missing field 'fps'");
}

TEST_F(SequenceReaderTest, FieldsOfAnotherKindAreNamedNotTruncated) {
  RewriteJson([](nlohmann::json& j) { j["frame_count"] = 39.5; });
  EXPECT_ERROR_MENTIONS("sequence.json: frame_count must be a whole number, got 39.5");
  RewriteJson([](nlohmann::json& j) { j["camera"]["width"] = 40.5; });
  EXPECT_ERROR_MENTIONS("camera: width must be a whole number, got 40.5");
  RewriteJson([](nlohmann::json& j) { j["fps"] = "30"; });
  EXPECT_ERROR_MENTIONS("sequence.json: fps must be a number, got \"30\"");
  RewriteJson([](nlohmann::json& j) { j["stereo"] = {{"baseline_mm", "5"}}; });
  EXPECT_ERROR_MENTIONS("sequence.json: stereo: baseline_mm must be a number, got \"5\"");
}

TEST_F(SequenceReaderTest, AMisspeltKeyIsRefusedNotLeftToItsDefault) {
  // Before, "depth_unit" was passed over and depth read in the default 0.01 mm units.
  RewriteJson([](nlohmann::json& j) {
    j["depth_unit"] = j["depth_unit_mm"];
    j.erase("depth_unit_mm");
  });
  EXPECT_ERROR_MENTIONS("sequence.json: unknown key 'depth_unit'; did you mean depth_unit_mm?");
  RewriteJson([](nlohmann::json& j) { j["stereo"] = {{"baseline", 5.0}}; });
  EXPECT_ERROR_MENTIONS("sequence.json: stereo: unknown key 'baseline'; did you mean baseline_mm?");
  RewriteJson([](nlohmann::json& j) { j["camera"]["distortion"] = {-0.3, 0.1, 0, 0}; });
  EXPECT_ERROR_MENTIONS("camera: model pinhole takes no 'distortion'; model opencv does");
}

TEST_F(SequenceReaderTest, AnotherFormatOrALaterVersionIsRefused) {
  RewriteJson([](nlohmann::json& j) { j["format"] = "tum-rgbd"; });
  EXPECT_ERROR_MENTIONS("sequence.json: format is 'tum-rgbd', not 'nrslam-sequence'");
  RewriteJson([](nlohmann::json& j) { j["version"] = 2; });
  EXPECT_ERROR_MENTIONS("sequence.json: version 2 is newer than this nrslam reads (1)");
  RewriteJson([](nlohmann::json& j) {
    j.erase("format");
    j.erase("version");
  });
  EXPECT_TRUE(SequenceReader(folder_).has_groundtruth());  // a hand-written file may leave both out
}

TEST_F(SequenceReaderTest, MissingFolderAndJson) {
  fs::remove(folder_ / "sequence.json");
  EXPECT_ERROR_MENTIONS("missing sequence.json");
  EXPECT_THROW(SequenceReader(folder_ / "nowhere"), Error);
}

TEST_F(SequenceReaderTest, GroundtruthLineCount) {
  std::ofstream(folder_ / "groundtruth.tum") << "0 0 0 0 0 0 0 1\n";
  EXPECT_ERROR_MENTIONS("groundtruth.tum has 1 poses, expected 40");
}

// Poses are matched to frames by their order and trajectories are written at t = index / fps,
// so poses out of order or on another clock would be scored against the wrong frames.
TEST_F(SequenceReaderTest, GroundtruthOffTheFrameClockIsNamed) {
  const auto write_times = [&](const std::function<double(int)>& time_of_frame) {
    std::vector<StampedPose> poses;
    for (int i = 0; i < kFrames; ++i) poses.push_back({time_of_frame(i), Rigid3()});
    WriteTum(folder_ / "groundtruth.tum", poses);
  };
  const double period = 1.0 / info_.fps;
  write_times([&](int i) { return (i == 5 ? 6 : i == 6 ? 5 : i) * period; });
  EXPECT_ERROR_MENTIONS("groundtruth.tum: pose 6 has t = 0.2 s, but frame 5 is at 5 / 30 fps = 0.166667 s");
  write_times([&](int i) { return 1305031102.175 + i * period; });
  EXPECT_ERROR_MENTIONS("groundtruth.tum: pose 1 has t = 1.30503e+09 s, but frame 0 is at 0 / 30 fps = 0 s");
  write_times([&](int i) { return (i + (i % 2 ? 0.4 : -0.4)) * period; });
  EXPECT_TRUE(SequenceReader(folder_).has_groundtruth());
}

// A folder where a file should be opens as a stream on Linux: named as a folder, not read as an
// empty file (no poses) or failed with the C library's "Is a directory" and no file name.
TEST_F(SequenceReaderTest, AFolderInPlaceOfAFileIsNamed) {
  fs::remove(folder_ / "groundtruth.tum");
  fs::create_directory(folder_ / "groundtruth.tum");
  EXPECT_ERROR_MENTIONS((folder_ / "groundtruth.tum").string() + " is a folder, not a TUM trajectory file");
  fs::remove(folder_ / "sequence.json");
  fs::create_directory(folder_ / "sequence.json");
  EXPECT_ERROR_MENTIONS((folder_ / "sequence.json").string() + " is a folder, not a JSON file");
}

TEST_F(SequenceReaderTest, GroundtruthNaN) {
  std::ofstream(folder_ / "groundtruth.tum") << "0 nan 0 0 0 0 0 1\n";
  EXPECT_ERROR_MENTIONS("groundtruth.tum:1: non-finite value");
}

TEST_F(SequenceReaderTest, GroundtruthWordsOrTooFewNumbers) {
  std::ofstream(folder_ / "groundtruth.tum") << "0 1.5mm 0 0 0 0 0 1\n";
  EXPECT_ERROR_MENTIONS("groundtruth.tum:1: expected 8 numbers");
  std::ofstream(folder_ / "groundtruth.tum") << "0 0 0 0 0 0 1\n";
  EXPECT_ERROR_MENTIONS("groundtruth.tum:1: expected 8 numbers");
}

TEST_F(SequenceReaderTest, StereoWithoutRightImages) {
  RewriteJson([](nlohmann::json& j) { j["stereo"] = {{"baseline_mm", 5.0}}; });
  EXPECT_ERROR_MENTIONS("declares stereo but right/ is missing");
}

TEST_F(SequenceReaderTest, MaskNamedButMissing) {
  RewriteJson([](nlohmann::json& j) { j["mask"] = "mask.png"; });
  EXPECT_ERROR_MENTIONS("mask mask.png named by sequence.json is missing");
}

TEST_F(SequenceReaderTest, MaskWithNoUsablePixel) {
  cv::imwrite((folder_ / "mask.png").string(), cv::Mat(30, 40, CV_8UC1, cv::Scalar(0)));
  RewriteJson([](nlohmann::json& j) { j["mask"] = "mask.png"; });
  EXPECT_ERROR_MENTIONS("mask mask.png marks no pixel usable (all zero; non-zero = usable)");
}

TEST_F(SequenceReaderTest, ReportsEveryProblemAtOnce) {
  fs::remove(folder_ / "rgb" / "000037.png");
  cv::imwrite((folder_ / "depth" / "000012.png").string(), cv::Mat(15, 20, CV_16UC1, cv::Scalar(100)));
  const std::string error = ErrorOf();
  EXPECT_NE(error.find("missing frame 37"), std::string::npos);
  EXPECT_NE(error.find("000012.png"), std::string::npos);
}

TEST_F(SequenceReaderTest, FixedAndPerFrameMasksCombine) {
  cv::Mat fixed(30, 40, CV_8UC1, cv::Scalar(255));
  fixed.colRange(0, 5) = 0;
  cv::imwrite((folder_ / "mask.png").string(), fixed);
  fs::create_directories(folder_ / "masks");
  for (int i = 0; i < kFrames; ++i) {
    cv::Mat frame_mask(30, 40, CV_8UC1, cv::Scalar(255));
    frame_mask.rowRange(0, 2) = 0;
    cv::imwrite((folder_ / "masks" / FrameFileName(i)).string(), frame_mask);
  }
  RewriteJson([](nlohmann::json& j) { j["mask"] = "mask.png"; });
  SequenceReader reader(folder_);
  const cv::Mat mask = reader.ReadMask(3);
  EXPECT_EQ(mask.at<uint8_t>(10, 2), 0);   // fixed mask
  EXPECT_EQ(mask.at<uint8_t>(1, 20), 0);   // frame mask
  EXPECT_EQ(mask.at<uint8_t>(10, 20), 255);
}

// Depth is stored to the nearest unit; what cannot be stored (none, NaN, negative, beyond 16
// bits) reads back as 0 = none, never as a clipped depth. A file written and read back holds
// exactly the in-memory round trip, which is what benchmarks use to track the runner's map.
TEST(DepthEncoding, RoundsToTheUnitAndKeepsNoneAsZero) {
  const float depths[] = {12.344f, 12.346f, 0.0f, std::numeric_limits<float>::quiet_NaN(), -3.0f, 655.35f, 700.0f};
  cv::Mat depth_mm(1, 7, CV_32F);
  for (int i = 0; i < 7; ++i) depth_mm.at<float>(0, i) = depths[i];
  const cv::Mat encoded = EncodeDepthMm(depth_mm, 0.01);
  ASSERT_EQ(encoded.type(), CV_16UC1);
  const uint16_t expected[] = {1234, 1235, 0, 0, 0, 65535, 0};
  for (int i = 0; i < 7; ++i) EXPECT_EQ(encoded.at<uint16_t>(0, i), expected[i]) << "column " << i;
  const cv::Mat decoded = DecodeDepthMm(encoded, 0.01);
  ASSERT_EQ(decoded.type(), CV_32F);
  EXPECT_NEAR(decoded.at<float>(0, 0), 12.34f, 1e-5);
  EXPECT_EQ(decoded.at<float>(0, 2), 0.0f);
  EXPECT_NEAR(decoded.at<float>(0, 5), 655.35f, 1e-3);
}

// Other programs' and datasets' file names give their frame by the last number in the stem.
TEST(FrameNumberOf, TheLastRunOfDigitsWithOrWithoutLeadingZeros) {
  EXPECT_EQ(FrameNumberOf("depth_000123"), 123);
  EXPECT_EQ(FrameNumberOf("0123_depth"), 123);
  EXPECT_EQ(FrameNumberOf("12_color"), 12);
  EXPECT_EQ(FrameNumberOf("cam2_frame0045"), 45);
  EXPECT_EQ(FrameNumberOf("0"), 0);
  EXPECT_EQ(FrameNumberOf("0000000000"), 0);
  EXPECT_EQ(FrameNumberOf("0000000123"), 123);  // Hamlyn's ten digits
  EXPECT_EQ(FrameNumberOf("depth"), std::nullopt);
  EXPECT_EQ(FrameNumberOf("1234567890"), std::nullopt);  // past what a frame number can be
}

TEST_F(SequenceReaderTest, WrittenDepthReadsBackAsTheInMemoryRoundTrip) {
  cv::Mat depth_mm(30, 40, CV_32F);
  cv::randu(depth_mm, 1.0, 400.0);
  SequenceWriter(folder_, info_, true, SequenceWriter::Target::kExistingSequence).WriteDepthMm(5, depth_mm);
  const cv::Mat read = SequenceReader(folder_).ReadDepthMm(5);
  const cv::Mat in_memory = DecodeDepthMm(EncodeDepthMm(depth_mm, info_.depth_unit_mm), info_.depth_unit_mm);
  EXPECT_EQ(cv::norm(read, in_memory, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(read, depth_mm, cv::NORM_INF), 0.0);  // the rounding is real
  EXPECT_LE(cv::norm(read, depth_mm, cv::NORM_INF), 0.5 * info_.depth_unit_mm + 1e-4);
}

}  // namespace
}  // namespace nrslam
