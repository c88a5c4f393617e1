// nrslam_import: converts a public dataset on disk (Endomapper simulated, Hamlyn in either layout,
// C3VD, a plain video / image folder with a calibration, or a raw stereo recording with its
// stereo calibration, rectified) into a sequence folder that nrslam_run and nrslam_eval read.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <iostream>

#include "documentation_footer.h"
#include "nrslam/datasets/dataset_import.h"
#include "nrslam/util/error.h"
#include "nrslam/util/json_options.h"
#include "nrslam/util/source_revision.h"

int main(int argc, char** argv) {
  CLI::App app{"Import a dataset into the nrslam sequence format"};
  app.set_version_flag("--version", nrslam::VersionString());
  app.footer(DocumentationFooter("docs/eval.md, \"Public datasets on your disk\" and \"Raw stereo recordings\""));
  nrslam::ImportOptions options;
  std::string out;
  app.add_option("--format", options.format, "endomapper-sim, hamlyn, c3vd, images or stereo")->required();
  app.add_option("--in", options.input, "the dataset's folder (or a video file for --format images and stereo)")
      ->required();
  app.add_option("--out", out, "sequence folder to write")->required();
  app.add_option("--calibration", options.calibration,
                 "camera JSON (as in sequence.json), OCamCalib's calib_results.txt or an OpenCV / ROS calibration "
                 "(.yml, .yaml, .xml); c3vd and images need one; stereo needs the pair's stereo calibration (OpenCV's "
                 "M1 D1 M2 D2 R T, Kalibr's camchain, or ROS camera_info with --second-calibration)");
  app.add_option("--mask", options.mask,
                 "fixed validity mask of the images (non-zero = usable), e.g. the black border of an endoscope's image");
  app.add_option("--fps", options.fps, "the dataset's frames per second")->capture_default_str();
  app.add_option("--max-frames", options.max_frames, "import at most this many frames (0 = all)")->capture_default_str();
  app.add_option("--frame-step", options.frame_step,
                 "keep every Nth frame (2 turns a 50 fps video into 25 fps; the sequence's fps is divided by it)")
      ->capture_default_str();
  app.add_option("--depth-unit-mm", options.depth_unit_mm, "resolution of the written depth, mm")->capture_default_str();
  app.add_option("--scale", options.scale,
                 "resize every image, depth map and the calibration by this factor, in (0, 4] (0.5 halves 1440x1080 to 720x540)")
      ->capture_default_str();
  app.add_option("--right", options.right, "stereo: the right camera's images (folder or video)");
  app.add_option(
      "--stereo-layout", options.stereo_layout,
      "stereo: both views in each input image, side-by-side (left half = left camera) or top-bottom (top = left)");
  app.add_option("--second-calibration", options.second_calibration,
                 "stereo: a second calibration file: R and T of OpenCV's stereo_calib extrinsics.yml, or the right "
                 "camera's ROS camera_info");
  app.add_option("--stereo-unit-mm", options.stereo_unit_mm,
                 "stereo: mm per unit of the calibration's translation; 0 = the format's own (OpenCV's names: mm; "
                 "Kalibr, ROS: metres)")
      ->capture_default_str();
  std::string rectified_size;
  app.add_option(
      "--rectified-size", rectified_size,
      "stereo: rectified image size WxH (default: the calibration's, stretched to square pixels when they are not)");
  app.add_option("--rectify-alpha", options.rectify_alpha,
                 "stereo: cv::stereoRectify's alpha in [0, 1] (0: only pixels both views see) or -1 (OpenCV's default)")
      ->capture_default_str();
  app.add_flag("--stereo-depth", options.stereo_depth,
               "write depth from the rectified pairs (semi-global matching, as nrslam_stereo_gt): stereo, or hamlyn "
               "without depth01/");
  std::vector<std::string> stereo_settings;
  app.add_option("--stereo-set", stereo_settings,
                 "an option of --stereo-depth as nrslam_stereo_gt's --set, e.g. --stereo-set min_depth_mm=20 (fewer "
                 "disparities to search)");
  app.add_option("--near", options.near, "endomapper-sim: near plane, scene units")->capture_default_str();
  app.add_option("--far", options.far, "endomapper-sim: far plane, scene units")->capture_default_str();
  app.add_option("--scene-unit-mm", options.scene_unit_mm, "endomapper-sim: mm per scene unit")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    options.stereo_depth_options = nrslam::WithAssignments(options.stereo_depth_options, stereo_settings);
    if (!rectified_size.empty()) {
      char separator = 0, rest = 0;
      if (std::sscanf(rectified_size.c_str(), "%d%c%d%c", &options.rectified_width, &separator,
                      &options.rectified_height, &rest) != 3 ||
          (separator != 'x' && separator != 'X') || options.rectified_width <= 0 || options.rectified_height <= 0) {
        throw nrslam::Error("--rectified-size: expected WIDTHxHEIGHT, e.g. 720x576, got '" + rectified_size + "'");
      }
    }
    const nrslam::SequenceInfo info = nrslam::ImportDataset(options, out);
    std::cout << "imported " << info.frame_count << " frames (" << info.camera.width() << "x" << info.camera.height()
              << ") into " << out;
    if (info.stereo) std::cout << ", stereo baseline " << info.stereo->baseline_mm << " mm";
    std::cout << '\n';
  } catch (const std::exception& e) {
    std::cerr << "nrslam_import: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
