// batch: paired runs compared (each run against its partner: the same sequence before and after a
// change, deformable against rigid, a swept value against the default): how many got better,
// stayed or got worse, the typical ratio with its confidence interval, and the sign and
// signed-rank tests.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace nrslam {

// Paired runs counted by how a run's RMSE compares with its partner's (the reference):
// "same" when equal to the printed 0.001 mm.
struct RmseChangeCounts {
  int better = 0, same = 0, worse = 0;
  // log(RMSE / reference) of each pair with both RMSEs positive, and whether that pair moved
  // (was not "same"): the size of each change, which the counts leave out.
  std::vector<double> log_ratios;
  std::vector<bool> pair_moved;
  void Add(double reference_mm, double rmse_mm);
  std::string ToString() const;  // "better / same / worse"
  // Two-sided exact sign test over the runs that moved (ties left out): the chance of a split
  // at least this uneven if better and worse were equally likely. 1 when none moved.
  double SignTestP() const;
  // exp(mean log ratio): the factor by which the RMSE typically changed (0.9: 10 % lower),
  // so that a 0.3 mm and a 15 mm sequence weigh alike. 1 with no pair.
  double GeometricMeanRatio() const;
  // The `confidence` interval of that factor, from Student's t over the log ratios: how far
  // the typical change could be from the measured one, were the same runs drawn again from
  // the scenes and seeds they stand for. Needs 2 pairs or more.
  struct RatioInterval {
    double low = 1, high = 1;
  };
  std::optional<RatioInterval> GeometricMeanRatioInterval(double confidence = 0.95) const;
  // The 95 % interval as tables print it, "0.981 to 1.109", or "" when there is none;
  // `reciprocal` turns it the other way up (reference / RMSE).
  std::string GeometricMeanRatioIntervalText(bool reciprocal = false) const;
  // The ratio with that interval, "1.043 (95 % CI 0.981 to 1.109)", or the ratio alone.
  std::string GeometricMeanRatioText(bool reciprocal = false) const;
  // Two-sided Wilcoxon signed-rank test of the log ratios of the runs that moved: like the
  // sign test, but a run that changed much counts more than one that changed a little.
  // Exact (the permutation distribution of the tied ranks) up to 200 runs, the normal
  // approximation with tie correction above. 1 when none moved.
  double SignedRankP() const;
};

}  // namespace nrslam
