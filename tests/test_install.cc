// Tests: the installation (cmake/NrslamInstall.cmake). nrslam is installed into a temporary
// prefix and used from there alone, as by someone who builds on it: another CMake project
// (tests/install_consumer) finds the package, compiles every installed header, links the library
// into a program and into a plugin and tracks a sequence with each, and the installed nrslam_eval
// runs a manifest from the installed share folder.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "nrslam/util/process.h"
#include "nrslam/util/source_revision.h"
#include "shell_command.h"
#include "temp_folder.h"

namespace nrslam {
namespace {

namespace fs = std::filesystem;

// The RMSE of the consumer's run in WORK (NaN when it wrote no summary).
double SummaryRmse(const fs::path& work) {
  std::ifstream summary(work / "run" / "summary.json");
  if (!summary) return std::nan("");
  return nlohmann::json::parse(summary).at("rmse_mm").get<double>();
}

TEST(Install, AnotherProjectBuildsOnTheInstalledLibraryAndTracksWithIt) {
  const fs::path folder = UniqueTempFolder("nrslam_install");
  fs::remove_all(folder);
  fs::create_directories(folder);
  const fs::path prefix = folder / "prefix";
  const std::string cmake = NRSLAM_CMAKE_COMMAND;

  const auto [install_status, install_log] =
      RunCaught(ShellLine({cmake, "--install", NRSLAM_BUILD_DIR, "--prefix", prefix}), folder / "install.txt");
  ASSERT_EQ(install_status, 0) << install_log;

  std::istringstream tools(NRSLAM_TOOL_NAMES);  // every program the build makes (tools/CMakeLists.txt)
  int tool_count = 0;
  for (std::string tool; tools >> tool; ++tool_count) EXPECT_TRUE(fs::exists(prefix / "bin" / tool)) << tool;
  EXPECT_GE(tool_count, 6);
  const fs::path libdir = prefix / NRSLAM_INSTALL_LIBDIR;
  EXPECT_TRUE(fs::exists(libdir / NRSLAM_LIBRARY_FILE_NAME));  // libnrslam.a, or .so in a shared build
  EXPECT_TRUE(fs::exists(libdir / "cmake" / "nrslam" / "nrslamConfig.cmake"));
  EXPECT_TRUE(fs::exists(libdir / "cmake" / "nrslam" / "nrslamConfigVersion.cmake"));
  EXPECT_TRUE(fs::exists(prefix / "share" / "doc" / "nrslam" / "docs" / "eval.md"));
  const fs::path library_sources = fs::path(NRSLAM_SOURCE_DIR) / "nrslam";
  int headers = 0;
  for (const auto& entry : fs::recursive_directory_iterator(library_sources)) {
    if (entry.path().extension() != ".h") continue;
    ++headers;
    EXPECT_TRUE(fs::exists(prefix / "include" / "nrslam" / fs::relative(entry.path(), library_sources)))
        << entry.path() << " was not installed";
  }
  EXPECT_GT(headers, 50);

  // The consumer sees nothing of the source or build tree: only the prefix.
  const fs::path consumer = folder / "consumer";
  const auto [configure_status, configure_log] =
      RunCaught(ShellLine({cmake, "-S", fs::path(NRSLAM_SOURCE_DIR) / "tests" / "install_consumer", "-B", consumer,
                           "-DCMAKE_BUILD_TYPE=Release", "-DCMAKE_PREFIX_PATH=" + prefix.string(),
                           "-DCMAKE_CXX_COMPILER=" NRSLAM_CXX_COMPILER}),
                folder / "configure.txt");
  ASSERT_EQ(configure_status, 0) << configure_log;
  EXPECT_NE(configure_log.find("nrslam headers installed: " + std::to_string(headers)), std::string::npos)
      << configure_log;
  const auto [build_status, build_log] =
      RunCaught(ShellLine({cmake, "--build", consumer, "-j2"}), folder / "build.txt");
  ASSERT_EQ(build_status, 0) << build_log;

  const auto [run_status, run_output] =
      RunCaught(ShellLine({consumer / "track_simulated", folder / "work"}), folder / "run.txt");
  EXPECT_EQ(run_status, 0) << run_output;
  EXPECT_NE(run_output.find(VersionString()), std::string::npos) << run_output;  // this build's library
  EXPECT_NE(run_output.find("status ok, tracked 12/12"), std::string::npos) << run_output;
  const double rmse_mm = SummaryRmse(folder / "work");
  EXPECT_TRUE(std::isfinite(rmse_mm) && rmse_mm > 0.0 && rmse_mm < 2.0) << rmse_mm;

  // The same job from a shared object loaded at run time, as a Python extension module would be:
  // the library links into one (position-independent code) and leaves nothing unresolved.
  const auto [plugin_status, plugin_output] =
      RunCaught(ShellLine({consumer / "load_plugin", consumer / "track_plugin.so", folder / "work_plugin"}),
                folder / "plugin.txt");
  EXPECT_EQ(plugin_status, 0) << plugin_output;
  EXPECT_NE(plugin_output.find("status ok, tracked 12/12"), std::string::npos) << plugin_output;
  EXPECT_EQ(SummaryRmse(folder / "work_plugin"), rmse_mm);  // the same code, the same run to the last bit

  // The installed tools find each other (nrslam_eval starts nrslam_simulate and nrslam_run beside
  // itself) and the shipped manifests.
  const auto [eval_status, eval_output] =
      RunCaught(ShellLine({prefix / "bin" / "nrslam_eval", prefix / "share" / "nrslam" / "data_manifests" / "ci-sim.json",
                           "--only", "sim-0", "--out", folder / "eval", "--cache", folder / "cache"}),
                folder / "eval.txt");
  EXPECT_EQ(eval_status, 0) << eval_output;
  EXPECT_NE(eval_output.find("60/60"), std::string::npos) << eval_output;
  EXPECT_TRUE(fs::exists(folder / "eval" / "results.csv"));
  fs::remove_all(folder);
}

}  // namespace
}  // namespace nrslam
