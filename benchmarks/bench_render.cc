// Render time per 640x480 frame of the simulator (sim-3, moving and deforming), for the
// pinhole and the fisheye camera. Target: <= 60 ms/frame on 2 cores.
#include <benchmark/benchmark.h>

#include "nrslam/sim/renderer.h"

namespace {

void RenderFrames(benchmark::State& state, const std::string& camera_model) {
  nrslam::SimOptions options = nrslam::SimPreset("sim-3");
  options.camera.model = camera_model;
  options.frames = 1000;
  nrslam::Renderer renderer(options);
  int frame = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(renderer.Render(frame++ % options.frames).left.bgr.data);
  }
  state.counters["triangles"] = static_cast<double>(renderer.caster().triangle_count());
}

void BM_RenderPinhole640x480(benchmark::State& state) { RenderFrames(state, "pinhole"); }
void BM_RenderFisheye640x480(benchmark::State& state) { RenderFrames(state, "fisheye"); }

BENCHMARK(BM_RenderPinhole640x480)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
BENCHMARK(BM_RenderFisheye640x480)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);

}  // namespace

BENCHMARK_MAIN();
