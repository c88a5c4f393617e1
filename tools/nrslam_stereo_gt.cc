// nrslam_stereo_gt: dense depth ground truth for a stereo sequence (one with right/ and a
// baseline in sequence.json, e.g. an imported Hamlyn sequence): SGBM in both directions with
// a left–right check, depth = f·B/d, written as the sequence's depth/.
#include <CLI/CLI.hpp>

#include <filesystem>
#include <iostream>
#include <vector>

#include "documentation_footer.h"
#include "nrslam/datasets/stereo_depth.h"
#include "nrslam/io/sequence_reader.h"
#include "nrslam/io/sequence_writer.h"
#include "nrslam/util/json_options.h"
#include "nrslam/util/progress_line.h"
#include "nrslam/util/source_revision.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  CLI::App app{"Depth ground truth from the rectified stereo pairs of a sequence"};
  app.set_version_flag("--version", nrslam::VersionString());
  app.footer(DocumentationFooter("docs/eval.md, \"Depth from stereo\""));
  std::string folder;
  std::vector<std::string> assignments;
  bool overwrite = false, quiet = false;
  app.add_option("sequence", folder, "sequence folder with right/ images")->required();
  app.add_option("--set", assignments, "stereo option, e.g. --set min_depth_mm=20 (min_depth_mm, block_size, "
                                       "uniqueness_ratio, max_lr_difference_px, speckle_window, speckle_range)");
  app.add_flag("--overwrite", overwrite, "replace an existing depth/");
  app.add_flag("--quiet", quiet, "no progress line");
  CLI11_PARSE(app, argc, argv);
  fs::path staging;  // where the depth is written until it is whole
  try {
    const nrslam::StereoDepthOptions options = nrslam::WithAssignments(nrslam::StereoDepthOptions{}, assignments);
    const nrslam::SequenceReader sequence(folder);
    if (!sequence.has_right() || !sequence.info().stereo) {
      throw nrslam::Error(folder + " has no right images and stereo baseline (sequence.json \"stereo\")");
    }
    // Disparity is depth only along the rows of a rectified pinhole pair; a lens with distortion
    // would give depth that looks right and is not.
    if (sequence.info().camera.model() != nrslam::CameraModelId::kPinhole) {
      throw nrslam::Error(folder + ": stereo depth needs a rectified pair with a pinhole camera, and this sequence's is " +
                          sequence.info().camera.model_name() +
                          " (import the raw pair with nrslam_import --format stereo, which rectifies it)");
    }
    if (sequence.has_depth() && !overwrite) throw nrslam::Error(folder + " already has depth/ (use --overwrite)");
    nrslam::SequenceInfo info = sequence.info();
    info.provenance["depth"] = {{"generator", std::string("nrslam_stereo_gt ") + NRSLAM_VERSION},
                                {"options", nrslam::Json(options)}};
    // The depth is written beside the sequence and swapped in whole at the end, so a run that
    // stops early leaves the sequence as it was (with --overwrite, its old depth too).
    staging = fs::path(folder) / ".stereo_gt_in_progress";
    fs::remove_all(staging);
    const nrslam::SequenceWriter staged(staging, info, true);
    nrslam::ProgressLine progress = nrslam::ProgressLine::OnStderr();
    std::vector<int> unreadable;  // frames whose pair could not be read: no depth (0) there
    const cv::Mat no_depth = cv::Mat::zeros(info.camera.height(), info.camera.width(), CV_32F);
    for (int i = 0; i < sequence.frame_count(); ++i) {
      // Only reading is forgiven: an error of the matching itself still ends the tool.
      cv::Mat left, right;
      try {
        left = sequence.ReadRgb(i);
        right = sequence.ReadRight(i);
      } catch (const nrslam::Error& e) {
        std::cerr << "nrslam_stereo_gt: frame " << i << ": " << e.what() << "; written without depth\n";
        unreadable.push_back(i);
      }
      staged.WriteDepthMm(i, left.empty() || right.empty()
                                 ? no_depth
                                 : nrslam::StereoDepthMm(left, right, info.camera.fx(), info.stereo->baseline_mm, options));
      if (!quiet) {
        progress.Update("depth " + std::to_string(i + 1) + "/" + std::to_string(sequence.frame_count()),
                        i + 1 == sequence.frame_count());
      }
    }
    if (!unreadable.empty()) info.provenance["depth"]["frames_without_input"] = unreadable;
    fs::remove_all(fs::path(folder) / "depth");
    fs::rename(staging / "depth", fs::path(folder) / "depth");
    // Constructing the writer rewrites sequence.json, which now lists the depth's provenance.
    const nrslam::SequenceWriter with_depth(folder, info, true, nrslam::SequenceWriter::Target::kExistingSequence);
    fs::remove_all(staging);
    std::cout << "wrote depth for " << sequence.frame_count() << " frames into " << folder << "/depth";
    if (!unreadable.empty()) {
      std::cout << " (" << unreadable.size() << " without depth: their images could not be read; sequence.json "
                << "lists them under provenance.depth.frames_without_input)";
    }
    std::cout << '\n';
  } catch (const std::exception& e) {
    std::error_code ignored;
    if (!staging.empty()) fs::remove_all(staging, ignored);
    std::cerr << "nrslam_stereo_gt: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
