// Known answers of Student's t critical values (checked against a numerical integration of
// the density) and its refusal of meaningless arguments.
#include <gtest/gtest.h>

#include "nrslam/util/error.h"
#include "nrslam/util/student_t.h"

namespace nrslam {
namespace {

TEST(StudentT, CriticalValuesMatchTheTables) {
  const struct {
    double confidence;
    int degrees_of_freedom;
    double t;
  } table[] = {{0.95, 1, 12.7062047361747},  {0.95, 2, 4.30265272974946},   {0.95, 10, 2.22813885198627},
               {0.95, 23, 2.06865761041905}, {0.95, 100, 1.98397151852355}, {0.99, 5, 4.03214298355522},
               {0.5, 3, 0.764892328404345}};
  for (const auto& row : table) {
    EXPECT_NEAR(StudentTCriticalValue(row.confidence, row.degrees_of_freedom), row.t, 1e-9 * row.t)
        << row.confidence << " at " << row.degrees_of_freedom;
  }
  // Many degrees of freedom: the normal distribution's 1.959964.
  EXPECT_NEAR(StudentTCriticalValue(0.95, 100000), 1.959964, 1e-4);
}

TEST(StudentT, RefusesWhatHasNoCriticalValue) {
  EXPECT_THROW(StudentTCriticalValue(0.95, 0), Error);
  EXPECT_THROW(StudentTCriticalValue(1.0, 5), Error);
  EXPECT_THROW(StudentTCriticalValue(0.0, 5), Error);
}

}  // namespace
}  // namespace nrslam
