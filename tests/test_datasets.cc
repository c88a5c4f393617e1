// Dataset importers: each public layout, written as a small fixture with known depth and
// poses, imports into a sequence that the reader accepts, with the depth and poses decoded
// as the layout defines them; broken layouts are named.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iterator>

#include "nrslam/datasets/dataset_import.h"
#include "nrslam/io/sequence_reader.h"
#include "nrslam/util/error.h"
#include "nrslam/util/source_revision.h"
#include "camera_fixtures.h"
#include "error_message.h"
#include "temp_folder.h"

namespace nrslam {
namespace {

namespace fs = std::filesystem;
constexpr int kWidth = 64, kHeight = 48, kFrames = 3;

cv::Mat Frame(int index) {
  cv::Mat image(kHeight, kWidth, CV_8UC3);
  cv::randu(image, cv::Scalar::all(0), cv::Scalar::all(255));
  image.row(0).setTo(cv::Scalar(index * 20, 0, 0));  // frames differ, and we can tell which is which
  return image;
}

void WriteCalibration(const fs::path& file) {
  std::ofstream(file) << R"({"model": "pinhole", "width": 64, "height": 48, "fx": 50, "fy": 51, "cx": 31.5, "cy": 23.5})";
}

std::string ImportError(const ImportOptions& options, const fs::path& out) {
  return ErrorMessage([&] { ImportDataset(options, out); });
}

ImportOptions Options(const std::string& format, const fs::path& input) {
  ImportOptions options;
  options.format = format;
  options.input = input;
  return options;
}

Rigid3 Pose(int index) {
  return Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * index, Eigen::Vector3d(0.3, 1, 0.2).normalized())),
                Eigen::Vector3d(1.0 * index, -2.0, 0.5 * index));
}

void ExpectSamePose(const Rigid3& a, const Rigid3& b, double tolerance) {
  EXPECT_LT((a.translation - b.translation).norm(), tolerance);
  EXPECT_LT(a.rotation.angularDistance(b.rotation), 1e-6);
}

TEST(DatasetImport, EndomapperSimulatedReversedZDepthAndInvertedPoses) {
  setenv("OPENCV_IO_ENABLE_OPENEXR", "1", 1);
  const fs::path in = UniqueTempFolder("endomapper_in"), out = UniqueTempFolder("endomapper_out");
  fs::create_directories(in / "rgb");
  fs::create_directories(in / "depth");
  // Reversed Z with near 0.01 and far 4: z = 0.05 scene units (50 mm) ↔ d = (far/z − 1)/(far/near − 1).
  const double near = 0.01, far = 4.0, z = 0.05;
  const float d = static_cast<float>((far / z - 1.0) / (far / near - 1.0));
  std::ofstream trajectory(in / "trajectory.csv");
  trajectory << "tX;tY;tZ;rX;rY;rZ;rW;time\n";
  for (int i = 0; i < kFrames; ++i) {
    char name[64];
    std::snprintf(name, sizeof name, "rgb/image_%04d.png", i);
    cv::imwrite((in / name).string(), Frame(i));
    cv::Mat exr(kHeight, kWidth, CV_32FC3, cv::Scalar(0, 0, d));  // R channel holds the buffer
    exr.at<cv::Vec3f>(0, 0) = cv::Vec3f(0, 0, 0);                  // far plane: no surface
    std::snprintf(name, sizeof name, "depth/aov_image_%04d.exr", i);
    ASSERT_TRUE(cv::imwrite((in / name).string(), exr));
    const Rigid3 camera_from_world = Pose(i).Inverse();  // the file stores T_cw, in metres
    const Eigen::Vector3d t = camera_from_world.translation / 1000.0;
    const Eigen::Quaterniond& q = camera_from_world.rotation;
    trajectory << t.x() << ';' << t.y() << ';' << t.z() << ';' << q.x() << ';' << q.y() << ';' << q.z() << ';' << q.w()
               << ';' << i / 30.0 << '\n';
  }
  trajectory.close();
  ImportOptions options = Options("endomapper-sim", in);
  ImportDataset(options, out);
  const SequenceReader sequence(out);
  EXPECT_EQ(sequence.frame_count(), kFrames);
  EXPECT_DOUBLE_EQ(sequence.info().camera.fx(), 472.6496);
  const cv::Mat depth = sequence.ReadDepthMm(1);
  EXPECT_NEAR(depth.at<float>(10, 10), 50.0, 0.01);
  EXPECT_EQ(depth.at<float>(0, 0), 0.f);
  ASSERT_EQ(sequence.groundtruth().size(), static_cast<size_t>(kFrames));
  for (int i = 0; i < kFrames; ++i) ExpectSamePose(sequence.groundtruth()[i].world_from_camera, Pose(i), 1e-3);
  EXPECT_EQ(sequence.ReadRgb(2).at<cv::Vec3b>(0, 0)[0], 40);

  // Without its header line, the file's first pose is still frame 0's.
  std::string poses;
  {
    std::ifstream with_header(in / "trajectory.csv");
    std::getline(with_header, poses);
    poses.assign(std::istreambuf_iterator<char>(with_header), std::istreambuf_iterator<char>());
  }
  std::ofstream(in / "trajectory.csv") << poses;
  fs::remove_all(out);
  ImportDataset(options, out);
  ASSERT_EQ(SequenceReader(out).groundtruth().size(), static_cast<size_t>(kFrames));
  for (int i = 0; i < kFrames; ++i) ExpectSamePose(SequenceReader(out).groundtruth()[i].world_from_camera, Pose(i), 1e-3);

  // A pose the file cannot mean is named, not normalised into one or written as read.
  std::ofstream(in / "trajectory.csv") << poses << "0;0;0;0;0;0;0;0.1\n";
  EXPECT_NE(ImportError(options, out).find("trajectory.csv line 4: rX;rY;rZ;rW is not a unit quaternion (length 0.0000)"),
            std::string::npos);
  std::ofstream(in / "trajectory.csv") << poses << "0;0;nan;0;0;0;1;0.1\n";
  EXPECT_NE(ImportError(options, out).find("trajectory.csv line 4 holds a value that is not finite (nan or inf)"),
            std::string::npos);
  std::ofstream(in / "trajectory.csv") << poses;

  fs::remove(in / "depth" / "aov_image_0002.exr");
  EXPECT_NE(ImportError(options, out).find("missing " + (in / "depth" / "aov_image_0002.exr").string()), std::string::npos);
  fs::remove_all(in);
  fs::remove_all(out);
}

