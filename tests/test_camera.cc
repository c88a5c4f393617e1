#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>

#include <opencv2/calib3d.hpp>

#include "camera_fixtures.h"
#include "temp_folder.h"
#include "nrslam/camera/camera.h"
#include "nrslam/io/camera_file.h"
#include "nrslam/sim/renderer.h"
#include "nrslam/util/error.h"

namespace nrslam {
namespace {

Camera Pinhole() { return Camera::Pinhole(640, 480, 320.0, 318.0, 319.5, 239.5); }
// The simulator's 170° fisheye and an Endomapper-like calibration (720x540, KB8).
Camera SimFisheye() {
  SimCameraOptions options;
  options.model = "fisheye";
  return MakeSimCamera(options);
}
Camera EndomapperLike() {
  return Camera::KannalaBrandt(720, 540, 358.6052, 358.7408, 367.6783, 276.3991,
                               Eigen::Vector4d(-0.1389272, -0.001239606, 0.0009125824, -4.071615e-05));
}

std::filesystem::path WriteText(const std::filesystem::path& file, const std::string& text) {
  std::ofstream(file) << text;
  return file;
}

class CameraModels : public ::testing::TestWithParam<int> {
 protected:
  Camera camera() const {
    switch (GetParam()) {
      case 0: return Pinhole();
      case 1: return SimFisheye();
      case 2: return EndomapperLike();
      case 3: return OcamFisheye();
      case 4: return OpenCvLaparoscope();
      default: return OpenCvRational();
    }
  }
};

TEST_P(CameraModels, ProjectUnprojectRoundTripOverTheWholeImage) {
  const Camera cam = camera();
  int checked = 0;
  for (int y = 0; y < cam.height(); y += 3) {
    for (int x = 0; x < cam.width(); x += 3) {
      const Eigen::Vector2d pixel(x + 0.25, y + 0.75);
      const Eigen::Vector3d bearing = cam.Unproject(pixel);
      ASSERT_NEAR(bearing.norm(), 1.0, 1e-12);
      const double theta = std::acos(bearing.z());
      if (theta > cam.max_theta() - 1e-9) continue;  // beyond the image circle: no ray to recover
      for (double distance : {0.5, 30.0}) {
        const auto projected = cam.Project(distance * bearing);
        ASSERT_TRUE(projected.has_value()) << "pixel " << pixel.transpose();
        ASSERT_LT((*projected - pixel).norm(), 1e-6) << "pixel " << pixel.transpose();
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, cam.width() * cam.height() / 9 * 0.6);
}

TEST_P(CameraModels, PrincipalPointIsTheOpticalAxis) {
  const Camera cam = camera();
  const Eigen::Vector3d axis = cam.Unproject(Eigen::Vector2d(cam.cx(), cam.cy()));
  EXPECT_LT((axis - Eigen::Vector3d::UnitZ()).norm(), 1e-12);
  const auto pixel = cam.Project(Eigen::Vector3d(0, 0, 5));
  ASSERT_TRUE(pixel.has_value());
  EXPECT_LT((*pixel - Eigen::Vector2d(cam.cx(), cam.cy())).norm(), 1e-12);
  // Jacobian on the axis is finite (no division by the radial distance).
  EXPECT_TRUE(cam.ProjectionJacobian(Eigen::Vector3d(0, 0, 5)).allFinite());
}

TEST_P(CameraModels, ProjectionJacobianMatchesNumericDifferences) {
  const Camera cam = camera();
  for (const Eigen::Vector3d& point : {Eigen::Vector3d(0.1, -0.2, 2.0), Eigen::Vector3d(-3.0, 1.0, 4.0),
                                      Eigen::Vector3d(1e-9, 0, 1.0), Eigen::Vector3d(0.5, 0.4, 0.3)}) {
    if (!cam.Project(point)) continue;
    const Eigen::Matrix<double, 2, 3> analytic = cam.ProjectionJacobian(point);
    constexpr double h = 1e-6;
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d plus = point, minus = point;
      plus[k] += h;
      minus[k] -= h;
      const Eigen::Vector2d numeric = (*cam.Project(plus) - *cam.Project(minus)) / (2 * h);
      EXPECT_LT((analytic.col(k) - numeric).norm(), 1e-5 * (1 + numeric.norm()))
          << "point " << point.transpose() << " column " << k;
    }
  }
}

TEST_P(CameraModels, JsonRoundTrip) {
  const Camera cam = camera();
  const Camera back = nlohmann::json(cam).get<Camera>();
  EXPECT_EQ(back.model(), cam.model());
  EXPECT_EQ(back.width(), cam.width());
  EXPECT_EQ(back.height(), cam.height());
  EXPECT_EQ(back.params(), cam.params());
}

// A camera resized with its images (halved, as the reference halves Endomapper's video, and
// scaled unevenly, which rounding to whole pixels can do) sees every ray where the resized
// image has that ray's pixel.
TEST_P(CameraModels, ResizedItSeesEachRayWhereTheResizedImageHasIt) {
  const Camera cam = camera();
  for (const auto& [width, height] : {std::pair(cam.width() / 2, cam.height() / 2),
                                      std::pair(static_cast<int>(cam.width() * 0.5), static_cast<int>(cam.height() * 0.6))}) {
    const Camera resized = cam.Resized(width, height);
    ASSERT_NO_THROW(resized.Check());
    EXPECT_EQ(resized.model(), cam.model());
    const Eigen::Array2d scale(static_cast<double>(width) / cam.width(), static_cast<double>(height) / cam.height());
    int checked = 0;
    for (int y = 0; y < cam.height(); y += 7) {
      for (int x = 0; x < cam.width(); x += 7) {
        const Eigen::Vector2d pixel(x + 0.25, y + 0.75);
        const Eigen::Vector3d ray = cam.Unproject(pixel);
        if (std::acos(ray.z()) > cam.max_theta() - 1e-9) continue;  // beyond the image circle
        const Eigen::Vector2d expected = ((pixel.array() + 0.5) * scale - 0.5).matrix();
        if (!resized.InImage(expected)) continue;  // past the resized image's outermost pixel centres
        const auto projected = resized.Project(20.0 * ray);
        ASSERT_TRUE(projected.has_value()) << pixel.transpose();
        ASSERT_LT((*projected - expected).norm(), 1e-6) << pixel.transpose() << " to " << width << "x" << height;
        ASSERT_LT((resized.Unproject(expected) - ray).norm(), 1e-8) << pixel.transpose();
        ++checked;
      }
    }
    EXPECT_GT(checked, cam.width() * cam.height() / 49 / 2);
  }
  EXPECT_THROW(cam.Resized(0, 10), Error);
}

INSTANTIATE_TEST_SUITE_P(EveryModel, CameraModels, ::testing::Values(0, 1, 2, 3, 4, 5));

// OpenCV itself is the reference for its model: cv::projectPoints for the projection and
// cv::undistortPoints (iterated to convergence) for the unprojection.
TEST(OpenCvModel, ProjectsAndUnprojectsAsOpenCvDoes) {
  for (const Camera& camera : {OpenCvLaparoscope(), OpenCvRational()}) {
    const std::vector<double>& p = camera.params();
    const cv::Matx33d k(p[0], 0, p[2], 0, p[1], p[3], 0, 0, 1);
    const std::vector<double> distortion(p.begin() + OpenCvModel::kDistortionOffset, p.end());
    std::vector<cv::Point3d> points;
    for (int i = 0; i < 200; ++i) {
      // Up to 55° off the axis, 5–100 mm deep.
      const double angle = 0.96 * (i % 20) / 19.0, azimuth = 0.37 * i, depth = 5 + i * 0.47;
      points.emplace_back(depth * std::tan(angle) * std::cos(azimuth), depth * std::tan(angle) * std::sin(azimuth),
                          depth);
    }
    std::vector<cv::Point2d> expected;
    cv::projectPoints(points, cv::Vec3d::all(0), cv::Vec3d::all(0), k, distortion, expected);
    std::vector<cv::Point2d> normalised;
    cv::undistortPoints(expected, normalised, k, distortion, cv::noArray(), cv::noArray(),
                        cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 1000, 1e-15));
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d point(points[i].x, points[i].y, points[i].z);
      const auto pixel = camera.Project(point);
      ASSERT_TRUE(pixel.has_value()) << point.transpose();
      EXPECT_LT((*pixel - Eigen::Vector2d(expected[i].x, expected[i].y)).norm(), 1e-9) << point.transpose();
      const Eigen::Vector3d ray = camera.Unproject(*pixel);
      EXPECT_LT((ray - point.normalized()).norm(), 1e-10) << point.transpose();
      EXPECT_LT((ray / ray.z() - Eigen::Vector3d(normalised[i].x, normalised[i].y, 1)).norm(), 1e-7)
          << point.transpose();
    }
  }
}

TEST(OpenCvModel, WithoutDistortionItIsThePinholeCamera) {
  const Camera plain = Camera::OpenCv(640, 480, 320.0, 318.0, 319.5, 239.5, {0, 0, 0, 0, 0});
  const Camera pinhole = Pinhole();
  EXPECT_EQ(plain.max_theta(), pinhole.max_theta());
  for (const Eigen::Vector3d& point : {Eigen::Vector3d(0.1, -0.2, 2.0), Eigen::Vector3d(-3.0, 1.0, 4.0),
                                      Eigen::Vector3d(40.0, 30.0, 1.0)}) {
    EXPECT_LT((*plain.Project(point) - *pinhole.Project(point)).norm(), 1e-10);
    const Eigen::Vector2d pixel = *pinhole.Project(point);
    EXPECT_LT((plain.Unproject(pixel) - pinhole.Unproject(pixel)).norm(), 1e-12);
  }
}

// Past the fold of its radial distortion the model is not one-to-one: such directions are
// outside the field of view, and pixels beyond the largest radius it reaches get its edge ray.
TEST(OpenCvModel, TheFieldOfViewEndsWhereTheDistortionFolds) {
  const Camera camera = OpenCvLaparoscope();
  // r(1 − 0.3r² + 0.1r⁴ − 0.01r⁶) stops growing at r ≈ 2.28 (66.3°).
  EXPECT_NEAR(camera.max_theta(), std::atan(2.28), 2e-3);
  EXPECT_FALSE(camera.Project(Eigen::Vector3d(3.0, 0.0, 1.0)).has_value());
  const Eigen::Vector3d edge = camera.Unproject(Eigen::Vector2d(camera.cx() + 5 * camera.fx(), camera.cy()));
  EXPECT_NEAR(std::acos(edge.z()), camera.max_theta(), 1e-9);
  EXPECT_GT(edge.x(), 0.0);
}

TEST(OpenCvModel, WrongCalibrationsAreNamed) {
  const auto message = [](const std::function<Camera()>& make) {
    try {
      make().Check();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  // The same lens with a focal length that puts the corners past the fold.
  EXPECT_NE(message([] { return Camera::OpenCv(640, 480, 200, 200, 319.5, 239.5, {-0.30, 0.10, 0, 0, -0.01}); })
                .find("folds back inside the image"),
            std::string::npos);
  EXPECT_NE(message([] { return Camera::OpenCv(640, 480, 360, 360, 319.5, 239.5, {-0.3, 0.1, 0, 0, 0, 0}); })
                .find("4, 5 or 8"),
            std::string::npos);
  EXPECT_NE(message([] { return Camera::OpenCv(640, 480, 360, 360, 319.5, 239.5, std::vector<double>(14, 0.0)); })
                .find("tilted"),
            std::string::npos);
  EXPECT_EQ(message(OpenCvLaparoscope), "accepted");
}

TEST(Fisheye, SimulatorLensCoversAtLeast160DegreesAndRoundTripsAtItsEdge) {
  const Camera cam = SimFisheye();
  EXPECT_GE(cam.max_theta(), 80.0 * M_PI / 180.0);
  for (double degrees : {60.0, 75.0, 80.0, 84.9}) {
    const double theta = degrees * M_PI / 180.0;
    for (double azimuth : {0.0, 1.0, 2.5, 4.0}) {
      const Eigen::Vector3d bearing(std::sin(theta) * std::cos(azimuth), std::sin(theta) * std::sin(azimuth),
                                    std::cos(theta));
      const auto pixel = cam.Project(bearing);
      ASSERT_TRUE(pixel.has_value()) << degrees << " deg";
      EXPECT_LT((cam.Unproject(*pixel) - bearing).norm(), 1e-9) << degrees << " deg";
    }
  }
  // The 85° edge of the image circle lies inside the image along the diagonal and the image
  // spans at least 160° across its width.
  const double diagonal = std::atan2(cam.height(), cam.width());
  const double edge_angle = 85 * M_PI / 180;
  const auto edge = cam.Project(Eigen::Vector3d(std::sin(edge_angle) * std::cos(diagonal),
                                                std::sin(edge_angle) * std::sin(diagonal), std::cos(edge_angle)));
  ASSERT_TRUE(edge.has_value());
  EXPECT_TRUE(cam.InImage(*edge));
  const Eigen::Vector3d left = cam.Unproject(Eigen::Vector2d(0, cam.cy()));
  const Eigen::Vector3d right = cam.Unproject(Eigen::Vector2d(cam.width() - 1, cam.cy()));
  EXPECT_GE(std::acos(left.dot(right)), 160 * M_PI / 180);
}

TEST(Ocam, RaysAgreeWithOCamCalibsDirectPolynomial) {
  const Camera cam = OcamFisheye();
  cam.Check();
  // Rays of OCamCalib's cam2world (direct polynomial, its axes swapped into ours), worked out
  // apart from this code; the model inverts the inverse polynomial, which agrees to ~0.002 px.
  const struct {
    double u, v;
    Eigen::Vector3d ray;
  } known[] = {{400, 0, {-0.059568, -0.981722, 0.180757}},
               {0, 0, {-0.594919, -0.549548, -0.586573}},
               {700, 600, {0.745340, 0.564661, 0.354439}},
               {523.714757, 390.949324, {0.340009, 0.000111, 0.940422}}};
  for (const auto& [u, v, ray] : known) {
    EXPECT_LT((cam.Unproject(Eigen::Vector2d(u, v)) - ray).norm(), 2e-5) << u << ", " << v;
  }
  EXPECT_NEAR(cam.max_theta() * 180 / M_PI, 128.456, 0.01);  // the bottom-left corner
  EXPECT_NEAR(cam.fx(), 289.37, 0.01);                      // invpol' on the axis, px per radian
  EXPECT_TRUE(cam.Project(Eigen::Vector3d(1, 0, -0.5)).has_value()) << "a ray 117° off the axis is in view";
  EXPECT_FALSE(cam.Project(Eigen::Vector3d(0.1, 0, -1)).has_value()) << "174° off the axis is not";
}

TEST(Ocam, AKannalaBrandtCameraInOCamCalibsTermsProjectsAndUnprojectsAlike) {
  // The simulator's lens, and one with non-square pixels and its centre off the middle (the
  // Endomapper-like calibration folds back before its corners, so no OCam model covers its image).
  const Camera oblong = Camera::KannalaBrandt(640, 480, 223.0, 227.5, 331.2, 228.7, Eigen::Vector4d(-0.02, 0.002, 0, 0));
  for (const Camera& kb : {SimFisheye(), oblong}) {
    const Camera ocam = OcamFromKannalaBrandt(kb);
    ocam.Check();
    int checked = 0;
    for (int y = 0; y < kb.height(); y += 7) {
      for (int x = 0; x < kb.width(); x += 7) {
        const Eigen::Vector2d pixel(x + 0.3, y + 0.6);
        const Eigen::Vector3d ray = kb.Unproject(pixel);
        if (std::acos(ray.z()) > std::min(kb.max_theta(), ocam.max_theta()) - 1e-6) continue;
        ASSERT_LT((ocam.Unproject(pixel) - ray).norm(), 1e-9) << pixel.transpose();
        const auto projected = ocam.Project(3.0 * ray);
        ASSERT_TRUE(projected.has_value());
        ASSERT_LT((*projected - pixel).norm(), 1e-8) << pixel.transpose();
        ASSERT_LT((ocam.ProjectionJacobian(ray) - kb.ProjectionJacobian(ray)).norm(), 1e-7) << pixel.transpose();
        ++checked;
      }
    }
    EXPECT_GT(checked, kb.width() * kb.height() / 49 / 2);
  }
}

TEST(Ocam, WrongCalibrationsAreNamed) {
  auto message = [](const std::function<Camera()>& make) {
    try {
      make().Check();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(message(OcamFisheye), "");
  EXPECT_NE(message([] {
              return Camera::Ocam(848, 800, 390.949324, 423.714757, 0.999134, -0.000325, -0.000071, kOcamDirect,
                                  kOcamInverse);
            }).find("disagree"),
            std::string::npos)
      << "centre's row and column swapped";
  std::vector<double> positive = kOcamDirect;
  positive[0] = 289.5569;
  EXPECT_NE(message([&] { return Camera::Ocam(848, 800, 423.7, 390.9, 1, 0, 0, positive, kOcamInverse); })
                .find("must be negative"),
            std::string::npos);
  EXPECT_NE(message([] { return Camera::Ocam(848, 800, 423.7, 390.9, 1, 0, 0, {}, kOcamInverse); }).find("coefficients"),
            std::string::npos);
  nlohmann::json json = OcamFisheye();
  json.erase("ss");
  EXPECT_NE(message([&] { return json.get<Camera>(); }).find("missing field 'ss'"), std::string::npos);
}

TEST(Ocam, WithoutAnInversePolynomialOneIsFittedToTheDirectOne) {
  // Some calibrations give only ss; OCamCalib's own fit of invpol is then redone.
  const Camera published = OcamFisheye();
  nlohmann::json json = published;
  json.erase("invpol");
  const Camera fitted = json.get<Camera>();
  EXPECT_EQ(fitted.params(), Camera::Ocam(848, 800, 423.714757, 390.949324, 0.999134, -0.000325, -0.000071,
                                          kOcamDirect, {}).params());
  double worst = 0;
  for (int y = 0; y < published.height(); y += 16) {
    for (int x = 0; x < published.width(); x += 16) {
      const auto pixel = fitted.Project(published.Unproject(Eigen::Vector2d(x, y)));
      ASSERT_TRUE(pixel.has_value());
      worst = std::max(worst, (*pixel - Eigen::Vector2d(x, y)).norm());
    }
  }
  // The published invpol itself agrees with ss to ~0.002 px; the fit is held to 0.01 px.
  EXPECT_LT(worst, 0.015);
  EXPECT_NEAR(fitted.max_theta(), published.max_theta(), 1e-4);
}

TEST(Ocam, CalibResultsTxtIsReadAsOCamCalibWritesIt) {
  const auto folder = UniqueTempFolder("ocam_file");
  std::filesystem::create_directories(folder);
  const auto write = [&](const std::string& name, const std::string& text) { return WriteText(folder / name, text); };
  const std::string header =
      "#polynomial coefficients for the DIRECT mapping function (ocam_model.ss in MATLAB). These are used by "
      "cam2world\n\n5 -2.895569e+02 0.000000e+00 1.538894e-03 -3.140320e-06 7.206996e-09 \n\n"
      "#polynomial coefficients for the inverse mapping function (ocam_model.invpol in MATLAB). These are used by "
      "world2cam\n\n13 434.372025 226.016722 -31.205890 43.418508 11.945692 -5.582063 36.541804 -10.674868 "
      "-55.334360 1.105775 43.550131 25.374995 4.505945 \n\n"
      "#center: \"row\" and \"column\", starting from 0 (C convention)\n\n390.949324 423.714757\n\n";
  const std::string tail = "#affine parameters \"c\", \"d\", \"e\"\n\n0.999134 -0.000325 -0.000071\n\n"
                           "#image size: \"height\" and \"width\"\n\n800 848\n";
  const Camera camera = ReadCameraFile(write("calib_results.txt", header + tail));
  EXPECT_EQ(camera.model(), CameraModelId::kOcam);
  EXPECT_EQ(camera.width(), 848);
  EXPECT_EQ(camera.height(), 800);
  EXPECT_EQ(camera.params(), OcamFisheye().params());

  const auto message = [&](const std::string& text) {
    try {
      ReadCameraFile(write("broken.txt", text));
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message(header).find("expected 5 lines of numbers"), std::string::npos);
  std::string miscounted = header + tail;
  miscounted.replace(miscounted.find("\n13 "), 4, "\n12 ");
  EXPECT_NE(message(miscounted).find("inverse polynomial (invpol): the first number must count"), std::string::npos);
  EXPECT_NE(message(header + tail.substr(0, tail.find("800"))  + "800 x\n").find("image size"), std::string::npos);
  EXPECT_EQ(message(header + tail), "");
  EXPECT_NE(message(header + tail.substr(0, tail.find("800"))).find((folder / "broken.txt").string()),
            std::string::npos)
      << "the file is named";
  std::filesystem::remove_all(folder);
}

// Calibration files as OpenCV's calibration sample (YAML and XML), a stereo rig (the left
// camera's M1 / D1), cv::fisheye and ROS's camera_info write them.
TEST(OpenCvModel, CalibrationFilesAreReadAsOpenCvAndRosWriteThem) {
  const auto folder = UniqueTempFolder("opencv_calibration");
  std::filesystem::create_directories(folder);
  const Camera lens = OpenCvLaparoscope();
  const std::vector<double>& p = lens.params();
  const cv::Mat k = (cv::Mat_<double>(3, 3) << p[0], 0, p[2], 0, p[1], p[3], 0, 0, 1);
  const cv::Mat five = (cv::Mat_<double>(5, 1) << p[4], p[5], p[6], p[7], p[8]);
  for (const char* name : {"camera.yml", "camera.xml"}) {
    cv::FileStorage storage((folder / name).string(), cv::FileStorage::WRITE);
    storage << "calibration_time" << "Fri Dec  4 08:00:00 2026" << "image_width" << 640 << "image_height" << 480
            << "camera_matrix" << k << "distortion_coefficients" << five << "avg_reprojection_error" << 0.21;
  }
  for (const char* name : {"camera.yml", "camera.xml"}) {
    const Camera read = ReadCameraFile(folder / name);
    EXPECT_EQ(read.model(), CameraModelId::kOpenCv) << name;
    EXPECT_EQ(read.params(), lens.params()) << name;
    EXPECT_EQ(read.width(), 640);
  }
  {
    cv::FileStorage storage((folder / "stereo.yaml").string(), cv::FileStorage::WRITE);
    const cv::Mat rational = (cv::Mat_<double>(1, 8) << 0.2, 0.01, 0.0008, -0.0006, 0.0005, 0.4, 0.02, 0.001);
    storage << "image_size" << cv::Size(640, 480) << "M1" << k << "D1" << rational << "M2" << k << "D2" << rational;
  }
  EXPECT_EQ(ReadCameraFile(folder / "stereo.yaml").params(), OpenCvRational().params());
  {
    cv::FileStorage storage((folder / "fisheye.yml").string(), cv::FileStorage::WRITE);
    storage << "image_width" << 720 << "image_height" << 540 << "distortion_model" << "equidistant"
            << "K" << (cv::Mat_<double>(3, 3) << 358.6052, 0, 367.6783, 0, 358.7408, 276.3991, 0, 0, 1)
            << "D" << (cv::Mat_<double>(4, 1) << -0.1389272, -0.001239606, 0.0009125824, -4.071615e-05);
  }
  const Camera fisheye = ReadCameraFile(folder / "fisheye.yml");
  EXPECT_EQ(fisheye.model(), CameraModelId::kKannalaBrandt);
  EXPECT_EQ(fisheye.params(), EndomapperLike().params());

  const auto write = [&](const std::string& name, const std::string& text) { return WriteText(folder / name, text); };
  const std::string ros =
      "image_width: 640\nimage_height: 480\ncamera_name: laparoscope_left\n"
      "camera_matrix:\n  rows: 3\n  cols: 3\n  data: [360.0, 0.0, 322.4, 0.0, 362.5, 236.8, 0.0, 0.0, 1.0]\n"
      "distortion_model: plumb_bob\n"
      "distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [-0.30, 0.10, 0.0008, -0.0006, -0.01]\n"
      "rectification_matrix:\n  rows: 3\n  cols: 3\n  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n";
  EXPECT_EQ(ReadCameraFile(write("ros.yaml", ros)).params(), lens.params());
  std::string plain = ros;
  plain.replace(plain.find("[-0.30"), plain.find("]\nrect") - plain.find("[-0.30"), "[0, 0, 0, 0, 0");
  EXPECT_EQ(ReadCameraFile(write("plain.yaml", plain)).model(), CameraModelId::kPinhole);

  const auto message = [&](const std::string& text) {
    try {
      ReadCameraFile(write("broken.yaml", text));
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  std::string four = ros;
  four.replace(four.find("distortion_model: plumb_bob\n"), 28, "");
  four.replace(four.find(", -0.01]"), 8, "]");
  EXPECT_NE(message(four).find("say which with distortion_model"), std::string::npos);
  EXPECT_NE(message(ros.substr(ros.find("camera_name"))).find("no image size"), std::string::npos);
  std::string skewed = ros;
  skewed.replace(skewed.find("360.0, 0.0"), 10, "360.0, 0.5");
  EXPECT_NE(message(skewed).find("no skew"), std::string::npos);
  std::string unknown = ros;
  unknown.replace(unknown.find("plumb_bob"), 9, "division");
  EXPECT_NE(message(unknown).find("unknown distortion_model 'division'"), std::string::npos);
  std::string not_finite = ros;
  not_finite.replace(not_finite.find("-0.30"), 5, ".nan");
  EXPECT_NE(message(not_finite).find("'distortion_coefficients' holds a value that is not finite"), std::string::npos);
  EXPECT_NE(message("image_width: [640\n").find((folder / "broken.yaml").string()), std::string::npos)
      << "a file OpenCV cannot parse is named";
  std::filesystem::remove_all(folder);
}

TEST(CameraModels, KannalaBrandtUnprojectsPastWhereNewtonFails) {
  // Strong coefficients (r(θ) folds back at 0.775 rad): Newton from the undistorted angle lands
  // beyond the fold at the image's edge; the ray found instead must project back to the pixel.
  const Camera squeezed = Camera::KannalaBrandt(320, 240, 160, 160, 159.5, 119.5, Eigen::Vector4d(1e9, -1e9, 3, 4));
  for (const Eigen::Vector2d& pixel :
       {Eigen::Vector2d(0, 119.5), Eigen::Vector2d(319, 0), Eigen::Vector2d(200, 119.5)}) {
    const std::optional<Eigen::Vector2d> back = squeezed.Project(squeezed.Unproject(pixel));
    ASSERT_TRUE(back.has_value()) << pixel.transpose();
    EXPECT_LT((*back - pixel).norm(), 1e-6) << pixel.transpose();
  }
}

TEST(CameraCheck, RejectsWrongCalibrations) {
  auto message = [](const Camera& camera) {
    try {
      camera.Check();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message(Camera::Pinhole(640, 480, -300, 300, 320, 240)).find("focal length"), std::string::npos);
  EXPECT_NE(message(Camera::Pinhole(0, 480, 300, 300, 320, 240)).find("image size"), std::string::npos);
  EXPECT_NE(message(Camera::Pinhole(640, 480, 300, 300, 900, 240)).find("principal point"), std::string::npos);
  EXPECT_NE(message(Camera::Pinhole(640, 480, NAN, 300, 320, 240)).find("finite"), std::string::npos);
  EXPECT_NE(message(Camera::Pinhole(640, 480, 1e12, 1e12, 320, 240)).find("intrinsics of another image size or unit?"),
            std::string::npos);
  EXPECT_NE(message(Camera::Pinhole(640, 480, 3000, 300, 320, 240)).find("differ by more than 4 times"),
            std::string::npos);
  EXPECT_EQ(message(Camera::Pinhole(720, 288, 800, 400, 360, 144)), "");  // an interlaced field
  // Intrinsics normalised by the image size, or a focal length in mm: a view no lens gives.
  EXPECT_NE(message(Camera::Pinhole(640, 480, 0.8, 1.07, 320, 240)).find("under 1/20 of the 640x480 image"),
            std::string::npos);
  EXPECT_NE(message(Camera::KannalaBrandt(640, 480, 3.2, 3.2, 320, 240, Eigen::Vector4d::Zero())).find("under 1/20"),
            std::string::npos);
  EXPECT_EQ(message(Camera::KannalaBrandt(640, 480, 110, 110, 320, 240, Eigen::Vector4d::Zero())), "")
      << "a 235-degree fisheye whose image circle fits the image's height";
  EXPECT_NE(message(Camera::KannalaBrandt(640, 480, 300, 300, 320, 240, Eigen::Vector4d(-5, 0, 0, 0))).find("fold"),
            std::string::npos);
  // Coefficients that pass the fold-back test but squeeze the image into a hundredth of a degree.
  EXPECT_NE(message(Camera::KannalaBrandt(320, 240, 160, 160, 159.5, 119.5, Eigen::Vector4d(1e9, -1e9, 3, 4)))
                .find("degrees of view"),
            std::string::npos);
  EXPECT_NE(message(Camera::OpenCv(320, 240, 160, 160, 159.5, 119.5, {1e8, 0, 0, 0})).find("degrees of view"),
            std::string::npos);
  EXPECT_EQ(message(Camera::OpenCv(320, 240, 160, 160, 159.5, 119.5, {50, 100, 0, 0, 200})), "")
      << "a 15-degree view is narrow, not wrong";
  EXPECT_EQ(message(Pinhole()), "");
  EXPECT_THROW((nlohmann::json{{"model", "orthographic"}, {"width", 1}, {"height", 1}, {"fx", 1}, {"fy", 1},
                                {"cx", 0}, {"cy", 0}}.get<Camera>()),
               Error);
}

TEST(CameraJson, AKeyTheModelDoesNotReadIsRefusedNotPassedOver) {
  const auto message = [](const std::function<void(nlohmann::json&)>& change) {
    nlohmann::json json = Pinhole();
    change(json);
    try {
      json.get<Camera>();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(message([](nlohmann::json&) {}), "");
  // Before, each of these was read as the plain pinhole camera, the lens or skew ignored.
  EXPECT_EQ(message([](nlohmann::json& j) { j["distortion"] = {-0.3, 0.1, 0, 0}; }),
            "camera: model pinhole takes no 'distortion'; model opencv does (docs/data.md, \"Sequence format\")");
  EXPECT_EQ(message([](nlohmann::json& j) { j["k"] = {0.01, 0, 0, 0}; }),
            "camera: model pinhole takes no 'k'; model kannala_brandt does (docs/data.md, \"Sequence format\")");
  EXPECT_EQ(message([](nlohmann::json& j) { j["skew"] = 0.5; }),
            "camera (model pinhole): unknown key 'skew'; known keys: model, width, height, cx, cy, fx, fy");
  EXPECT_EQ(message([](nlohmann::json& j) {
              j["model"] = "opencv";
              j["distortion"] = {0, 0, 0, 0};
              j["distorsion"] = {0, 0, 0, 0};
            }),
            "camera (model opencv): unknown key 'distorsion'; did you mean distortion?");
  EXPECT_EQ(message([](nlohmann::json& j) { j["model"] = "fisheye"; }),
            "camera: unknown camera model 'fisheye' (known: pinhole, kannala_brandt, opencv, ocam); fisheye is "
            "kannala_brandt here");
  EXPECT_EQ(message([](nlohmann::json& j) { j["model"] = "perspective"; }),
            "camera: unknown camera model 'perspective' (known: pinhole, kannala_brandt, opencv, ocam)");
  // Coefficients one key each, as many calibration files write them, with any model.
  EXPECT_EQ(message([](nlohmann::json& j) { j["k1"] = -0.2; }),
            "camera: unknown key 'k1': lens coefficients go in one list, \"distortion\": [k1, k2, p1, p2, k3] with "
            "model opencv (OpenCV's order), or \"k\": [k0, k1, k2, k3] with model kannala_brandt");
}

}  // namespace
}  // namespace nrslam
