// nrslam_simulate: renders simulated endoscopy sequences (colonoscopy presets sim-0…sim-6
// with the paper's (A, ω), and the laparoscopic lap-lobes) with exact depth ground truth.
#include <CLI/CLI.hpp>

#include <filesystem>
#include <iostream>

#include "documentation_footer.h"
#include "nrslam/io/sequence_writer.h"
#include "nrslam/sim/simulate.h"
#include "nrslam/util/json_options.h"
#include "nrslam/util/progress_line.h"
#include "nrslam/util/source_revision.h"
#include "nrslam/util/text_table.h"

int main(int argc, char** argv) {
  CLI::App app{"Render simulated endoscopy sequences with exact depth ground truth."};
  app.set_version_flag("--version", nrslam::VersionString());
  app.footer(DocumentationFooter("docs/data.md (presets, scene, deformation law, sequence format)"));
  std::string preset = "sim-0", out, config_path, camera_model;
  bool suite = false, stereo = false, print_options = false, quiet = false;
  int frames = 0, width = 0, height = 0;
  int64_t seed = 0;
  std::vector<std::string> assignments;
  app.add_option("--preset", preset, "sim-0 … sim-6, lap-lobes")->capture_default_str();
  app.add_flag("--suite", suite, "render every preset into OUT/<preset> and print a summary table");
  app.add_option("--out", out, "output sequence folder (with --suite: parent folder)");
  app.add_option("--config", config_path, "JSON file of simulator options applied over the preset");
  // Given values go to the options as they are, so that their Check() rejects a bad one.
  const CLI::Option* frames_given = app.add_option("--frames", frames, "number of frames");
  const CLI::Option* width_given = app.add_option("--width", width, "image width, px");
  const CLI::Option* height_given = app.add_option("--height", height, "image height, px");
  const CLI::Option* seed_given =
      app.add_option("--seed", seed, "random seed (same seed and options = identical files)");
  app.add_option("--camera", camera_model, "pinhole or fisheye")->check(CLI::IsMember({"pinhole", "fisheye"}));
  app.add_flag("--stereo", stereo, "also render a rectified right camera");
  app.add_option("--set", assignments, "set any option, e.g. --set deformation.amplitude_mm=5 (see --print-options)");
  app.add_flag("--print-options", print_options, "print the resolved options as JSON and exit");
  app.add_flag("--quiet", quiet, "no progress line");
  bool overwrite = false;
  app.add_flag("--overwrite", overwrite, "replace a sequence already in the output folder (its sequence.json, rgb/, "
                                         "depth/, right/, masks/, groundtruth.tum and mask; other files stay)");
  CLI11_PARSE(app, argc, argv);

  try {
    auto resolve = [&](const std::string& name) {
      nrslam::SimOptions options = nrslam::SimPreset(name);
      if (!config_path.empty()) {
        options = nrslam::OptionsFromJson(nrslam::ReadJsonFile(config_path), config_path, options);
      }
      if (frames_given->count()) options.frames = frames;
      if (width_given->count()) options.camera.width = width;
      if (height_given->count()) options.camera.height = height;
      if (seed_given->count()) {
        if (seed < 0) throw nrslam::Error("--seed must be >= 0, got " + std::to_string(seed));
        options.seed = static_cast<uint64_t>(seed);
      }
      if (!camera_model.empty()) options.camera.model = camera_model;
      if (stereo) options.camera.stereo = true;
      return nrslam::WithAssignments(options, assignments);
    };
    if (print_options) {
      std::cout << nrslam::Json(resolve(preset)).dump(2) << '\n';
      return 0;
    }
    if (out.empty()) throw nrslam::Error("--out is required");

    const std::vector<std::string> names = suite ? nrslam::SimPresetNames() : std::vector<std::string>{preset};
    nrslam::TextTable table({"sequence", "frames", "resolution", "camera", "depth min (mm)", "depth max (mm)",
                             "render ms/frame", "write ms/frame"});
    nrslam::ProgressLine progress = nrslam::ProgressLine::OnStderr();
    for (const std::string& name : names) {
      const nrslam::SimOptions options = resolve(name);
      const std::filesystem::path folder = suite ? std::filesystem::path(out) / name : std::filesystem::path(out);
      if (overwrite) nrslam::RemoveSequence(folder);
      const auto summary = nrslam::SimulateSequence(options, name, folder, [&](int done, int total, double ms) {
        if (quiet) return;
        progress.Update("rendering " + name + ": frame " + std::to_string(done) + "/" + std::to_string(total) + " (" +
                            nrslam::FormatFixed(ms, 1) + " ms/frame)",
                        done == total);
      });
      table.AddRow({name, std::to_string(summary.frames),
                    std::to_string(summary.width) + "x" + std::to_string(summary.height),
                    (options.camera.calibration.empty() ? options.camera.model : "calibration " + options.camera.calibration) +
                        (options.camera.stereo ? "+stereo" : ""),
                    nrslam::FormatFixed(summary.depth_min_mm, 1), nrslam::FormatFixed(summary.depth_max_mm, 1),
                    nrslam::FormatFixed(summary.render_ms_per_frame, 1),
                    nrslam::FormatFixed(summary.write_ms_per_frame, 1)});
    }
    std::cout << '\n';
    table.Print(std::cout);
    std::cout << "\nsequences written to " << out << '\n';
  } catch (const std::exception& e) {
    std::cerr << "\nnrslam_simulate: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
