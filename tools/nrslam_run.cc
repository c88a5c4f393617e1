// nrslam_run: runs NR-SLAM offline over one sequence and writes the run folder
// (config, trajectory, tracked points, estimated depth, per-frame metrics, summary, map).
#include <CLI/CLI.hpp>

#include <iostream>

#include "documentation_footer.h"
#include "nrslam/system/run_sequence.h"
#include "nrslam/util/json_options.h"
#include "nrslam/util/progress_line.h"
#include "nrslam/util/source_revision.h"

int main(int argc, char** argv) {
  CLI::App app{"Run NR-SLAM over a sequence and write its run folder."};
  app.set_version_flag("--version", nrslam::VersionString());
  app.footer(DocumentationFooter("docs/tracking.md (the runner, the run folder) and docs/mapping.md (the monocular "
                                 "system); every option: --print-options"));
  std::string sequence, out, config_path, init;
  bool rigid = false, no_mapping = false, quiet = false, print_options = false;
  std::vector<std::string> assignments;
  // Not marked required: --print-options needs neither (checked after parsing).
  app.add_option("sequence", sequence, "sequence folder (required unless --print-options)");
  app.add_option("--out", out, "run folder to write (required unless --print-options)");
  app.add_option("--config", config_path, "JSON options applied over the defaults: a run folder's config.json (to repeat that run) or an options object");
  app.add_option("--init", init, "monocular (the map from the images: full NR-SLAM, the default) or depth (from the sequence's depth)");
  app.add_flag("--rigid", rigid, "rigid baseline: no deformation");
  app.add_flag("--no-mapping", no_mapping, "tracking only, no keyframe DBA or new points (the paper's Table II experiment)");
  app.add_option("--set", assignments, "set any option by its path or a unique last name, e.g. --set deformation.k=2 or --set k=2 (see --print-options)");
  app.add_flag("--print-options", print_options, "print every option as JSON and exit");
  app.add_flag("--quiet", quiet, "no progress line");
  CLI11_PARSE(app, argc, argv);
  if (!print_options && (sequence.empty() || out.empty())) {
    std::cerr << "nrslam_run: " << (sequence.empty() ? "a sequence folder" : "--out") << " is required\n"
              << "Run with --help for more information.\n";
    return 1;
  }
  try {
    // Defaults, then the file, then the flags given, then --set: each overrides the one before.
    nrslam::SystemOptions options = config_path.empty() ? nrslam::SystemOptions{} : nrslam::SystemOptionsFromFile(config_path);
    if (!init.empty()) options.run.init = init;
    if (rigid) options.tracking.rigid = true;
    if (no_mapping) options.run.mapping = false;
    options = nrslam::WithRunAssignments(options, assignments);
    if (print_options) {
      std::cout << nrslam::Json(options).dump(2) << '\n';
      return 0;
    }
    nrslam::ProgressLine progress = nrslam::ProgressLine::OnStderr();
    const nrslam::RunSummary summary = nrslam::RunSequence(sequence, options, out, [&](int done, int total, const std::string& line) {
      if (!quiet) progress.Update(line, done == total);
    });
    std::cout << nrslam::DescribeSummary(summary) << '\n';
    std::cout << "run folder: " << out << '\n';
  } catch (const std::exception& e) {
    std::cerr << "nrslam_run: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
