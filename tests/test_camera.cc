#include <gtest/gtest.h>

#include "nrslam/camera/camera.h"
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
      default: return EndomapperLike();
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

INSTANTIATE_TEST_SUITE_P(PinholeAndFisheye, CameraModels, ::testing::Values(0, 1, 2));

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
