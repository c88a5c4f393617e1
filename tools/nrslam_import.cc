// nrslam_import: converts a public dataset on disk (Endomapper simulated, Hamlyn rectified,
// C3VD, or a plain video / image folder with a calibration) into a sequence folder that
// nrslam_run and nrslam_eval read.
#include <CLI/CLI.hpp>

#include <iostream>

#include "nrslam/datasets/dataset_import.h"
#include "nrslam/util/source_revision.h"

int main(int argc, char** argv) {
  CLI::App app{"Import a dataset into the nrslam sequence format"};
  app.set_version_flag("--version", nrslam::VersionString());
  nrslam::ImportOptions options;
  std::string out;
  app.add_option("--format", options.format, "endomapper-sim, hamlyn, c3vd or images")->required();
  app.add_option("--in", options.input, "the dataset's folder (or a video file for --format images)")->required();
  app.add_option("--out", out, "sequence folder to write")->required();
  app.add_option("--calibration", options.calibration, "camera JSON (as in sequence.json), OCamCalib's calib_results.txt or an OpenCV / ROS calibration (.yml, .yaml, .xml); c3vd and images need one");
  app.add_option("--mask", options.mask,
                 "fixed validity mask of the images (non-zero = usable), e.g. the black border of an endoscope's image");
  app.add_option("--fps", options.fps, "frames per second")->capture_default_str();
  app.add_option("--max-frames", options.max_frames, "import at most this many frames (0 = all)")->capture_default_str();
  app.add_option("--depth-unit-mm", options.depth_unit_mm, "resolution of the written depth, mm")->capture_default_str();
  app.add_option("--scale", options.scale,
                 "resize every image, depth map and the calibration by this factor, in (0, 4] (0.5 halves 1440x1080 to 720x540)")
      ->capture_default_str();
  app.add_option("--near", options.near, "endomapper-sim: near plane, scene units")->capture_default_str();
  app.add_option("--far", options.far, "endomapper-sim: far plane, scene units")->capture_default_str();
  app.add_option("--scene-unit-mm", options.scene_unit_mm, "endomapper-sim: mm per scene unit")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    const nrslam::SequenceInfo info = nrslam::ImportDataset(options, out);
    std::cout << "imported " << info.frame_count << " frames (" << info.camera.width() << "x" << info.camera.height()
              << ") into " << out << '\n';
  } catch (const std::exception& e) {
    std::cerr << "nrslam_import: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
