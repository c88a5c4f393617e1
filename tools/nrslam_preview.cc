// nrslam_preview: writes one frame of a sequence as a PNG — the colour image beside its
// ground-truth depth in false colour (near = red, far = blue, black = none).
#include <CLI/CLI.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <iostream>

#include "nrslam/io/sequence_reader.h"
#include "nrslam/util/error.h"
#include "nrslam/util/source_revision.h"

int main(int argc, char** argv) {
  CLI::App app{"Write a frame of a sequence (colour | depth) as a PNG."};
  app.set_version_flag("--version", nrslam::VersionString());
  std::string sequence, out;
  int frame = 0;
  double scale = 1.0, near_mm = 10.0, far_mm = 120.0;
  app.add_option("sequence", sequence, "sequence folder")->required();
  app.add_option("--frame", frame, "frame index")->capture_default_str();
  app.add_option("--out", out, "output PNG")->required();
  app.add_option("--scale", scale, "resize factor")->capture_default_str();
  app.add_option("--near", near_mm, "depth shown red, mm")->capture_default_str();
  app.add_option("--far", far_mm, "depth shown blue, mm")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    const nrslam::SequenceReader reader(sequence);
    cv::Mat panel = reader.ReadRgb(frame);
    if (reader.has_depth()) {
      const cv::Mat depth = reader.ReadDepthMm(frame);
      cv::Mat level;
      depth.convertTo(level, CV_8U, -255.0 / (far_mm - near_mm), 255.0 * far_mm / (far_mm - near_mm));
      cv::Mat coloured;
      cv::applyColorMap(level, coloured, cv::COLORMAP_TURBO);
      coloured.setTo(cv::Scalar::all(0), depth <= 0);
      cv::hconcat(panel, coloured, panel);
    }
    if (scale != 1.0) cv::resize(panel, panel, cv::Size(), scale, scale, cv::INTER_AREA);
    if (!cv::imwrite(out, panel)) throw nrslam::Error("cannot write " + out);
  } catch (const std::exception& e) {
    std::cerr << "nrslam_preview: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
