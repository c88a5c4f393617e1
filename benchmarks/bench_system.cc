// Whole-system speed and memory: monocular NR-SLAM (initialisation, tracking, DBA,
// triangulation) over simulated sequences at 640x480, run through the offline runner
// (reading images and writing the run folder included; rendering is done beforehand and
// not timed). Prints the host's load average before the first run, then fps, mean ms per frame
// of each stage and the peak resident memory.
// Targets: >= 15 fps; <= 1 GB on a 1000-frame run.
//   bench_system [FRAMES=120] [PRESET...] [--set module.option=value ...]   e.g. bench_system 1000 sim-3
#include <unistd.h>

#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "bench_options.h"
#include "host_load.h"
#include "nrslam/sim/simulate.h"
#include "nrslam/system/run_sequence.h"
#include "nrslam/util/memory_usage.h"
#include "nrslam/util/source_revision.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  CLI::App app{"Whole-system speed and memory of monocular NR-SLAM on simulated sequences at 640x480"};
  app.set_version_flag("--version", nrslam::VersionString());
  int frames = 120;
  std::vector<std::string> presets = {"sim-0", "sim-3", "sim-6"};
  app.add_option("frames", frames, "frames per sequence")->check(CLI::Range(2, 100000));
  app.add_option("presets", presets, "simulator presets")->check(CLI::IsMember(nrslam::SimPresetNames()));
  std::vector<std::string> assignments;
  app.add_option("--set", assignments, "options of both modes, as nrslam_run's --set (e.g. --set mapping.dba_lag_frames=2)");
  CLI11_PARSE(app, argc, argv);
  const std::optional<nrslam::SystemOptions> options = BenchmarkOptions(assignments);
  if (!options) return 1;
  const fs::path work = fs::temp_directory_path() / ("nrslam_bench_system_" + std::to_string(::getpid()));
  // "linear ms" is inside "track ms": the joint solves' linear solver.
  std::printf("%s\n", nrslam::VersionString().c_str());
  PrintHostLoad();
  std::printf("%-9s %-10s %6s %7s %9s %9s %9s %9s %9s %9s %8s\n", "preset", "mode", "frames", "fps", "init ms", "track ms",
              "linear ms", "DBA ms", "triang ms", "RMSE mm", "points");
  for (const std::string& preset : presets) {
    nrslam::SimOptions sim = nrslam::SimPreset(preset);
    sim.frames = frames;
    nrslam::SimulateSequence(sim, preset, work / preset);
    for (const bool rigid : {false, true}) {
      nrslam::SystemOptions mode = *options;
      mode.tracking.rigid = rigid;
      const nrslam::RunSummary s = nrslam::RunSequence(work / preset, mode, work / (preset + "-run"));
      std::printf("%-9s %-10s %6d %7.1f %9.2f %9.2f %9.2f %9.2f %9.2f %9.2f %8zu\n", preset.c_str(),
                  rigid ? "rigid" : "deformable", s.frames_tracked, s.fps, s.ms_initialisation, s.ms_tracking,
                  s.ms_tracking_linear_solve, s.ms_dba, s.ms_triangulation, s.rmse_mm, s.map_points);
      std::fflush(stdout);
    }
    fs::remove_all(work / preset);
    fs::remove_all(work / (preset + "-run"));
  }
  std::printf("peak resident memory: %.0f MB (whole process, all runs)\n", nrslam::PeakResidentMemoryMb());
  fs::remove_all(work);
  return 0;
}
