#include "nrslam/geometry/two_view.h"

#include <Eigen/SVD>

#include <algorithm>
#include <array>
#include <cmath>

#include "nrslam/util/random.h"

namespace nrslam {
namespace {

// Least-squares E from pairs (rows of f_c ⊗ f_r), projected onto the essential manifold:
// singular values (1, 1, 0).
Eigen::Matrix3d FitEssential(const Bearings& reference, const Bearings& current, const std::vector<int>& pairs) {
  Eigen::MatrixXd system(pairs.size(), 9);
  for (size_t row = 0; row < pairs.size(); ++row) {
    const Eigen::Vector3d& r = reference[pairs[row]];
    const Eigen::Vector3d& c = current[pairs[row]];
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) system(row, 3 * i + j) = c[i] * r[j];
    }
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> nullspace(system, Eigen::ComputeFullV);
  const Eigen::VectorXd e = nullspace.matrixV().col(8);
  Eigen::Matrix3d essential;
  essential << e[0], e[1], e[2], e[3], e[4], e[5], e[6], e[7], e[8];
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(essential, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixU() * Eigen::Vector3d(1, 1, 0).asDiagonal() * svd.matrixV().transpose();
}

int Score(const Eigen::Matrix3d& essential, const Bearings& reference, const Bearings& current, double threshold,
          std::vector<bool>* inliers) {
  inliers->assign(reference.size(), false);
  int count = 0;
  for (size_t i = 0; i < reference.size(); ++i) {
    if (EpipolarAngle(essential, reference[i], current[i]) < threshold) {
      (*inliers)[i] = true;
      ++count;
    }
  }
  return count;
}

}  // namespace

Eigen::Matrix3d EssentialFromPose(const Rigid3& current_from_reference) {
  const Eigen::Vector3d t = current_from_reference.translation.normalized();
  Eigen::Matrix3d t_cross;
  t_cross << 0, -t.z(), t.y(), t.z(), 0, -t.x(), -t.y(), t.x(), 0;
  return t_cross * current_from_reference.rotation.toRotationMatrix();
}

double EpipolarAngle(const Eigen::Matrix3d& essential, const Eigen::Vector3d& reference, const Eigen::Vector3d& current) {
  const Eigen::Vector3d normal = essential * reference;
  const double norm = normal.norm() * current.norm();
  if (norm <= 0) return M_PI / 2;
  return std::asin(std::min(1.0, std::abs(normal.dot(current)) / norm));
}

std::optional<EssentialEstimate> EstimateEssential(const Bearings& reference, const Bearings& current,
                                                   const EssentialRansacOptions& options) {
  const int n = static_cast<int>(reference.size());
  if (n < 8 || current.size() != reference.size()) return std::nullopt;
  EssentialEstimate best;
  std::vector<bool> inliers;
  uint64_t state = options.seed;
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    std::vector<int> sample;
    while (sample.size() < 8) {
      state = SplitMix64(state);
      const int candidate = static_cast<int>(UnitFromBits(state) * n);
      if (std::find(sample.begin(), sample.end(), candidate) == sample.end()) sample.push_back(candidate);
    }
    const Eigen::Matrix3d essential = FitEssential(reference, current, sample);
    const int count = Score(essential, reference, current, options.epipolar_threshold_rad, &inliers);
    if (count > best.inlier_count) best = {essential, inliers, count};
  }
  if (best.inlier_count < 8) return std::nullopt;
  std::vector<int> all;
  for (int i = 0; i < n; ++i) {
    if (best.inliers[i]) all.push_back(i);
  }
  const Eigen::Matrix3d refit = FitEssential(reference, current, all);
  const int count = Score(refit, reference, current, options.epipolar_threshold_rad, &inliers);
  if (count >= best.inlier_count) best = {refit, inliers, count};
  return best;
}

