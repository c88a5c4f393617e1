// Known answers for the similarity-aligned trajectory error (eval/trajectory_error.h).
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>

#include "nrslam/eval/trajectory_error.h"
#include "nrslam/util/error.h"

namespace nrslam {
namespace {

// A map's frame: the truth seen through an arbitrary similarity (what a monocular map is).
Eigen::Vector3d IntoMap(const Eigen::Vector3d& truth) {
  const Eigen::Quaterniond rotation(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized()));
  return 0.05 * (rotation * truth) + Eigen::Vector3d(3, -1, 2);
}

// Camera centres on a 4 x 4 x 2 grid around (10, 20, 30) mm, and a noise along z with a
// checkerboard sign over x and y. The noise n has zero sum and Σ p nᵀ = 0 over the centred
// grid p, so the best similarity keeps the rotation and shrinks the scale to P/(P+Q), with
// P and Q the mean squared norms of p and n; the aligned RMSE is then √(PQ/(P+Q)).
struct NoisyGrid {
  TrajectorySegment map;
  double expected_rmse = 0, expected_scale = 0;
  explicit NoisyGrid(double noise) {
    double p = 0, q = 0;
    for (int ix = 0; ix < 4; ++ix) {
      for (int iy = 0; iy < 4; ++iy) {
        for (int iz = 0; iz < 2; ++iz) {
          const Eigen::Vector3d centred(2 * ix - 3, 2 * iy - 3, 2 * iz - 1);
          const Eigen::Vector3d n(0, 0, (ix + iy) % 2 == 0 ? noise : -noise);
          const Eigen::Vector3d truth = centred + Eigen::Vector3d(10, 20, 30);
          map.groundtruth.push_back(truth);
          map.estimated.push_back(IntoMap(truth + n));
          p += centred.squaredNorm();
          q += n.squaredNorm();
        }
      }
    }
    p /= 32;
    q /= 32;
    expected_rmse = std::sqrt(p * q / (p + q));
    expected_scale = 20.0 * p / (p + q);  // the map is at 0.05 of the truth
  }
};

TEST(TrajectoryError, ExactMapAlignsToZeroWithItsScale) {
  const NoisyGrid grid(0.0);
  const TrajectoryError error = AlignedTrajectoryError({grid.map});
  ASSERT_TRUE(error.evaluated);
  EXPECT_EQ(error.poses, 32);
  EXPECT_EQ(error.maps, 1);
  EXPECT_LT(error.rmse_mm, 1e-9);
  EXPECT_NEAR(error.scale, 20.0, 1e-9);
}

TEST(TrajectoryError, NoiseTheAlignmentCannotAbsorbGivesTheKnownRmse) {
  const NoisyGrid grid(0.5);
  const TrajectoryError error = AlignedTrajectoryError({grid.map});
  ASSERT_TRUE(error.evaluated);
  EXPECT_NEAR(error.rmse_mm, grid.expected_rmse, 1e-9);
  EXPECT_NEAR(error.scale, grid.expected_scale, 1e-9);
  EXPECT_GT(error.rmse_mm, 0.4);  // not absorbed: close to the noise's own 0.5
}

TEST(TrajectoryError, EachMapIsAlignedOnItsOwnAndTheErrorsPooled) {
  // A second map in another gauge and scale, exact: aligned together with the first the error
  // would be large; aligned on its own it adds 16 zero distances to the pool.
  const NoisyGrid noisy(0.5);
  TrajectorySegment exact;
  for (int i = 0; i < 16; ++i) {
    const Eigen::Vector3d truth(40.0 + i, 5.0 * std::sin(i), 0.3 * i * i);
    exact.groundtruth.push_back(truth);
    exact.estimated.push_back(7.0 * truth + Eigen::Vector3d(-100, 0, 4));
  }
  const TrajectoryError error = AlignedTrajectoryError({noisy.map, exact});
  ASSERT_TRUE(error.evaluated);
  EXPECT_EQ(error.poses, 48);
  EXPECT_EQ(error.maps, 2);
  EXPECT_NEAR(error.rmse_mm, noisy.expected_rmse * std::sqrt(32.0 / 48.0), 1e-9);
  EXPECT_NEAR(error.scale, noisy.expected_scale, 1e-9);  // the map with more frames
}

TEST(TrajectoryError, MapsThatCannotBeAlignedAreLeftOut) {
  TrajectorySegment still, short_map;
  for (int i = 0; i < 5; ++i) {
    still.estimated.push_back(Eigen::Vector3d(1, 2, 3));  // the camera never moved
    still.groundtruth.push_back(Eigen::Vector3d(i, 0, 0));
  }
  short_map.estimated = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0)};
  short_map.groundtruth = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(2, 0, 0)};
  const TrajectoryError error = AlignedTrajectoryError({still, short_map});
  EXPECT_FALSE(error.evaluated);
  EXPECT_EQ(error.poses, 0);
  EXPECT_EQ(AlignedTrajectoryError({}).evaluated, false);
}

// The centres the error is taken over (what the report plots): an exact map lands on the
// truth, a noisy one at the known distance, one that cannot be aligned gives none.
TEST(TrajectoryError, AlignedCentresAreTheOnesTheErrorMeasures) {
  const NoisyGrid exact(0.0), noisy(0.5);
  const auto on_truth = AlignedCentres(exact.map);
  ASSERT_TRUE(on_truth);
  ASSERT_EQ(on_truth->size(), exact.map.groundtruth.size());
  for (size_t i = 0; i < on_truth->size(); ++i) EXPECT_LT(((*on_truth)[i] - exact.map.groundtruth[i]).norm(), 1e-9);
  const auto off_truth = AlignedCentres(noisy.map);
  ASSERT_TRUE(off_truth);
  double squared = 0;
  for (size_t i = 0; i < off_truth->size(); ++i) squared += ((*off_truth)[i] - noisy.map.groundtruth[i]).squaredNorm();
  EXPECT_NEAR(std::sqrt(squared / static_cast<double>(off_truth->size())), noisy.expected_rmse, 1e-9);
  TrajectorySegment short_map;
  short_map.estimated = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0)};
  short_map.groundtruth = short_map.estimated;
  EXPECT_FALSE(AlignedCentres(short_map));
}

TEST(TrajectoryError, BadInputIsAnError) {
  TrajectorySegment mismatched;
  mismatched.estimated = {Eigen::Vector3d::Zero()};
  EXPECT_THROW(AlignedTrajectoryError({mismatched}), Error);
  NoisyGrid grid(0.1);
  grid.map.estimated[3].x() = NAN;
  EXPECT_THROW(AlignedTrajectoryError({grid.map}), Error);
}

}  // namespace
}  // namespace nrslam
