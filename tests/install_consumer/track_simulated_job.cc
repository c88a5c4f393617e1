#include "track_simulated_job.h"

#include <nrslam/sim/sim_options.h>
#include <nrslam/sim/simulate.h>
#include <nrslam/system/run_sequence.h>
#include <nrslam/system/system_options.h>
#include <nrslam/util/error.h>
#include <nrslam/util/source_revision.h>

#include <filesystem>
#include <iostream>

int TrackSimulatedSequence(const char* work_folder) {
  try {
    const std::filesystem::path work = work_folder;
    nrslam::SimOptions simulation = nrslam::SimPreset("sim-3");
    simulation.frames = 12;
    simulation.camera.width = 320;
    simulation.camera.height = 240;
    nrslam::SimulateSequence(simulation, "sim-3", work / "sequence");

    const nrslam::SystemOptions options =
        nrslam::WithRunAssignments(nrslam::SystemOptions{}, {"run.init=depth", "run.mapping=false"});
    const nrslam::RunSummary summary = nrslam::RunSequence(work / "sequence", options, work / "run");
    std::cout << nrslam::VersionString() << "\nstatus " << summary.Status() << ", tracked "
              << summary.frames_tracked << "/" << summary.frames_total << ", RMSE " << summary.rmse_mm << " mm\n";
    return summary.Status() == "ok" && summary.frames_tracked == summary.frames_total ? 0 : 1;
  } catch (const nrslam::Error& error) {
    std::cerr << "error: " << error.what() << "\n";
    return 1;
  }
}
