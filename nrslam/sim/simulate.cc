#include "nrslam/sim/simulate.h"

#include <chrono>
#include <limits>

#include "nrslam/io/sequence_writer.h"
#include "nrslam/sim/renderer.h"
#include "nrslam/util/source_revision.h"

namespace nrslam {

SimulationSummary SimulateSequence(const SimOptions& options, const std::string& name,
                                   const std::filesystem::path& folder, const SimulationProgress& progress) {
  using Clock = std::chrono::steady_clock;
  options.Check();
  Renderer renderer(options);

  SequenceInfo info;
  info.camera = renderer.camera();
  info.fps = options.fps;
  info.frame_count = options.frames;
  info.depth_unit_mm = options.depth_unit_mm;
  info.stereo = renderer.stereo();
  if (!renderer.validity_mask().empty()) info.mask = "mask.png";
  info.provenance = {{"generator", std::string("nrslam_simulate ") + NRSLAM_VERSION},
                     {"code", SequenceCodeFingerprint()},
                     {"preset", name},
                     {"parameters", options}};
  SequenceWriter writer(folder, info, /*with_depth=*/true);
  if (!info.mask.empty()) writer.WriteFixedMask(renderer.validity_mask());

  SimulationSummary summary;
  summary.name = name;
  summary.frames = options.frames;
  summary.width = info.camera.width();
  summary.height = info.camera.height();
  double depth_min = std::numeric_limits<double>::infinity(), depth_max = 0.0;
  double render_seconds = 0.0, write_seconds = 0.0;
  std::vector<StampedPose> poses;
  for (int index = 0; index < options.frames; ++index) {
    const auto start = Clock::now();
    const RenderedFrame frame = renderer.Render(index);
    const auto rendered = Clock::now();
    writer.WriteRgb(index, frame.left.bgr);
    writer.WriteDepthMm(index, frame.left.depth_mm);
    if (frame.right) writer.WriteRight(index, frame.right->bgr);
    write_seconds += std::chrono::duration<double>(Clock::now() - rendered).count();
    render_seconds += std::chrono::duration<double>(rendered - start).count();
    poses.push_back({renderer.TimeOf(index), frame.world_from_camera});

    for (int y = 0; y < frame.left.depth_mm.rows; ++y) {
      const float* row = frame.left.depth_mm.ptr<float>(y);
      for (int x = 0; x < frame.left.depth_mm.cols; ++x) {
        if (row[x] > 0) {
          depth_min = std::min(depth_min, static_cast<double>(row[x]));
          depth_max = std::max(depth_max, static_cast<double>(row[x]));
        }
      }
    }
    if (progress) progress(index + 1, options.frames, 1000.0 * render_seconds / (index + 1));
  }
  writer.WriteGroundtruth(poses);
  summary.depth_min_mm = std::isfinite(depth_min) ? depth_min : 0.0;
  summary.depth_max_mm = depth_max;
  summary.render_ms_per_frame = 1000.0 * render_seconds / options.frames;
  summary.write_ms_per_frame = 1000.0 * write_seconds / options.frames;
  return summary;
}

}  // namespace nrslam