// A Hamlyn rectified layout: stereo frames, the depth of frame i from depth_mm(i), a baseline.
void HamlynFixture(const fs::path& in, const std::function<cv::Mat(int)>& depth_mm) {
  for (const char* folder : {"image01", "image02", "depth01"}) fs::create_directories(in / folder);
  for (int i = 0; i < kFrames; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "%010d.png", i);
    cv::imwrite((in / "image01" / name).string(), Frame(i));
    cv::imwrite((in / "image02" / name).string(), Frame(i + 10));
    cv::imwrite((in / "depth01" / name).string(), depth_mm(i));
  }
  std::ofstream(in / "intrinsics.txt") << "50.5 0 31.2\n0 50.7 23.9\n0 0 1\n5.38\n";
}

TEST(DatasetImport, HamlynRectifiedStereoWithMillimetreDepth) {
  const fs::path in = UniqueTempFolder("hamlyn_in"), out = UniqueTempFolder("hamlyn_out");
  HamlynFixture(in, [](int i) { return cv::Mat(kHeight, kWidth, CV_16UC1, cv::Scalar(60 + i)); });
  ImportOptions options = Options("hamlyn", in);
  ImportDataset(options, out);
  const SequenceReader sequence(out);
  EXPECT_EQ(sequence.frame_count(), kFrames);
  EXPECT_DOUBLE_EQ(sequence.info().camera.fx(), 50.5);
  EXPECT_DOUBLE_EQ(sequence.info().camera.cy(), 23.9);
  ASSERT_TRUE(sequence.has_right());
  EXPECT_DOUBLE_EQ(sequence.info().stereo->baseline_mm, 5.38);
  EXPECT_FLOAT_EQ(sequence.ReadDepthMm(2).at<float>(5, 5), 62.f);
  EXPECT_FALSE(sequence.has_groundtruth());
  EXPECT_EQ(sequence.info().provenance.at("code"), SequenceCodeFingerprint());  // which importer made it

  // --stereo-depth: for a Hamlyn sequence without depth01/, depth from its rectified pairs.
  options.stereo_depth = true;
  EXPECT_NE(ImportError(options, UniqueTempFolder("hamlyn_stereo")).find("has depth of its own"), std::string::npos);
  fs::remove_all(in / "depth01");
  ImportDataset(options, UniqueTempFolder("hamlyn_stereo"));
  const SequenceReader stereo(UniqueTempFolder("hamlyn_stereo"));
  EXPECT_TRUE(stereo.has_depth());
  EXPECT_EQ(
      stereo.info().provenance.at("depth").at("generator").get<std::string>().rfind("nrslam_import --stereo-depth", 0),
      0u);
  fs::remove_all(UniqueTempFolder("hamlyn_stereo"));
  fs::remove_all(in / "image02");
  EXPECT_NE(ImportError(options, out).find("--stereo-depth needs the right camera's images"), std::string::npos);
  HamlynFixture(in, [](int i) { return cv::Mat(kHeight, kWidth, CV_16UC1, cv::Scalar(60 + i)); });
  options.stereo_depth = false;

  fs::remove(in / "image02" / "0000000001.png");
  EXPECT_NE(ImportError(options, out).find("image02/ has no image of frame 1 (image01/0000000001.png)"),
            std::string::npos);
  HamlynFixture(in, [](int i) { return cv::Mat(kHeight, kWidth, CV_16UC1, cv::Scalar(60 + i)); });
  fs::remove(in / "intrinsics.txt");
  EXPECT_NE(ImportError(options, out).find("missing intrinsics.txt"), std::string::npos);
  fs::create_directory(in / "intrinsics.txt");  // opens as a stream, then reads as nothing
  EXPECT_NE(ImportError(options, out).find((in / "intrinsics.txt").string() + " is a folder, not a text file"),
            std::string::npos);
  fs::remove_all(in);
  fs::remove_all(out);
}

