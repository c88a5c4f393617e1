// Importing a raw stereo recording: a tilted textured plane seen by two distorted cameras turned
// against each other, imported with its OpenCV stereo calibration, must come out as a rectified
// pair whose stereo depth is the plane's true depth in the rectified camera; the packed layouts
// and a video give the same images; calibrations that cannot give a side-by-side pair are refused.
#include <gtest/gtest.h>

#include <Eigen/Core>  // before OpenCV's Eigen bridge, which needs it
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <iomanip>
#include <sstream>
#include <fstream>
#include <string>
#include <vector>

#include "nrslam/datasets/dataset_import.h"
#include "nrslam/datasets/stereo_depth.h"
#include "nrslam/datasets/stereo_rectification.h"
#include "nrslam/io/sequence_reader.h"
#include "nrslam/util/error.h"
#include "camera_fixtures.h"
#include "error_message.h"
#include "temp_folder.h"

namespace nrslam {
namespace {

namespace fs = std::filesystem;
constexpr int kWidth = 320, kHeight = 240, kFrames = 3;

// A plane n·x = d in the left camera's frame, 45–75 mm away, with a blurred-noise texture that
// slides by 1.5 mm per frame (so frames differ). One for all tests: its texture takes a while.
struct TexturedPlane {
  Eigen::Vector3d normal = Eigen::Vector3d(0.25, -0.15, 1.0).normalized();
  double distance = 60.0;
  Eigen::Vector3d axis_u, axis_v;
  cv::Mat texture;  // CV_32F, 8 texels per mm, centred on the plane's point nearest the camera
  static constexpr double kTexelsPerMm = 8.0;

  TexturedPlane() {
    axis_u = normal.cross(Eigen::Vector3d::UnitY()).normalized();
    axis_v = normal.cross(axis_u);
    cv::Mat noise(2048, 2048, CV_32F);  // 256 mm across: wider than a fisheye sees of it
    cv::RNG rng(7);
    rng.fill(noise, cv::RNG::UNIFORM, 0.0, 1.0);
    cv::GaussianBlur(noise, texture, cv::Size(0, 0), 1.6);
    cv::normalize(texture, texture, 20, 235, cv::NORM_MINMAX);
  }

  // Grey level where the ray origin + t·direction (left camera frame) meets the plane; -1 if it
  // does not.
  float Shade(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, int frame) const {
    const double t = (distance - normal.dot(origin)) / normal.dot(direction);
    if (!(t > 0)) return -1.0f;
    const Eigen::Vector3d offset = origin + t * direction - distance * normal;
    const float x = static_cast<float>((offset.dot(axis_u) + 1.5 * frame) * kTexelsPerMm + texture.cols / 2.0);
    const float y = static_cast<float>(offset.dot(axis_v) * kTexelsPerMm + texture.rows / 2.0);
    if (x < 0 || y < 0 || x > texture.cols - 2 || y > texture.rows - 2) return -1.0f;
    cv::Mat sample;
    cv::getRectSubPix(texture, cv::Size(1, 1), cv::Point2f(x, y), sample);
    return sample.at<float>(0, 0);
  }

