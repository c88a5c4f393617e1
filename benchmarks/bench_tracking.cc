// Tracking speed at 640x480: frames per second of tracking alone (rendering excluded) and
// milliseconds per stage on simulator presets: deformable (sparse Cholesky, the default; each
// frame is given the next one's image, as nrslam_run does, so its KLT runs ahead on the other
// core), the same without that look-ahead, deformable with the CGNR joint solver, deformable
// with at most 150 points in the joint solve (tracking.joint_solve_max_points), and rigid.
// Target: >= 30 fps. A mode that loses the track is timed over the frames before the loss
// ("tracked"). This host's speed drifts by ±15 % from minute to minute, so with --repeat the
// modes are run in turn that many times and each column is the median over the repeats; "vs
// def" is the median of a mode's fps over the deformable mode's in the same repeat, the
// figure that drifts least. The host's load average before the first run is printed above the
// table, so that a slow table on a busy host reads as such.
//   bench_tracking [FRAMES=60] [PRESET ...=sim-0 sim-3 sim-6] [--repeat N=1] [--set module.option=value ...]
#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "bench_options.h"
#include "host_load.h"
#include "nrslam/io/depth_encoding.h"
#include "nrslam/sim/renderer.h"
#include "nrslam/sim/sim_options.h"
#include "nrslam/tracking/tracker.h"
#include "nrslam/util/median.h"
#include "nrslam/util/source_revision.h"