// intrinsics.txt is read by rows, so that K comes out right from a 3×3, a 3×4 projection matrix
// or a homogeneous 4×4; a baseline line after it makes the right camera usable.
TEST(DatasetImport, HamlynIntrinsicsAsThreeByThreeThreeByFourOrFourByFour) {
  const fs::path in = UniqueTempFolder("hamlyn_k_in"), out = UniqueTempFolder("hamlyn_k_out");
  HamlynFixture(in, [](int i) { return cv::Mat(kHeight, kWidth, CV_16UC1, cv::Scalar(60 + i)); });
  const ImportOptions options = Options("hamlyn", in);
  const auto import_with = [&](const std::string& intrinsics) {
    std::ofstream(in / "intrinsics.txt") << intrinsics;
    fs::remove_all(out);
    ImportDataset(options, out);
    return SequenceReader(out);
  };
  const SequenceReader three_by_four = import_with("50.5 0 31.2 0\n0 50.7 23.9 0\n0 0 1 0\n5.38\n");
  EXPECT_EQ(three_by_four.info().camera.params(), Camera::Pinhole(kWidth, kHeight, 50.5, 50.7, 31.2, 23.9).params());
  ASSERT_TRUE(three_by_four.has_right());
  EXPECT_DOUBLE_EQ(three_by_four.info().stereo->baseline_mm, 5.38);
  const SequenceReader homogeneous = import_with("  50.5 0 31.2 0\r\n\n0 50.7 23.9 0\r\n0 0 1 0\r\n0 0 0 1\r\n");
  EXPECT_EQ(homogeneous.info().camera.params(), Camera::Pinhole(kWidth, kHeight, 50.5, 50.7, 31.2, 23.9).params());
  EXPECT_FALSE(homogeneous.has_right());  // no baseline: the right images cannot be used
  // A rectified right camera's projection matrix gives the baseline: its 4th column, fx·(−B).
  const SequenceReader right_projection = import_with("50.5 0 31.2 -271.69\n0 50.7 23.9 0\n0 0 1 0\n");
  EXPECT_EQ(right_projection.info().camera.params(), Camera::Pinhole(kWidth, kHeight, 50.5, 50.7, 31.2, 23.9).params());
  ASSERT_TRUE(right_projection.has_right());
  EXPECT_NEAR(right_projection.info().stereo->baseline_mm, 5.38, 1e-12);
  EXPECT_DOUBLE_EQ(import_with("50.5 0 31.2 -271.69\n0 50.7 23.9 0\n0 0 1 0\n5.4\n").info().stereo->baseline_mm,
                   5.4);  // within 1 %: the line's

  const auto error_with = [&](const std::string& intrinsics) {
    std::ofstream(in / "intrinsics.txt") << intrinsics;
    return ImportError(options, out);
  };
  EXPECT_NE(error_with("50.5 0.2 31.2\n0 50.7 23.9\n0 0 1\n").find("is not a pinhole K"), std::string::npos);
  EXPECT_NE(error_with("0 50.7 23.9\n50.5 0 31.2\n0 0 1\n").find("is not a pinhole K"), std::string::npos);
  EXPECT_NE(error_with("50.5 0 31.2 50.7 23.9 0 0 1 5.38\n").find("expected K as three rows"), std::string::npos);
  EXPECT_NE(error_with("fx 0 cx\n0 fy cy\n0 0 1\n").find("intrinsics.txt line 1 is not a row of numbers"),
            std::string::npos);
  EXPECT_NE(error_with("50.5 0 31.2\n0 50.7 23.9\n0 0 1\n5.38 1\n").find("the 4th line holds 2 numbers"),
            std::string::npos);
  EXPECT_NE(error_with("50.5 0 31.2 -271.69\n0 50.7 23.9 0\n0 0 1 0\n6\n")
                .find("the baseline after K (6.000 mm) is not the one its projection matrix gives (5.380 mm"),
            std::string::npos);
  EXPECT_NE(error_with("50.5 0 31.2 0\n0 50.7 23.9 -271.69\n0 0 1 0\n").find("a 4th column other than 0 0 0"),
            std::string::npos);

  // --stereo-depth without a baseline says what is missing, not that the right images are.
  fs::remove_all(in / "depth01");
  std::ofstream(in / "intrinsics.txt") << "50.5 0 31.2\n0 50.7 23.9\n0 0 1\n";
  ImportOptions stereo = options;
  stereo.stereo_depth = true;
  EXPECT_NE(ImportError(stereo, out).find("--stereo-depth needs the baseline"), std::string::npos);

  // A calibration file stands in for a missing intrinsics.txt.
  fs::remove(in / "intrinsics.txt");
  ImportOptions calibrated = options;
  calibrated.calibration = in / "camera.json";
  WriteCalibration(calibrated.calibration);
  fs::remove_all(out);
  ImportDataset(calibrated, out);
  EXPECT_DOUBLE_EQ(SequenceReader(out).info().camera.fy(), 51);
  fs::remove_all(in);
  fs::remove_all(out);
}