  // Depth of the plane along the ray (z = 1) of a rectified camera turned by `rectified_from_left`.
  double Depth(const Eigen::Matrix3d& rectified_from_left, const Eigen::Vector3d& rectified_ray) const {
    return distance / normal.dot(rectified_from_left.transpose() * rectified_ray);
  }
};

const TexturedPlane& Plane() {
  static const TexturedPlane plane;
  return plane;
}

StereoCalibration Rig() {
  StereoCalibration rig;
  rig.left = Camera::OpenCv(kWidth, kHeight, 300, 302, 161.0, 118.5, {-0.25, 0.08, 0.001, -0.0005, -0.01});
  rig.right = Camera::OpenCv(kWidth, kHeight, 305, 306, 157.5, 122.0, {-0.22, 0.06, -0.0008, 0.0004, 0.0});
  const Eigen::Matrix3d toe_in =
      (Eigen::AngleAxisd(0.035, Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(0.012, Eigen::Vector3d::UnitX()) *
       Eigen::AngleAxisd(-0.008, Eigen::Vector3d::UnitZ()))
          .toRotationMatrix();
  rig.right_from_left = Rigid3(Eigen::Quaterniond(toe_in), Eigen::Vector3d(-5.2, 0.15, 0.1));
  return rig;
}

// The same rig with fisheye (Kannala–Brandt) lenses, about 105° across the diagonal.
StereoCalibration FisheyeRig() {
  StereoCalibration rig = Rig();
  rig.left = Camera::KannalaBrandt(kWidth, kHeight, 210, 211, 160.5, 119.0, Eigen::Vector4d(0.04, -0.01, 0.002, 0));
  rig.right = Camera::KannalaBrandt(kWidth, kHeight, 212, 212, 158.0, 121.5, Eigen::Vector4d(0.03, -0.008, 0.001, 0));
  return rig;
}

// The raw image of `camera`, placed at camera_from_left, of the plane at `frame`.
cv::Mat RawView(const TexturedPlane& plane, const Camera& camera, const Rigid3& camera_from_left, int frame) {
  const Rigid3 left_from_camera = camera_from_left.Inverse();
  cv::Mat image(camera.height(), camera.width(), CV_8UC3, cv::Scalar::all(0));
  for (int v = 0; v < image.rows; ++v) {
    for (int u = 0; u < image.cols; ++u) {
      const Eigen::Vector3d direction = left_from_camera.rotation * camera.Unproject(Eigen::Vector2d(u, v));
      const float shade = plane.Shade(left_from_camera.translation, direction, frame);
      if (shade >= 0) image.at<cv::Vec3b>(v, u) = cv::Vec3b::all(cv::saturate_cast<uchar>(shade));
    }
  }
  return image;
}

void WriteMatrix(cv::FileStorage& storage, const char* key, const Eigen::MatrixXd& value) {
  cv::Mat matrix(static_cast<int>(value.rows()), static_cast<int>(value.cols()), CV_64F);
  for (int r = 0; r < matrix.rows; ++r) {
    for (int c = 0; c < matrix.cols; ++c) matrix.at<double>(r, c) = value(r, c);
  }
  storage << key << matrix;
}

Eigen::Matrix3d CameraMatrix(const Camera& camera) {
  Eigen::Matrix3d k;
  k << camera.fx(), 0, camera.cx(), 0, camera.fy(), camera.cy(), 0, 0, 1;
  return k;
}

// OpenCV's coefficients: k1 k2 p1 p2 k3, or the fisheye model's k1 … k4.
Eigen::VectorXd Distortion(const Camera& camera) {
  const bool fisheye = camera.model() == CameraModelId::kKannalaBrandt;
  return Eigen::Map<const Eigen::VectorXd>(camera.params().data() + 4, fisheye ? 4 : 5);
}

// The rig as OpenCV's stereo_calib sample writes it: intrinsics and extrinsics in two files,
// without the image size unless `with_size`. `translation` overrides T.
void WriteCalibration(const StereoCalibration& rig, const fs::path& intrinsics, const fs::path& extrinsics,
                      const Eigen::Vector3d& translation, bool with_size = false) {
  cv::FileStorage in(intrinsics.string(), cv::FileStorage::WRITE);
  if (with_size) in << "image_width" << rig.left.width() << "image_height" << rig.left.height();
  if (rig.left.model() == CameraModelId::kKannalaBrandt) in << "distortion_model" << "equidistant";
  WriteMatrix(in, "M1", CameraMatrix(rig.left));
  WriteMatrix(in, "D1", Distortion(rig.left).transpose());
  WriteMatrix(in, "M2", CameraMatrix(rig.right));
  WriteMatrix(in, "D2", Distortion(rig.right).transpose());
  cv::FileStorage ex(extrinsics.string(), cv::FileStorage::WRITE);
  WriteMatrix(ex, "R", rig.right_from_left.rotation.toRotationMatrix());
  WriteMatrix(ex, "T", translation);
}

// Writes the left and right frames to left/ and right/, both side by side to both/, and one
// above the other to a video.
void WriteRecording(const fs::path& in, const StereoCalibration& rig = Rig()) {
  const TexturedPlane& plane = Plane();
  for (const char* folder : {"left", "right", "both"}) fs::create_directories(in / folder);
  cv::VideoWriter video((in / "stacked.avi").string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 30,
                        cv::Size(kWidth, 2 * kHeight));
  ASSERT_TRUE(video.isOpened());
  for (int i = 0; i < kFrames; ++i) {
    const cv::Mat left = RawView(plane, rig.left, Rigid3(), i);
    const cv::Mat right = RawView(plane, rig.right, rig.right_from_left, i);
    const std::string name = std::to_string(i) + ".png";
    cv::imwrite((in / "left" / name).string(), left);
    cv::imwrite((in / "right" / name).string(), right);
    cv::Mat both, stacked;
    cv::hconcat(left, right, both);
    cv::vconcat(left, right, stacked);
    cv::imwrite((in / "both" / name).string(), both);
    video << stacked;
  }
  WriteCalibration(rig, in / "intrinsics.yml", in / "extrinsics.yml", rig.right_from_left.translation);
}

ImportOptions StereoImport(const fs::path& in) {
  ImportOptions options;
  options.format = "stereo";
  options.input = in / "left";
  options.right = in / "right";
  options.calibration = in / "intrinsics.yml";
  options.second_calibration = in / "extrinsics.yml";
  return options;
}

// The rotation from the raw left camera to the rectified one, as the import recorded it.
Eigen::Matrix3d RectifiedFromLeft(const SequenceInfo& info) {
  const auto& rows = info.provenance.at("rectification").at("rectified_from_raw_left");
  Eigen::Matrix3d rotation;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) rotation(r, c) = rows.at(r).at(c).get<double>();
  }
  return rotation;
}

double MedianDepthError(const cv::Mat& depth, const Camera& camera, const Eigen::Matrix3d& rectified_from_left,
                        double* coverage) {
  const TexturedPlane& plane = Plane();
  std::vector<double> errors;
  for (int v = 0; v < depth.rows; ++v) {
    for (int u = 0; u < depth.cols; ++u) {
      if (!(depth.at<float>(v, u) > 0)) continue;
      const Eigen::Vector3d ray((u - camera.cx()) / camera.fx(), (v - camera.cy()) / camera.fy(), 1.0);
      errors.push_back(std::abs(depth.at<float>(v, u) - plane.Depth(rectified_from_left, ray)));
    }
  }
  *coverage = static_cast<double>(errors.size()) / depth.total();
  if (errors.empty()) return 1e9;
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  return errors[errors.size() / 2];
}

TEST(StereoRectification, ARawDistortedPairGivesThePlanesTrueDepth) {
  const fs::path folder = UniqueTempFolder("stereo_rectify");
  fs::remove_all(folder);
  WriteRecording(folder);
  ASSERT_FALSE(HasFatalFailure());
  ImportOptions options = StereoImport(folder);
  options.stereo_depth = true;
  const SequenceInfo info = ImportDataset(options, folder / "seq");
  const StereoCalibration rig = Rig();
  ASSERT_TRUE(info.stereo.has_value());
  // Rectification turns T onto the x axis: the baseline is its length.
  EXPECT_NEAR(info.stereo->baseline_mm, rig.right_from_left.translation.norm(), 1e-6);
  EXPECT_EQ(info.camera.model(), CameraModelId::kPinhole);
  EXPECT_EQ(info.camera.width(), kWidth);  // pixels are square here: the size is kept
  EXPECT_EQ(info.camera.height(), kHeight);

  const SequenceReader sequence(folder / "seq");
  const Eigen::Matrix3d rectified_from_left = RectifiedFromLeft(sequence.info());
  EXPECT_LT((rectified_from_left.transpose() * rectified_from_left - Eigen::Matrix3d::Identity()).norm(), 1e-9);
  ASSERT_TRUE(sequence.has_depth());
  EXPECT_EQ(sequence.info().provenance.at("depth").at("options").at("block_size"), StereoDepthOptions{}.block_size);
  for (int i = 0; i < kFrames; ++i) {
    double coverage = 0;
    const cv::Mat depth = sequence.ReadDepthMm(i);  // --stereo-depth's, from the rectified pair
    const double median = MedianDepthError(depth, info.camera, rectified_from_left, &coverage);
    std::printf("frame %d: rectified pair, stereo depth on %.1f %% of the pixels, median |error| %.3f mm, f %.1f px\n",
                i, 100 * coverage, median, info.camera.fx());
    // Measured: 92 % of the pixels, median error 0.31 mm at 45–75 mm (disparities of 20–35 px).
    // That is semi-global matching's own error: an ideal rectified pair of the same plane, rendered
    // directly with the rectified camera, measured 0.33 mm.
    EXPECT_GT(coverage, 0.8);
    EXPECT_LT(median, 0.5);
  }
  // Halved on import, the depth is still matched at the recording's size, then resized: as
  // accurate as unhalved (measured 0.31 mm; matched after halving, with half the disparity, 0.70).
  options.scale = 0.5;
  options.stereo_depth_options.min_depth_mm = 30;  // the plane is 45–75 mm away: fewer disparities, same depth
  const SequenceInfo half = ImportDataset(options, folder / "half");
  EXPECT_EQ(half.provenance.at("depth").at("options").at("min_depth_mm"), 30);
  EXPECT_EQ(half.camera.width(), kWidth / 2);
  double half_coverage = 0;
  const double half_median = MedianDepthError(SequenceReader(folder / "half").ReadDepthMm(0), half.camera,
                                              rectified_from_left, &half_coverage);
  std::printf("halved: stereo depth on %.1f %% of the pixels, median |error| %.3f mm\n", 100 * half_coverage,
              half_median);
  EXPECT_GT(half_coverage, 0.7);
  EXPECT_LT(half_median, 0.5);
  // The control: the raw pair read as if it were rectified (left intrinsics, |T|) is far off,
  // so the figures above are the rectification's.
  double raw_coverage = 0;
  const cv::Mat raw_depth =
      StereoDepthMm(cv::imread((folder / "left" / "0.png").string()), cv::imread((folder / "right" / "0.png").string()),
                    rig.left.fx(), rig.right_from_left.translation.norm(), StereoDepthOptions{});
  const double raw_median = MedianDepthError(raw_depth, rig.left, Eigen::Matrix3d::Identity(), &raw_coverage);
  std::printf("control: the raw pair as if rectified, depth on %.1f %%, median |error| %.3f mm\n", 100 * raw_coverage,
              raw_median);
  EXPECT_TRUE(raw_coverage < 0.35 || raw_median > 1.0);
  fs::remove_all(folder);
}

// Fisheye lenses go through OpenCV's fisheye rectification: the same plane, SGBM's accuracy.
TEST(StereoRectification, ARawFisheyePairGivesThePlanesTrueDepth) {
  const fs::path folder = UniqueTempFolder("stereo_fisheye");
  fs::remove_all(folder);
  const StereoCalibration rig = FisheyeRig();
  WriteRecording(folder, rig);
  ASSERT_FALSE(HasFatalFailure());
  ImportOptions options = StereoImport(folder);
  options.stereo_depth = true;
  options.max_frames = 1;
  const SequenceInfo info = ImportDataset(options, folder / "seq");
  EXPECT_NEAR(info.stereo->baseline_mm, rig.right_from_left.translation.norm(), 1e-6);
  EXPECT_EQ(info.provenance.at("rectification").at("raw_left_camera").at("model"), "kannala_brandt");
  const Eigen::Matrix3d rectified_from_left = RectifiedFromLeft(info);
  double coverage = 0;
  const double median =
      MedianDepthError(SequenceReader(folder / "seq").ReadDepthMm(0), info.camera, rectified_from_left, &coverage);
  std::printf("fisheye pair: f %.1f px, stereo depth on %.1f %% of the pixels, median |error| %.3f mm\n",
              info.camera.fx(), 100 * coverage, median);
  // Measured: 95 % of the pixels, median 0.52 mm. The rectified focal length is 191 px, so the
  // disparities are smaller than the pinhole rig's: an ideal pair rendered directly with this
  // rectified camera measured 0.53 mm.
  EXPECT_GT(coverage, 0.8);
  EXPECT_LT(median, 0.8);
  fs::remove_all(folder);
}

TEST(StereoRectification, PackedLayoutsAndAVideoGiveTheSameImages) {
  const fs::path folder = UniqueTempFolder("stereo_layouts");
  fs::remove_all(folder);
  WriteRecording(folder);
  ASSERT_FALSE(HasFatalFailure());
  ImportDataset(StereoImport(folder), folder / "two");
  ImportOptions side_by_side = StereoImport(folder);
  side_by_side.input = folder / "both";
  side_by_side.right.clear();
  side_by_side.stereo_layout = "side-by-side";
  ImportDataset(side_by_side, folder / "packed");
  ImportOptions stacked = side_by_side;
  stacked.input = folder / "stacked.avi";
  stacked.stereo_layout = "top-bottom";
  ImportDataset(stacked, folder / "video");
  const SequenceReader two(folder / "two"), packed(folder / "packed"), video(folder / "video");
  ASSERT_EQ(video.frame_count(), kFrames);
  for (int i = 0; i < kFrames; ++i) {
    EXPECT_EQ(cv::norm(two.ReadRgb(i), packed.ReadRgb(i), cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(two.ReadRight(i), packed.ReadRight(i), cv::NORM_INF), 0.0);
    // The video is JPEG-compressed: close to the PNGs' frame, and far from the next frame's.
    const double same = cv::norm(two.ReadRgb(i), video.ReadRgb(i), cv::NORM_L1) / two.ReadRgb(i).total();
    const double next =
        cv::norm(two.ReadRgb((i + 1) % kFrames), video.ReadRgb(i), cv::NORM_L1) / two.ReadRgb(i).total();
    const double right = cv::norm(two.ReadRight(i), video.ReadRight(i), cv::NORM_L1) / two.ReadRight(i).total();
    EXPECT_LT(same, 10.0);
    EXPECT_LT(right, 10.0);
    EXPECT_GT(next, 3 * same);
  }
  fs::remove_all(folder);
}

TEST(StereoRectification, InterlacedFieldsAreStretchedToSquarePixels) {
  StereoCalibration rig = Rig();
  // A field of an interlaced video: every other row, so half the vertical focal length.
  rig.left = Camera::Pinhole(720, 288, 760, 380, 360, 144);
  rig.right = Camera::Pinhole(720, 288, 760, 380, 358, 145);
  const StereoRectifier automatic(rig, StereoRectificationOptions{});
  EXPECT_EQ(automatic.camera().width(), 720);
  EXPECT_EQ(automatic.camera().height(), 576);
  EXPECT_NEAR(automatic.camera().fx() / automatic.camera().fy(), 1.0, 1e-9);
  const StereoRectifier chosen(rig, StereoRectificationOptions{720, 515, 0.0});  // the reference's Hamlyn 20 size
  EXPECT_EQ(chosen.camera().height(), 515);
}

// A matrix as a YAML flow list, row by row, with every digit a double keeps.
std::string FlowList(const Eigen::MatrixXd& matrix) {
  std::ostringstream text;
  text << std::setprecision(17) << "[";
  for (int r = 0; r < matrix.rows(); ++r) {
    for (int c = 0; c < matrix.cols(); ++c) text << (r + c > 0 ? ", " : "") << matrix(r, c);
  }
  text << "]";
  return text.str();
}

void ExpectSameRig(const StereoCalibration& read, const StereoCalibration& rig) {
  EXPECT_EQ(read.left.params(), rig.left.params());
  EXPECT_EQ(read.right.params(), rig.right.params());
  EXPECT_EQ(read.left.width(), rig.left.width());
  EXPECT_EQ(read.right.height(), rig.right.height());
  EXPECT_LT(read.right_from_left.rotation.angularDistance(rig.right_from_left.rotation), 1e-9);
  EXPECT_LT((read.right_from_left.translation - rig.right_from_left.translation).norm(), 1e-9);  // mm
}

// Kalibr's camchain (metres, no %YAML line) and a ROS camera_info pair (ROS's own rectification,
// its projection in metres) give the rig they describe.
TEST(StereoRectification, KalibrAndRosCalibrationsGiveTheirRig) {
  const fs::path folder = UniqueTempFolder("stereo_formats");
  fs::create_directories(folder);
  StereoCalibration rig = Rig();
  rig.left = Camera::OpenCv(kWidth, kHeight, 300, 302, 161.0, 118.5, {-0.25, 0.08, 0.001, -0.0005});  // radtan: 4
  const Eigen::Matrix4d cam1_from_cam0 = rig.right_from_left.Matrix();
  const auto kalibr_camera = [](const Camera& camera) {
    const std::vector<double>& p = camera.params();
    return "  camera_model: pinhole\n  distortion_model: radtan\n  distortion_coeffs: " +
           FlowList(Eigen::Vector4d(p[4], p[5], p[6], p[7]).transpose()) +
           "\n  intrinsics: " + FlowList(Eigen::Vector4d(p[0], p[1], p[2], p[3]).transpose()) +
           "\n  resolution: [320, 240]\n  rostopic: /cam/image_raw\n";
  };
  {
    // T_cn_cnm1 in metres, one row per line.
    std::ofstream file(folder / "camchain.yaml");
    file << "cam0:\n  cam_overlaps: [1]\n" << kalibr_camera(rig.left) << "cam1:\n  T_cn_cnm1:\n";
    Eigen::Matrix4d metres = cam1_from_cam0;
    metres.topRightCorner<3, 1>() /= 1000.0;
    for (int r = 0; r < 4; ++r) file << "  - " << FlowList(metres.row(r)) << "\n";
    file << "  cam_overlaps: [0]\n" << kalibr_camera(rig.right);
  }
  ExpectSameRig(ReadStereoCalibration({folder / "camchain.yaml"}, std::nullopt, 0.0), rig);

  const auto opencv = [](const Eigen::MatrixXd& matrix) {
    cv::Mat converted;
    cv::eigen2cv(matrix, converted);
    return converted;
  };
  cv::Mat r1, r2, p1, p2, q;
  const Eigen::Vector3d metres = rig.right_from_left.translation / 1000.0;
  cv::stereoRectify(opencv(CameraMatrix(rig.left)), opencv(Distortion(rig.left)), opencv(CameraMatrix(rig.right)),
                    opencv(Distortion(rig.right)), cv::Size(kWidth, kHeight),
                    opencv(rig.right_from_left.rotation.toRotationMatrix()), opencv(metres), r1, r2, p1, p2, q,
                    cv::CALIB_ZERO_DISPARITY, 0.3);
  const auto camera_info = [&](const fs::path& file, const Camera& camera, const cv::Mat& rectification,
                               const cv::Mat& projection) {
    const auto eigen = [](const cv::Mat& matrix) {
      Eigen::MatrixXd converted;
      cv::cv2eigen(matrix, converted);
      return converted;
    };
    std::ofstream(file) << "image_width: 320\nimage_height: 240\ncamera_name: narrow_stereo\ncamera_matrix:\n  rows: "
                           "3\n  cols: 3\n  data: "
                        << FlowList(CameraMatrix(camera))
                        << "\ndistortion_model: plumb_bob\ndistortion_coefficients:\n  rows: 1\n  cols: 5\n  data: "
                        << FlowList(Distortion(camera).transpose())
                        << "\nrectification_matrix:\n  rows: 3\n  cols: 3\n  data: " << FlowList(eigen(rectification))
                        << "\nprojection_matrix:\n  rows: 3\n  cols: 4\n  data: " << FlowList(eigen(projection))
                        << "\n";
  };
  camera_info(folder / "left.yaml", rig.left, r1, p1);
  camera_info(folder / "right.yaml", rig.right, r2, p2);
  const StereoCalibration ros = ReadStereoCalibration({folder / "left.yaml", folder / "right.yaml"}, std::nullopt, 0.0);
  EXPECT_LT(ros.right_from_left.rotation.angularDistance(rig.right_from_left.rotation), 1e-9);
  EXPECT_LT((ros.right_from_left.translation - rig.right_from_left.translation).norm(), 1e-6);  // mm
  EXPECT_EQ(ros.right.params(), rig.right.params());

  // One camera_info alone is not a pair.
  EXPECT_NE(ErrorMessage([&] {
              ReadStereoCalibration({folder / "left.yaml"}, std::nullopt, 0.0);
            }).find("not a stereo calibration"),
            std::string::npos);
  fs::remove_all(folder);
}

std::string StereoError(const ImportOptions& options, const fs::path& out) {
  return ErrorMessage([&] { ImportDataset(options, out); });
}

TEST(StereoRectification, RefusesWhatCannotBeASideBySidePair) {
  const fs::path folder = UniqueTempFolder("stereo_refused");
  fs::remove_all(folder);
  WriteRecording(folder);
  ASSERT_FALSE(HasFatalFailure());
  const StereoCalibration rig = Rig();
  const auto with_translation = [&](const Eigen::Vector3d& t) {
    WriteCalibration(rig, folder / "intrinsics.yml", folder / "extrinsics.yml", t);
    return StereoError(StereoImport(folder), folder / "out");
  };
  EXPECT_NE(with_translation(Eigen::Vector3d(0.1, -5.0, 0.0)).find("above or below"), std::string::npos);
  EXPECT_NE(with_translation(Eigen::Vector3d(5.2, 0.1, 0.0)).find("swap the two cameras"), std::string::npos);
  EXPECT_NE(with_translation(Eigen::Vector3d::Zero()).find("T is zero"), std::string::npos);
  WriteCalibration(rig, folder / "intrinsics.yml", folder / "extrinsics.yml", rig.right_from_left.translation);

  ImportOptions options = StereoImport(folder);
  options.second_calibration.clear();
  EXPECT_NE(StereoError(options, folder / "out").find("no 'R'"), std::string::npos);
  options = StereoImport(folder);
  options.stereo_depth_options.block_size = 4;
  EXPECT_NE(StereoError(options, folder / "out").find("an odd block_size"), std::string::npos);
  options = StereoImport(folder);
  options.stereo_layout = "side-by-side";
  EXPECT_NE(StereoError(options, folder / "out").find("either --right"), std::string::npos);
  options.right.clear();
  options.stereo_layout = "diagonal";
  EXPECT_NE(StereoError(options, folder / "out").find("side-by-side or top-bottom"), std::string::npos);
  options = StereoImport(folder);
  options.input = folder / "both";  // twice as wide as the calibration
  WriteCalibration(rig, folder / "intrinsics.yml", folder / "extrinsics.yml", rig.right_from_left.translation, true);
  EXPECT_NE(StereoError(options, folder / "out").find("left frame 0 is 640x240 but the calibration is 320x240"),
            std::string::npos);
  options.input = folder / "left";
  options.right = folder / "both";
  EXPECT_NE(StereoError(options, folder / "out")
                .find("right frame 0 is 640x240 but the left frames and the calibration are 320x240"),
            std::string::npos);
  options = StereoImport(folder);
  fs::remove(folder / "right" / "2.png");
  EXPECT_NE(StereoError(options, folder / "out").find("the right camera has 2 frames, the left 3"), std::string::npos);
  options.format = "images";
  EXPECT_NE(StereoError(options, folder / "out").find("apply to --format stereo only"), std::string::npos);
  EXPECT_FALSE(fs::exists(folder / "out" / "sequence.json"));  // a failed import leaves no sequence

  StereoCalibration mixed = rig;
  mixed.right = Camera::KannalaBrandt(kWidth, kHeight, 150, 150, 160, 120, Eigen::Vector4d(0.01, 0, 0, 0));
  EXPECT_THROW(StereoRectifier(mixed, StereoRectificationOptions{}), Error);
  StereoCalibration ocam = rig;
  ocam.left = ocam.right = OcamFisheye();
  EXPECT_THROW(StereoRectifier(ocam, StereoRectificationOptions{}), Error);
  EXPECT_THROW(StereoRectifier(rig, StereoRectificationOptions{0, 0, 1.5}), Error);
  fs::remove_all(folder);
}

}  // namespace
}  // namespace nrslam
