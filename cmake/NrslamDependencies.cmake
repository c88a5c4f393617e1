# Finds every third-party dependency. All come from Debian 12 packages, installed by
# tools/install_deps.sh; nothing is downloaded at configure or build time.
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(Ceres 2.1 REQUIRED)
# The installed package (cmake/nrslamConfig.cmake.in) asks for the same OpenCV modules.
set(NRSLAM_OPENCV_COMPONENTS core imgproc imgcodecs video videoio calib3d)
find_package(OpenCV 4.6 REQUIRED COMPONENTS ${NRSLAM_OPENCV_COMPONENTS})
find_package(embree 3.13 REQUIRED)
find_package(nlohmann_json 3.11 REQUIRED)
find_package(CLI11 2.1 REQUIRED)
find_package(OpenMP REQUIRED COMPONENTS CXX)
find_package(Threads REQUIRED)
if(NRSLAM_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(NRSLAM_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()