// Endo-Depth-and-Motion's Hamlyn tracking data (color/, depth/, names without leading zeros),
// and frames paired across folders by their numbers, not by their places in each folder.
TEST(DatasetImport, HamlynFramesPairedByNumberInEitherLayout) {
  const fs::path in = UniqueTempFolder("edam_in"), out = UniqueTempFolder("edam_out");
  constexpr int kManyFrames = 12;  // past 9, where name order and number order part
  fs::create_directories(in / "color");
  fs::create_directories(in / "depth");
  for (int i = 0; i < kManyFrames; ++i) {
    cv::imwrite((in / "color" / (std::to_string(i) + ".png")).string(), Frame(i));
    cv::imwrite((in / "depth" / (std::to_string(i) + ".png")).string(),
                cv::Mat(kHeight, kWidth, CV_16UC1, cv::Scalar(60 + 2 * i)));
  }
  std::ofstream(in / "intrinsics.txt") << "50.5 0 31.2\n0 50.7 23.9\n0 0 1\n";
  const ImportOptions options = Options("hamlyn", in);
  ImportDataset(options, out);
  const SequenceReader sequence(out);
  ASSERT_EQ(sequence.frame_count(), kManyFrames);
  EXPECT_FALSE(sequence.has_right());
  for (int i = 0; i < kManyFrames; ++i) {
    EXPECT_EQ(sequence.ReadRgb(i).at<cv::Vec3b>(0, 0)[0], i * 20) << "frame " << i;
    EXPECT_FLOAT_EQ(sequence.ReadDepthMm(i).at<float>(5, 5), 60.f + 2 * i) << "frame " << i;
  }

  // As many depth images as frames, but one of them of a frame that is not there.
  fs::rename(in / "depth" / "1.png", in / "depth" / "12.png");
  EXPECT_NE(ImportError(options, out).find("depth/ has no image of frame 1 (color/1.png)"), std::string::npos);
  fs::rename(in / "depth" / "12.png", in / "depth" / "01.png");
  cv::imwrite((in / "depth" / "1.png").string(), cv::Mat(kHeight, kWidth, CV_16UC1, cv::Scalar(62)));
  EXPECT_NE(ImportError(options, out).find("two images of frame 1: "), std::string::npos);
  fs::remove_all(in);

  // The rectified release unpacked into a folder of its own name: the message points to it.
  HamlynFixture(in / "rectified08" / "rectified08", [](int i) { return cv::Mat(kHeight, kWidth, CV_16UC1, cv::Scalar(60 + i)); });
  const std::string nested = ImportError(Options("hamlyn", in / "rectified08"), out);
  EXPECT_NE(nested.find("no images in image01/"), std::string::npos) << nested;
  EXPECT_NE(nested.find((in / "rectified08" / "rectified08").string() + " has them: import that folder"), std::string::npos)
      << nested;
  fs::remove(in / "rectified08" / "rectified08" / "image02" / "0000000002.png");
  cv::imwrite((in / "rectified08" / "rectified08" / "image02" / "0000000005.png").string(), Frame(5));
  EXPECT_NE(ImportError(Options("hamlyn", in / "rectified08" / "rectified08"), out)
                .find("image02/ has no image of frame 2 (image01/0000000002.png)"),
            std::string::npos);
  fs::remove_all(in);
  fs::remove_all(out);
}

