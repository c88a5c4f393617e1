#include <gtest/gtest.h>

#include "nrslam/geometry/rigid3.h"
#include "nrslam/geometry/se3_manifold.h"

namespace nrslam {
namespace {

Rigid3 SomePose() {
  return Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized())),
                Eigen::Vector3d(3, -1, 2));
}

TEST(Rigid3, InverseComposesToIdentity) {
  const Rigid3 pose = SomePose();
  const Rigid3 identity = pose * pose.Inverse();
  EXPECT_LT(identity.translation.norm(), 1e-12);
  EXPECT_LT(identity.rotation.angularDistance(Eigen::Quaterniond::Identity()), 1e-12);
  const Eigen::Vector3d x(0.3, 4.0, -2.0);
  EXPECT_LT((pose.Inverse() * (pose * x) - x).norm(), 1e-12);
}

TEST(Rigid3, ParamsRoundTripAndTemplatedTransformAgree) {
  const Rigid3 pose = SomePose();
  const PoseParams params = pose.ToParams();
  const Rigid3 back = Rigid3::FromParams(params.data());
  EXPECT_LT((back.Matrix() - pose.Matrix()).norm(), 1e-12);
  const Eigen::Vector3d x(1, 2, 3);
  EXPECT_LT((TransformPoint(params.data(), x) - pose * x).norm(), 1e-12);
}

TEST(Se3Manifold, PlusZeroIsIdentityAndMinusInvertsPlus) {
  const Se3Manifold manifold;
  const PoseParams x = SomePose().ToParams();
  const double zero[6] = {0, 0, 0, 0, 0, 0};
  double same[7];
  ASSERT_TRUE(manifold.Plus(x.data(), zero, same));
  for (int i = 0; i < 7; ++i) EXPECT_NEAR(same[i], x[i], 1e-15);

  const double delta[6] = {0.1, -0.2, 0.05, 0.03, -0.02, 0.04};
  double moved[7], recovered[6];
  ASSERT_TRUE(manifold.Plus(x.data(), delta, moved));
  ASSERT_TRUE(manifold.Minus(moved, x.data(), recovered));
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(recovered[i], delta[i], 1e-12);
  // The update is on the left: a pure translation step moves the translation by exactly it.
  const double translate[6] = {1, 2, 3, 0, 0, 0};
  ASSERT_TRUE(manifold.Plus(x.data(), translate, moved));
  EXPECT_NEAR(moved[4] - x[4], 1.0, 1e-12);
  EXPECT_NEAR(moved[6] - x[6], 3.0, 1e-12);
}

TEST(Se3Manifold, PlusJacobianMatchesNumericDifferences) {
  const Se3Manifold manifold;
  const PoseParams x = SomePose().ToParams();
  double jacobian[7 * 6];
  ASSERT_TRUE(manifold.PlusJacobian(x.data(), jacobian));
  constexpr double h = 1e-6;
  for (int k = 0; k < 6; ++k) {
    double delta[6] = {0, 0, 0, 0, 0, 0}, plus[7], minus[7];
    delta[k] = h;
    manifold.Plus(x.data(), delta, plus);
    delta[k] = -h;
    manifold.Plus(x.data(), delta, minus);
    for (int i = 0; i < 7; ++i) EXPECT_NEAR(jacobian[i * 6 + k], (plus[i] - minus[i]) / (2 * h), 1e-7);
  }
}

}  // namespace
}  // namespace nrslam
