// Every cost functor: Ceres GradientChecker at random points (autodiff against numeric
// differences through the manifolds), and known energies for both weightings.
#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <memory>

#include "camera_fixtures.h"
#include "nrslam/camera/reprojection_cost.h"
#include "nrslam/deformation/regularizer_costs.h"
#include "nrslam/geometry/two_view.h"
#include "nrslam/geometry/se3_manifold.h"
#include "nrslam/sim/renderer.h"
#include "nrslam/util/random.h"

namespace nrslam {
namespace {

Eigen::Vector3d RandomVector(Rng& rng, double scale) {
  return Eigen::Vector3d(rng.Uniform(-scale, scale), rng.Uniform(-scale, scale), rng.Uniform(-scale, scale));
}

PoseParams RandomPose(Rng& rng) {
  const Eigen::Quaterniond rotation(Eigen::AngleAxisd(rng.Uniform(0, 0.5), RandomVector(rng, 1).normalized()));
  return Rigid3(rotation, RandomVector(rng, 0.5)).ToParams();
}

void ExpectGradientsMatch(const ceres::CostFunction& cost, const std::vector<const ceres::Manifold*>& manifolds,
                          std::vector<double*> parameters) {
  ceres::NumericDiffOptions numeric;
  // GradientChecker extrapolates with Ridders from 1 % steps by default: too coarse where a
  // residual is normalised (the epipolar angle) and bends sharply.
  numeric.ridders_relative_initial_step_size = 1e-4;
  ceres::GradientChecker checker(&cost, &manifolds, numeric);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(parameters.data(), 1e-6, &results)) << results.error_log;
}

std::vector<Camera> Cameras() {
  SimCameraOptions fisheye;
  fisheye.model = "fisheye";
  return {Camera::Pinhole(640, 480, 320, 318, 319.5, 239.5), MakeSimCamera(fisheye), OcamFisheye(), OpenCvLaparoscope(),
          OpenCvRational()};
}

TEST(ReprojectionCost, GradientsAtRandomPointsForEveryCameraModel) {
  Rng rng(3);
  const Se3Manifold se3;
  for (const Camera& camera : Cameras()) {
    for (int trial = 0; trial < 20; ++trial) {
      PoseParams pose = RandomPose(rng);
      const Rigid3 cam_from_world = Rigid3::FromParams(pose.data());
      // A point 1–5 units in front, within ±35° (pinhole, OpenCV) / ±70° (fisheye) of the axis.
      const bool fisheye = camera.model() == CameraModelId::kKannalaBrandt || camera.model() == CameraModelId::kOcam;
      const double reach = fisheye ? 2.5 : 0.7;
      const Eigen::Vector3d in_camera = rng.Uniform(1, 5) * Eigen::Vector3d(rng.Uniform(-reach, reach) * 0.5,
                                                                              rng.Uniform(-reach, reach) * 0.5, 1.0);
      Eigen::Vector3d point = cam_from_world.Inverse() * in_camera;
      const Eigen::Vector2d observed = *camera.Project(in_camera) + Eigen::Vector2d(rng.Normal(), rng.Normal());
      std::unique_ptr<ceres::CostFunction> cost(CreateReprojectionCost(camera, observed, 0.5));
      ExpectGradientsMatch(*cost, {&se3, nullptr}, {pose.data(), point.data()});

      Eigen::Vector3d displacement = RandomVector(rng, 0.05);
      std::unique_ptr<ceres::CostFunction> deformed(CreateDeformedReprojectionCost(camera, observed, point, 0.5));
      ExpectGradientsMatch(*deformed, {&se3, nullptr}, {pose.data(), displacement.data()});
      // Same residual as the rigid functor at the moved point.
      Eigen::Vector3d moved = point + displacement;
      const double* deformed_parameters[2] = {pose.data(), displacement.data()};
      const double* rigid_parameters[2] = {pose.data(), moved.data()};
      Eigen::Vector2d deformed_residual, rigid_residual;
      ASSERT_TRUE(deformed->Evaluate(deformed_parameters, deformed_residual.data(), nullptr));
      ASSERT_TRUE(cost->Evaluate(rigid_parameters, rigid_residual.data(), nullptr));
      EXPECT_LT((deformed_residual - rigid_residual).norm(), 1e-9);
    }
  }
}

TEST(ReprojectionCost, ResidualIsPixelErrorOverSigma) {
  const Camera camera = Camera::Pinhole(640, 480, 300, 300, 320, 240);
  PoseParams identity = Rigid3().ToParams();
  double point[3] = {0.1, -0.2, 2.0};  // projects to (335, 210)
  std::unique_ptr<ceres::CostFunction> cost(CreateReprojectionCost(camera, Eigen::Vector2d(336, 208), 0.5));
  const double* parameters[2] = {identity.data(), point};
  double residual[2];
  ASSERT_TRUE(cost->Evaluate(parameters, residual, nullptr));
  EXPECT_NEAR(residual[0], 2.0, 1e-12);
  EXPECT_NEAR(residual[1], -4.0, 1e-12);
  double behind[3] = {0, 0, -1};
  const double* behind_parameters[2] = {identity.data(), behind};
  EXPECT_FALSE(cost->Evaluate(behind_parameters, residual, nullptr));
}

TEST(EpipolarCost, GradientsAtRandomPosesAndZeroOnTheEpipolarPlane) {
  Rng rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    const Rigid3 pose = Rigid3::FromParams(RandomPose(rng).data());
    const Eigen::AngleAxisd angle_axis(pose.rotation);
    Eigen::Vector3d rotation = angle_axis.angle() * angle_axis.axis();
    Eigen::Vector3d translation = RandomVector(rng, 1).normalized();
    const Eigen::Vector3d point = RandomVector(rng, 1) + Eigen::Vector3d(0, 0, 4);
    const Eigen::Vector3d reference = point.normalized();
    const Eigen::Vector3d current = (pose.rotation * point + translation).normalized();
    std::unique_ptr<ceres::CostFunction> exact(EpipolarCost::Create(reference, current));
    double residual = 1;
    const double* parameters[2] = {rotation.data(), translation.data()};
    ASSERT_TRUE(exact->Evaluate(parameters, &residual, nullptr));
    EXPECT_NEAR(residual, 0.0, 1e-12);
    const Eigen::Vector3d off_plane = (current + RandomVector(rng, 0.05)).normalized();
    std::unique_ptr<ceres::CostFunction> cost(EpipolarCost::Create(reference, off_plane));
    // Ambient derivatives: the functor is smooth off the unit sphere too, and Ceres's sphere
    // manifold is not ours to test.
    ExpectGradientsMatch(*cost, {nullptr, nullptr}, {rotation.data(), translation.data()});
  }
}