// --scale resizes the images, the depth and the calibration together (the reference halves
// Endomapper's video); the depth takes the nearest pixel, so a step stays a step.
TEST(DatasetImport, ScaleResizesImagesDepthAndCalibrationTogether) {
  const fs::path in = UniqueTempFolder("scaled_in"), out = UniqueTempFolder("scaled_out");
  HamlynFixture(in, [](int) {
    cv::Mat depth(kHeight, kWidth, CV_16UC1, cv::Scalar(60));
    depth.colRange(kWidth / 2 + 1, kWidth).setTo(90);  // a step edge between two columns pairs average over
    return depth;
  });
  // An endoscope's black border, given as the images' fixed mask, is resized with them.
  cv::Mat border(kHeight, kWidth, CV_8UC1, cv::Scalar(0));
  border(cv::Rect(8, 6, kWidth - 16, kHeight - 12)).setTo(255);
  cv::imwrite((in / "border.png").string(), border);
  ImportOptions options = Options("hamlyn", in);
  options.scale = 0.5;
  options.mask = in / "border.png";
  ImportDataset(options, out);
  const SequenceReader sequence(out);
  const Camera expected = Camera::Pinhole(kWidth, kHeight, 50.5, 50.7, 31.2, 23.9).Resized(kWidth / 2, kHeight / 2);
  EXPECT_EQ(sequence.info().camera.params(), expected.params());
  EXPECT_DOUBLE_EQ(sequence.info().camera.fx(), 25.25);
  EXPECT_DOUBLE_EQ(sequence.info().camera.cx(), 15.35);  // (31.2 + 0.5) / 2 - 0.5
  EXPECT_EQ(sequence.info().stereo->right_camera.params(), expected.params());
  EXPECT_DOUBLE_EQ(sequence.info().stereo->baseline_mm, 5.38);  // a length: it does not scale
  EXPECT_EQ(sequence.ReadRgb(1).size(), cv::Size(kWidth / 2, kHeight / 2));
  EXPECT_EQ(sequence.ReadRight(1).size(), cv::Size(kWidth / 2, kHeight / 2));
  const cv::Mat depth = sequence.ReadDepthMm(1);
  ASSERT_EQ(depth.size(), cv::Size(kWidth / 2, kHeight / 2));
  for (int x = 0; x < depth.cols; ++x) {
    const float value = depth.at<float>(5, x);
    EXPECT_TRUE(value == 60.f || value == 90.f) << "column " << x << " reads " << value;
  }
  EXPECT_EQ(sequence.info().provenance.at("scale"), 0.5);
  const cv::Mat mask = sequence.ReadMask(0);
  ASSERT_EQ(mask.size(), cv::Size(kWidth / 2, kHeight / 2));
  EXPECT_EQ(mask.at<uint8_t>(1, 1), 0);
  EXPECT_EQ(mask.at<uint8_t>(kHeight / 4, kWidth / 4), 255);
  EXPECT_EQ(cv::countNonZero(mask), (kWidth - 16) / 2 * (kHeight - 12) / 2);

  cv::imwrite((in / "border.png").string(), cv::Mat(kHeight / 2, kWidth, CV_8UC1, cv::Scalar(255)));
  EXPECT_NE(ImportError(options, UniqueTempFolder("scaled_out_2")).find("is 64x24 but the images are 64x48"),
            std::string::npos);
  options.mask.clear();

  options.scale = 0;
  EXPECT_NE(ImportError(options, UniqueTempFolder("scaled_out_2")).find("scale must be in (0, 4]"), std::string::npos);
  fs::remove_all(in);
  fs::remove_all(out);
}

// The names C3VD gives its files: colour without leading zeros, depth with four, beside it.
struct C3vdNames {
  const char* colour = "%d_color.png";
  const char* depth = "%04d_depth.tiff";
};