namespace {

const std::array<const char*, 5> kModes = {"deformable", "no-ahead", "cgnr", "cap-150", "rigid"};

// One mode's run over a preset: frames timed and, per timed frame, mean ms per stage.
struct ModeRun {
  double tracked = 0, fps = 0;
  double klt = 0, ahead = 0, pose = 0, deformation = 0, solve = 0, linear = 0, total = 0, points = 0;
};

ModeRun TimeMode(const std::string& mode, const nrslam::SystemOptions& options, const nrslam::Renderer& renderer,
                 const std::vector<nrslam::RenderedFrame>& rendered, const cv::Mat& initial_depth_mm) {
  nrslam::TrackingOptions tracking = options.tracking;
  tracking.rigid = mode == "rigid";
  if (mode == "cgnr") tracking.joint_linear_solver = "cgnr";
  if (mode == "no-ahead") tracking.klt_lookahead = false;
  if (mode == "cap-150") tracking.joint_solve_max_points = 150;
  nrslam::Tracker tracker(renderer.camera(), options.frontend, options.deformation, tracking);
  tracker.InitialiseFromDepth(0, rendered[0].left.bgr, initial_depth_mm, {});
  ModeRun run;
  const int frames = static_cast<int>(rendered.size());
  for (int i = 1; i < frames; ++i) {
    const cv::Mat next = i + 1 < frames ? rendered[i + 1].left.bgr : cv::Mat();
    const nrslam::FrameResult result = tracker.Track(i, rendered[i].left.bgr, {}, next);
    if (result.state != nrslam::TrackingState::kTracking) break;
    run.klt += result.ms_klt;
    run.ahead += result.ms_klt_ahead;
    run.pose += result.ms_pose;
    run.deformation += result.ms_deformation;
    run.solve += result.ms_joint_solve;
    run.linear += result.ms_linear_solve;
    run.total += result.ms_total;
    run.points += result.points.size();
    run.tracked += 1;
  }
  const double n = std::max(run.tracked, 1.0);
  run.fps = 1000.0 * n / std::max(run.total, 1e-9);
  for (double* mean : {&run.klt, &run.ahead, &run.pose, &run.deformation, &run.solve, &run.linear, &run.total,
                       &run.points}) {
    *mean /= n;
  }
  return run;
}

// The median over the repeats of one column.
double MedianOf(const std::vector<ModeRun>& runs, double ModeRun::*column) {
  std::vector<double> values;
  for (const ModeRun& run : runs) values.push_back(run.*column);
  return nrslam::Median(values);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Tracking speed at 640x480 from a depth-initialised map"};
  app.set_version_flag("--version", nrslam::VersionString());
  int frames = 60;
  app.add_option("frames", frames, "frames per preset, the first one initialising")->check(CLI::Range(2, 100000));
  std::vector<std::string> presets = {"sim-0", "sim-3", "sim-6"};
  app.add_option("presets", presets, "simulator presets")->check(CLI::IsMember(nrslam::SimPresetNames()));
  std::vector<std::string> assignments;
  app.add_option("--set", assignments, "options of every mode, as nrslam_run's --set (e.g. --set tracking.displacement_prior_sigma=0.2)");
  int repeats = 1;
  app.add_option("--repeat", repeats, "run the modes in turn this many times; each column is the median")
      ->check(CLI::Range(1, 100));
  CLI11_PARSE(app, argc, argv);
  const std::optional<nrslam::SystemOptions> options = BenchmarkOptions(assignments);
  if (!options) return 1;
  // "solve" and "linear" are inside "deform": Ceres's joint solves and their linear solver;
  // "ahead" is KLT time spent on the other core during the previous frame (not in "total").
  std::printf("%s\n", nrslam::VersionString().c_str());
  PrintHostLoad();
  if (repeats > 1) std::printf("medians over %d repeats, the modes run in turn\n", repeats);
  std::printf("%-9s %-10s %7s %7s %11s %7s %8s %8s %8s %9s %8s %9s %8s %8s\n", "preset", "mode", "tracked", "fps",
              "fps range", "vs def", "klt ms", "ahead ms", "pose ms", "deform ms", "solve ms", "linear ms", "total ms",
              "points");
  for (const std::string& preset : presets) {
    const nrslam::SimOptions sim = nrslam::SimPreset(preset);
    nrslam::Renderer renderer(sim);
    std::vector<nrslam::RenderedFrame> rendered;
    for (int i = 0; i < frames; ++i) rendered.push_back(renderer.Render(i));
    // The first depth map as nrslam_run reads it from the sequence's PNG, so that both track
    // the same map (the unrounded one sent sim-6 down another path).
    const cv::Mat initial_depth_mm = nrslam::DecodeDepthMm(
        nrslam::EncodeDepthMm(rendered[0].left.depth_mm, sim.depth_unit_mm), sim.depth_unit_mm);
    std::vector<std::vector<ModeRun>> runs(kModes.size());  // by mode, one per repeat
    for (int repeat = 0; repeat < repeats; ++repeat) {
      for (size_t m = 0; m < kModes.size(); ++m) {
        runs[m].push_back(TimeMode(kModes[m], *options, renderer, rendered, initial_depth_mm));
      }
    }
    for (size_t m = 0; m < kModes.size(); ++m) {
      std::vector<double> fps, versus_deformable;
      for (int repeat = 0; repeat < repeats; ++repeat) {
        fps.push_back(runs[m][repeat].fps);
        versus_deformable.push_back(runs[m][repeat].fps / runs[0][repeat].fps);
      }
      char range[32];
      std::snprintf(range, sizeof range, "%.1f-%.1f", *std::min_element(fps.begin(), fps.end()),
                    *std::max_element(fps.begin(), fps.end()));
      std::printf("%-9s %-10s %7.0f %7.1f %11s %7.2f %8.2f %8.2f %8.2f %9.2f %8.2f %9.2f %8.2f %8.0f\n",
                  preset.c_str(), kModes[m], MedianOf(runs[m], &ModeRun::tracked), nrslam::Median(fps), range,
                  nrslam::Median(versus_deformable), MedianOf(runs[m], &ModeRun::klt),
                  MedianOf(runs[m], &ModeRun::ahead), MedianOf(runs[m], &ModeRun::pose),
                  MedianOf(runs[m], &ModeRun::deformation), MedianOf(runs[m], &ModeRun::solve),
                  MedianOf(runs[m], &ModeRun::linear), MedianOf(runs[m], &ModeRun::total),
                  MedianOf(runs[m], &ModeRun::points));
    }
  }
  return 0;
}