std::optional<Triangulated> TriangulateMidpoint(const Eigen::Vector3d& centre0, const Eigen::Vector3d& ray0,
                                                const Eigen::Vector3d& centre1, const Eigen::Vector3d& ray1) {
  // λ0·ray0 − λ1·ray1 = centre1 − centre0; crossing with each ray isolates one λ.
  const Eigen::Vector3d baseline = centre1 - centre0;
  const Eigen::Vector3d normal = ray0.cross(ray1);
  const double normal2 = normal.squaredNorm();
  if (normal2 < 1e-18) return std::nullopt;
  Triangulated result;
  result.depth0 = baseline.cross(ray1).dot(normal) / normal2;
  result.depth1 = baseline.cross(ray0).dot(normal) / normal2;
  result.parallax_rad = std::atan2(std::sqrt(normal2), ray0.dot(ray1));
  const Eigen::Vector3d on0 = centre0 + result.depth0 * ray0;
  const Eigen::Vector3d on1 = centre1 + result.depth1 * ray1;
  // Weights 1/depth: the nearer ray is the more precise one.
  const double a = std::abs(result.depth0), b = std::abs(result.depth1);
  result.point = a + b > 0 ? (b * on0 + a * on1) / (a + b) : on0;
  return result;
}

Rigid3 DecomposeEssential(const Eigen::Matrix3d& essential, const Bearings& reference, const Bearings& current,
                          const std::vector<bool>& inliers, int* in_front) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(essential, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d u = svd.matrixU(), v = svd.matrixV();
  if (u.determinant() < 0) u = -u;
  if (v.determinant() < 0) v = -v;
  Eigen::Matrix3d w;
  w << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  const std::array<Eigen::Matrix3d, 2> rotations = {u * w * v.transpose(), u * w.transpose() * v.transpose()};
  const Eigen::Vector3d t = u.col(2);
  Rigid3 best;
  int best_count = -1;
  for (const Eigen::Matrix3d& rotation : rotations) {
    for (const double sign : {1.0, -1.0}) {
      // current_from_reference = (R, s·t); in the reference frame the current centre is −Rᵀ·s·t.
      const Rigid3 pose(Eigen::Quaterniond(rotation), sign * t);
      const Eigen::Vector3d centre = -(rotation.transpose() * (sign * t));
      int count = 0;
      for (size_t i = 0; i < reference.size(); ++i) {
        if (!inliers.empty() && !inliers[i]) continue;
        const auto point = TriangulateMidpoint(Eigen::Vector3d::Zero(), reference[i], centre,
                                               rotation.transpose() * current[i]);
        if (point && point->depth0 > 0 && point->depth1 > 0) ++count;
      }
      if (count > best_count) {
        best_count = count;
        best = pose;
      }
    }
  }
  if (in_front) *in_front = best_count;
  return best;
}

Rigid3 RefineRelativePose(const Bearings& reference, const Bearings& current, const std::vector<bool>& inliers,
                          const Rigid3& current_from_reference, double scale_rad) {
  const Eigen::AngleAxisd initial(current_from_reference.rotation);
  Eigen::Vector3d rotation = initial.angle() * initial.axis();
  Eigen::Vector3d translation = current_from_reference.translation.normalized();
  ceres::Problem problem;
  for (size_t i = 0; i < reference.size(); ++i) {
    if (!inliers[i]) continue;
    problem.AddResidualBlock(EpipolarCost::Create(reference[i], current[i]), new ceres::CauchyLoss(scale_rad),
                             rotation.data(), translation.data());
  }
  if (problem.NumResidualBlocks() < 5) return current_from_reference;
  problem.SetManifold(translation.data(), new ceres::SphereManifold<3>);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 20;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  if (!summary.IsSolutionUsable()) return current_from_reference;
  const double angle = rotation.norm();
  const Eigen::Matrix3d refined =
      (angle > 0 ? Eigen::AngleAxisd(angle, rotation / angle) : Eigen::AngleAxisd::Identity()).toRotationMatrix();
  // A linear fit that started from the wrong one of the four poses refines to a good E in
  // that pose's disguise: choose among the four again, on the refined E.
  return DecomposeEssential(EssentialFromPose(Rigid3(Eigen::Quaterniond(refined), translation)), reference, current,
                            inliers);
}

}  // namespace nrslam