// C3VD poses come as one 4×4 per line; the importer must read both storage orders. Depth is
// 20, 40, 60 … mm, up to the format's 100, with row 0 marking the frame (1000 · (i + 1) units,
// 1.5 mm apart).
void C3vdFixture(const fs::path& in, bool column_major, int frames = kFrames, const C3vdNames& names = {}) {
  fs::create_directories((in / names.depth).parent_path());
  std::ofstream poses(in / "pose.txt");
  for (int i = 0; i < frames; ++i) {
    char name[64];
    std::snprintf(name, sizeof name, names.colour, i);
    cv::imwrite((in / name).string(), Frame(i));
    std::snprintf(name, sizeof name, names.depth, i);
    cv::Mat depth(kHeight, kWidth, CV_16UC1, cv::Scalar(13107 * std::min(i + 1, 5)));
    depth.row(0).setTo(1000 * (i + 1));
    cv::imwrite((in / name).string(), depth);
    Eigen::Matrix4d matrix = Eigen::Matrix4d::Identity();
    matrix.topLeftCorner<3, 3>() = Pose(i).rotation.toRotationMatrix();
    matrix.topRightCorner<3, 1>() = Pose(i).translation;
    for (int k = 0; k < 16; ++k) {
      poses << (k ? "," : "") << (column_major ? matrix(k % 4, k / 4) : matrix(k / 4, k % 4));
    }
    poses << '\n';
  }
}

TEST(DatasetImport, C3vdDepthScaleAndBothPoseOrders) {
  for (bool column_major : {false, true}) {
    const fs::path in = UniqueTempFolder("c3vd_in"), out = UniqueTempFolder("c3vd_out");
    C3vdFixture(in, column_major);
    WriteCalibration(in / "camera.json");
    ImportOptions options = Options("c3vd", in);
    EXPECT_NE(ImportError(options, out).find("needs --calibration"), std::string::npos);
    options.calibration = in / "camera.json";
    ImportDataset(options, out);
    const SequenceReader sequence(out);
    EXPECT_EQ(sequence.frame_count(), kFrames);
    EXPECT_DOUBLE_EQ(sequence.info().camera.fy(), 51.0);
    EXPECT_NEAR(sequence.ReadDepthMm(1).at<float>(3, 3), 40.0, 0.01);
    ASSERT_EQ(sequence.groundtruth().size(), static_cast<size_t>(kFrames));
    for (int i = 0; i < kFrames; ++i) ExpectSamePose(sequence.groundtruth()[i].world_from_camera, Pose(i), 1e-4);
    // Every other frame: frames 0 and 2, with their depth, poses and times, at half the rate.
    options.frame_step = 2;
    fs::remove_all(out);
    ImportDataset(options, out);
    const SequenceReader halved(out);
    ASSERT_EQ(halved.frame_count(), 2);
    EXPECT_DOUBLE_EQ(halved.info().fps, 15.0);
    EXPECT_NEAR(halved.ReadDepthMm(1).at<float>(3, 3), 60.0, 0.01);
    ASSERT_EQ(halved.groundtruth().size(), 2u);
    ExpectSamePose(halved.groundtruth()[1].world_from_camera, Pose(2), 1e-4);
    EXPECT_NEAR(halved.groundtruth()[1].timestamp, 2 / 30.0, 1e-9);  // TUM files keep 12 digits
    EXPECT_EQ(halved.info().provenance.at("frame_step"), 2);
    fs::remove_all(in);
    fs::remove_all(out);
  }
}