double SquaredResidual(const ceres::CostFunction& cost, const std::vector<const double*>& parameters);

TEST(RegularizerCosts, GradientsAtRandomPoints) {
  Rng rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::Vector3d p_i = RandomVector(rng, 0.1), p_j = RandomVector(rng, 0.1);
    const Eigen::Vector3d base_i = RandomVector(rng, 2.0), base_j = RandomVector(rng, 2.0);
    std::unique_ptr<ceres::CostFunction> elastic(ElasticCost::Create(base_i, base_j, rng.Uniform(0.5, 2), 1.7));
    ExpectGradientsMatch(*elastic, {nullptr, nullptr}, {p_i.data(), p_j.data()});
    std::unique_ptr<ceres::CostFunction> viscous(ViscousCost::Create(0.8));
    ExpectGradientsMatch(*viscous, {nullptr, nullptr}, {p_i.data(), p_j.data()});
    Eigen::Vector3d a = RandomVector(rng, 1), b = RandomVector(rng, 1), c = RandomVector(rng, 1), d = RandomVector(rng, 1);
    std::unique_ptr<ceres::CostFunction> keyframes(ViscousKeyframeCost::Create(1.3));
    ExpectGradientsMatch(*keyframes, {nullptr, nullptr, nullptr, nullptr}, {a.data(), b.data(), c.data(), d.data()});
    std::unique_ptr<ceres::CostFunction> flow(NeighbourFlowCost::Create(RandomVector(rng, 0.2), 2.5));
    ExpectGradientsMatch(*flow, {nullptr, nullptr}, {a.data(), b.data()});
  }
}

