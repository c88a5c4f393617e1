// Tests: camera calibrations shared by the camera and cost-functor tests.
#pragma once

#include <vector>

#include "nrslam/camera/camera.h"

namespace nrslam {

// An OCamCalib calibration of a 848x800 fisheye that sees up to 128° off its axis in the corners,
// as its calib_results.txt gives it (centre "row column" 390.949324 423.714757).
inline const std::vector<double> kOcamDirect = {-2.895569e+02, 0.000000e+00, 1.538894e-03, -3.140320e-06, 7.206996e-09};
inline const std::vector<double> kOcamInverse = {434.372025, 226.016722, -31.205890, 43.418508, 11.945692,
                                          -5.582063,  36.541804,  -10.674868, -55.334360, 1.105775,
                                          43.550131,  25.374995,  4.505945};
inline Camera OcamFisheye() {
  return Camera::Ocam(848, 800, 423.714757, 390.949324, 0.999134, -0.000325, -0.000071, kOcamDirect, kOcamInverse);
}

}  // namespace nrslam