// Past frame 9, C3VD's unpadded colour names sort by name as 0, 1, 10, 11, 2 …: the frames
// are taken in the order of their numbers, and each depth found by its number, with four
// leading zeros beside the colour or (the later release) in depth/, with none, or with six.
TEST(DatasetImport, C3vdFramesInTheOrderOfTheirNumbersWhateverThePadding) {
  for (const char* depth_names : {"%04d_depth.tiff", "depth/%04d_depth.tiff", "%d_depth.tiff", "%06d_depth.tiff"}) {
    const fs::path in = UniqueTempFolder("c3vd_numbers_in"), out = UniqueTempFolder("c3vd_numbers_out");
    constexpr int kManyFrames = 12;
    C3vdFixture(in, false, kManyFrames, {"%d_color.png", depth_names});
    WriteCalibration(in / "camera.json");
    ImportOptions options = Options("c3vd", in);
    options.calibration = in / "camera.json";
    ImportDataset(options, out);
    const SequenceReader sequence(out);
    ASSERT_EQ(sequence.frame_count(), kManyFrames) << depth_names;
    for (int i = 0; i < kManyFrames; ++i) {
      EXPECT_EQ(sequence.ReadRgb(i).at<cv::Vec3b>(0, 5)[0], 20 * i) << depth_names << ", frame " << i;
      EXPECT_NEAR(sequence.ReadDepthMm(i).at<float>(0, 5), 1000.0 * (i + 1) * 100.0 / 65535.0, 0.01) << depth_names;
      ExpectSamePose(sequence.groundtruth()[i].world_from_camera, Pose(i), 1e-4);
    }
    fs::remove_all(in);
    fs::remove_all(out);
  }
  // pose.txt's lines are frames 0, 1, 2 …: a gap in the colour frames would pair the wrong poses.
  const fs::path in = UniqueTempFolder("c3vd_gap_in");
  C3vdFixture(in, false, 4);
  fs::remove(in / "2_color.png");
  ImportOptions options = Options("c3vd", in);
  WriteCalibration(in / "camera.json");
  options.calibration = in / "camera.json";
  EXPECT_NE(ImportError(options, UniqueTempFolder("c3vd_gap_out"))
                .find("3_color.png is where frame 2 should be: the colour images must be numbered 0, 1, 2"),
            std::string::npos);
  fs::remove(in / "3_color.png");
  fs::copy_file(in / "0001_depth.tiff", in / "1_depth.tiff");
  EXPECT_NE(ImportError(options, UniqueTempFolder("c3vd_gap_out")).find("two images of frame 1: "), std::string::npos);
  fs::remove(in / "1_depth.tiff");
  fs::remove(in / "0001_depth.tiff");
  EXPECT_NE(ImportError(options, UniqueTempFolder("c3vd_gap_out"))
                .find("no depth of frame 1 (1_depth.tiff, with leading zeros or none, here or in depth/)"),
            std::string::npos);
  fs::remove_all(in);
}

// C3VD's colonoscope is calibrated with OCamCalib: its calib_results.txt is the calibration as
// it is (here a 64x48 fisheye written in that format).
TEST(DatasetImport, C3vdWithItsOCamCalibResults) {
  const fs::path in = UniqueTempFolder("c3vd_ocam_in"), out = UniqueTempFolder("c3vd_ocam_out");
  C3vdFixture(in, false);
  const Camera lens = OcamFromKannalaBrandt(
      Camera::KannalaBrandt(kWidth, kHeight, 22.0, 22.3, 31.8, 23.2, Eigen::Vector4d(-0.02, 0.002, 0, 0)));
  const nlohmann::json fields = lens;
  std::ofstream text(in / "calib_results.txt");
  const auto polynomial = [&](const char* key) {
    text << fields[key].size();
    for (double coefficient : fields[key]) text << ' ' << std::setprecision(17) << coefficient;
    text << "\n\n";
  };
  text << "#polynomial coefficients for the DIRECT mapping function (ocam_model.ss in MATLAB)\n\n";
  polynomial("ss");
  text << "#polynomial coefficients for the inverse mapping function (ocam_model.invpol in MATLAB)\n\n";
  polynomial("invpol");
  text << "#center: \"row\" and \"column\", starting from 0 (C convention)\n\n" << lens.cy() << ' ' << lens.cx()
       << "\n\n#affine parameters \"c\", \"d\", \"e\"\n\n" << fields["c"] << " 0 0\n\n"
       << "#image size: \"height\" and \"width\"\n\n" << kHeight << ' ' << kWidth << '\n';
  text.close();
  ImportOptions options = Options("c3vd", in);
  options.calibration = in / "calib_results.txt";
  ImportDataset(options, out);
  const SequenceReader sequence(out);
  EXPECT_EQ(sequence.info().camera.model(), CameraModelId::kOcam);
  EXPECT_LT((sequence.info().camera.Unproject(Eigen::Vector2d(50.3, 10.6)) - lens.Unproject(Eigen::Vector2d(50.3, 10.6)))
                .norm(),
            1e-9);
  fs::remove_all(in);
  fs::remove_all(out);
}

