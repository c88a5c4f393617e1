#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>

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

class CameraModels : public ::testing::TestWithParam<int> {
 protected:
  Camera camera() const {
    switch (GetParam()) {
      case 0: return Pinhole();
      case 1: return SimFisheye();
      case 2: return EndomapperLike();
      default: return OcamFisheye();
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

INSTANTIATE_TEST_SUITE_P(PinholeFisheyeAndOcam, CameraModels, ::testing::Values(0, 1, 2, 3));

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
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(folder / name) << text;
    return folder / name;
  };
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
  EXPECT_NE(message(Camera::KannalaBrandt(640, 480, 300, 300, 320, 240, Eigen::Vector4d(-5, 0, 0, 0))).find("fold"),
            std::string::npos);
  EXPECT_EQ(message(Pinhole()), "");
  EXPECT_THROW((nlohmann::json{{"model", "orthographic"}, {"width", 1}, {"height", 1}, {"fx", 1}, {"fy", 1},
                                {"cx", 0}, {"cy", 0}}.get<Camera>()),
               Error);
}

}  // namespace
}  // namespace nrslam