TEST(RegularizerCosts, NeighbourFlowEqualsTheSumOverNeighboursUpToAConstant) {
  // Σ_n ‖m − f_n‖²/σ² = N‖m − mean f‖²/σ² + Σ_n ‖f_n − mean f‖²/σ²: the cost with
  // c = √N/σ must differ from the explicit sum by a constant, whatever the motion m.
  const std::vector<Eigen::Vector3d> flows = {{0.1, 0, 0}, {0.12, 0.01, 0}, {0.08, -0.02, 0.01}};
  const double sigma = 0.1;
  const Eigen::Vector3d mean = (flows[0] + flows[1] + flows[2]) / 3.0;
  std::unique_ptr<ceres::CostFunction> cost(NeighbourFlowCost::Create(mean, std::sqrt(3.0) / sigma));
  const Eigen::Vector3d x_a(0, 0, 3);
  std::vector<double> gaps;
  for (const Eigen::Vector3d& motion : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.3, -0.1, 0.2), Eigen::Vector3d(0.1, 0, 0)}) {
    const Eigen::Vector3d x_b = x_a + motion;
    double explicit_sum = 0;
    for (const auto& f : flows) explicit_sum += (motion - f).squaredNorm() / (sigma * sigma);
    gaps.push_back(explicit_sum - SquaredResidual(*cost, {x_a.data(), x_b.data()}));
  }
  EXPECT_NEAR(gaps[0], gaps[1], 1e-9);
  EXPECT_NEAR(gaps[0], gaps[2], 1e-9);
  EXPECT_GT(gaps[0], 0);
}

double SquaredResidual(const ceres::CostFunction& cost, const std::vector<const double*>& parameters) {
  std::vector<double> residual(cost.num_residuals());
  EXPECT_TRUE(cost.Evaluate(parameters.data(), residual.data(), nullptr));
  double sum = 0;
  for (double r : residual) sum += r * r;
  return sum;
}

// Points 2 apart with rest length 1.5, k = 1.1; motions differing by (0.1, 0, 0), b = 0.5, map scale 2.
TEST(RegularizerCosts, KnownEnergiesOfBothWeightings) {
  DeformationModelOptions paper, reference;
  paper.weighting = "paper";
  reference.weighting = "reference";
  const double zero[3] = {0, 0, 0};
  const Eigen::Vector3d origin(0, 0, 0), two(2, 0, 0);
  auto elastic_energy = [&](const DeformationModelOptions& options) {
    std::unique_ptr<ceres::CostFunction> cost(ElasticCost::Create(origin, two, 1.5, ElasticMultiplier(options, 1.5)));
    return SquaredResidual(*cost, {zero, zero});
  };
  EXPECT_NEAR(elastic_energy(paper), 1.1 * 0.25 / 1.5, 1e-12);                           // k (d − d0)²/d0
  EXPECT_NEAR(elastic_energy(reference), std::pow(1.1 * 0.5 / 1.5 / 0.1, 2), 1e-12);     // (k strain / σ_e)²

  const double delta_i[3] = {0.1, 0, 0};
  auto viscous_energy = [&](const DeformationModelOptions& options) {
    std::unique_ptr<ceres::CostFunction> cost(ViscousCost::Create(ViscousMultiplier(options, 0.5, 2.0)));
    return SquaredResidual(*cost, {delta_i, zero});
  };
  EXPECT_NEAR(viscous_energy(paper), 0.5 * 0.01, 1e-12);                                 // b ‖δi − δj‖²
  EXPECT_NEAR(viscous_energy(reference), std::pow(0.5 * 0.1 / (reference.viscous_sigma_factor * 2.0), 2),
              1e-12);  // (b Δδ / σ_v s)²

  // Keyframe form: point i moves by 0.1 between keyframes, j stays.
  const double x_i_next[3] = {0.1, 0, 0};
  std::unique_ptr<ceres::CostFunction> keyframes(ViscousKeyframeCost::Create(ViscousMultiplier(paper, 0.5, 2.0)));
  EXPECT_NEAR(SquaredResidual(*keyframes, {zero, x_i_next, zero, zero}), 0.5 * 0.01, 1e-12);
  // At rest length the spring is silent.
  std::unique_ptr<ceres::CostFunction> rest(ElasticCost::Create(origin, two, 2.0, ElasticMultiplier(reference, 2.0)));
  EXPECT_NEAR(SquaredResidual(*rest, {zero, zero}), 0.0, 1e-20);
}

}  // namespace
}  // namespace nrslam