// Frames written as ffmpeg's frame_%d.png sort by name as 0, 1, 10, 11, 2 …; they are taken
// in the order of their numbers.
TEST(DatasetImport, ImageFolderNumberedWithoutLeadingZerosKeepsItsOrder) {
  const fs::path in = UniqueTempFolder("numbered_in"), out = UniqueTempFolder("numbered_out");
  fs::create_directories(in);
  constexpr int kManyFrames = 12;
  for (int i = 0; i < kManyFrames; ++i) cv::imwrite((in / ("frame_" + std::to_string(i) + ".png")).string(), Frame(i));
  WriteCalibration(in / "camera.json");
  ImportOptions options = Options("images", in);
  options.calibration = in / "camera.json";
  ImportDataset(options, out);
  const SequenceReader sequence(out);
  ASSERT_EQ(sequence.frame_count(), kManyFrames);
  for (int i = 0; i < kManyFrames; ++i) EXPECT_EQ(sequence.ReadRgb(i).at<cv::Vec3b>(0, 5)[0], 20 * i) << "frame " << i;
  fs::remove_all(in);
  fs::remove_all(out);
}

TEST(DatasetImport, PlainImageFolderAndVideoWithACalibration) {
  const fs::path in = UniqueTempFolder("images_in"), out = UniqueTempFolder("images_out");
  fs::create_directories(in / "frames");
  for (int i = 0; i < kFrames; ++i) cv::imwrite((in / "frames" / ("f" + std::to_string(i) + ".jpg")).string(), Frame(i));
  WriteCalibration(in / "camera.json");
  ImportOptions options = Options("images", in / "frames");
  options.calibration = in / "camera.json";
  ImportDataset(options, out);
  {
    const SequenceReader sequence(out);
    EXPECT_EQ(sequence.frame_count(), kFrames);
    EXPECT_FALSE(sequence.has_depth());
    EXPECT_FALSE(sequence.has_groundtruth());
  }
  // A video (Motion JPEG, which OpenCV encodes without external codecs).
  {
    cv::VideoWriter video((in / "clip.avi").string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 30,
                          cv::Size(kWidth, kHeight));
    ASSERT_TRUE(video.isOpened());
    for (int i = 0; i < 5; ++i) video.write(Frame(i));
  }
  fs::remove_all(out);
  options.input = in / "clip.avi";
  ImportDataset(options, out);
  EXPECT_EQ(SequenceReader(out).frame_count(), 5);
  // Every other frame of a video whose frame i is grey level 40·i: 0, 2 and 4 are kept.
  {
    cv::VideoWriter video((in / "levels.avi").string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 30,
                          cv::Size(kWidth, kHeight));
    for (int i = 0; i < 6; ++i) video.write(cv::Mat(kHeight, kWidth, CV_8UC3, cv::Scalar::all(40 * i)));
  }
  fs::remove_all(out);
  options.input = in / "levels.avi";
  options.frame_step = 2;
  ImportDataset(options, out);
  {
    const SequenceReader sequence(out);
    ASSERT_EQ(sequence.frame_count(), 3);
    EXPECT_DOUBLE_EQ(sequence.info().fps, 15.0);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(cv::mean(sequence.ReadRgb(i))[0], 80 * i, 3) << i;
  }
  options.input = in / "clip.avi";
  options.frame_step = 1;
  // Another sequence's sequence.json serves as the calibration: its "camera" is read.
  fs::copy(out / "sequence.json", in / "sequence.json");
  options.calibration = in / "sequence.json";
  fs::remove_all(out);
  ImportDataset(options, out);
  EXPECT_DOUBLE_EQ(SequenceReader(out).info().camera.fy(), 51.0);
  // A calibration for another image size is caught.
  std::ofstream(in / "wrong.json") << R"({"model": "pinhole", "width": 640, "height": 480, "fx": 500, "fy": 500, "cx": 319.5, "cy": 239.5})";
  options.calibration = in / "wrong.json";
  fs::remove_all(out);
  EXPECT_NE(ImportError(options, out).find("is 64x48 but the camera is 640x480"), std::string::npos);
  // A failed import leaves no half sequence behind (it would pass for a whole one until read):
  // here a frame whose file is cut short.
  EXPECT_FALSE(fs::exists(out / "sequence.json"));
  options.input = in / "frames";
  options.calibration = in / "camera.json";
  fs::resize_file(in / "frames" / "f1.jpg", 100);
  EXPECT_NE(ImportError(options, out).find("cannot read " + (in / "frames" / "f1.jpg").string()), std::string::npos);
  EXPECT_FALSE(fs::exists(out / "sequence.json"));
  EXPECT_FALSE(fs::exists(out / "rgb"));
  options.format = "hamlin";
  EXPECT_NE(ImportError(options, out).find("unknown dataset format 'hamlin'"), std::string::npos);
  fs::remove_all(in);
  fs::remove_all(out);
}

}  // namespace
}  // namespace nrslam
