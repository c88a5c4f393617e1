// Tracking speed at 640x480: frames per second of tracking alone (rendering excluded) and
// milliseconds per stage on simulator presets: deformable (sparse Cholesky, the default; each
// frame is given the next one's image, as nrslam_run does, so its KLT runs ahead on the other
// core), the same without that look-ahead, deformable with the CGNR joint solver, and rigid.
// Target: >= 30 fps. A mode that loses the track is timed over the frames before the loss
// ("tracked").
//   bench_tracking [FRAMES=60] [PRESET ...=sim-0 sim-3 sim-6] [--set module.option=value ...]
#include <CLI/CLI.hpp>

#include <cstdio>
#include <string>
#include <vector>

#include "bench_options.h"
#include "nrslam/io/depth_encoding.h"
#include "nrslam/sim/renderer.h"
#include "nrslam/sim/sim_options.h"
#include "nrslam/tracking/tracker.h"
#include "nrslam/util/source_revision.h"

int main(int argc, char** argv) {
  CLI::App app{"Tracking speed at 640x480 from a depth-initialised map"};
  app.set_version_flag("--version", nrslam::VersionString());
  int frames = 60;
  app.add_option("frames", frames, "frames per preset, the first one initialising")->check(CLI::Range(2, 100000));
  std::vector<std::string> presets = {"sim-0", "sim-3", "sim-6"};
  app.add_option("presets", presets, "simulator presets")->check(CLI::IsMember(nrslam::SimPresetNames()));
  std::vector<std::string> assignments;
  app.add_option("--set", assignments, "options of every mode, as nrslam_run's --set (e.g. --set tracking.displacement_prior_sigma=0.2)");
  CLI11_PARSE(app, argc, argv);
  const std::optional<nrslam::SystemOptions> options = BenchmarkOptions(assignments);
  if (!options) return 1;
  // "solve" and "linear" are inside "deform": Ceres's joint solves and their linear solver;
  // "ahead" is KLT time spent on the other core during the previous frame (not in "total").
  std::printf("%s\n", nrslam::VersionString().c_str());
  std::printf("%-9s %-10s %7s %7s %8s %8s %8s %9s %8s %9s %8s %8s\n", "preset", "mode", "tracked", "fps", "klt ms",
              "ahead ms", "pose ms", "deform ms", "solve ms", "linear ms", "total ms", "points");
  for (const std::string& preset : presets) {
    const nrslam::SimOptions sim = nrslam::SimPreset(preset);
    nrslam::Renderer renderer(sim);
    std::vector<nrslam::RenderedFrame> rendered;
    for (int i = 0; i < frames; ++i) rendered.push_back(renderer.Render(i));
    // The first depth map as nrslam_run reads it from the sequence's PNG, so that both track
    // the same map (the unrounded one sent sim-6 down another path).
    const cv::Mat initial_depth_mm = nrslam::DecodeDepthMm(
        nrslam::EncodeDepthMm(rendered[0].left.depth_mm, sim.depth_unit_mm), sim.depth_unit_mm);
    for (const std::string mode : {"deformable", "no-ahead", "cgnr", "rigid"}) {
      nrslam::TrackingOptions tracking = options->tracking;
      tracking.rigid = mode == "rigid";
      if (mode == "cgnr") tracking.joint_linear_solver = "cgnr";
      if (mode == "no-ahead") tracking.klt_lookahead = false;
      nrslam::Tracker tracker(renderer.camera(), options->frontend, options->deformation, tracking);
      tracker.InitialiseFromDepth(0, rendered[0].left.bgr, initial_depth_mm, {});
      double klt = 0, ahead = 0, pose = 0, deformation = 0, solve = 0, linear = 0, total = 0, points = 0;
      int tracked = 0;
      for (int i = 1; i < frames; ++i) {
        const cv::Mat next = i + 1 < frames ? rendered[i + 1].left.bgr : cv::Mat();
        const nrslam::FrameResult result = tracker.Track(i, rendered[i].left.bgr, {}, next);
        if (result.state != nrslam::TrackingState::kTracking) break;
        klt += result.ms_klt;
        ahead += result.ms_klt_ahead;
        pose += result.ms_pose;
        deformation += result.ms_deformation;
        solve += result.ms_joint_solve;
        linear += result.ms_linear_solve;
        total += result.ms_total;
        points += result.points.size();
        ++tracked;
      }
      const double n = std::max(tracked, 1);
      std::printf("%-9s %-10s %7d %7.1f %8.2f %8.2f %8.2f %9.2f %8.2f %9.2f %8.2f %8.0f\n", preset.c_str(),
                  mode.c_str(), tracked, 1000.0 * n / std::max(total, 1e-9), klt / n, ahead / n, pose / n,
                  deformation / n, solve / n, linear / n, total / n, points / n);
    }
  }
  return 0;
}
