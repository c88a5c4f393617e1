// system: every option of a run, one struct per module, saved as config.json with the run.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "nrslam/deformation/deformation_options.h"
#include "nrslam/eval/depth_evaluation.h"
#include "nrslam/frontend/frontend_options.h"
#include "nrslam/mapping/mapping_options.h"
#include "nrslam/tracking/tracking_options.h"

namespace nrslam {

struct RunOptions {
  std::string init = "monocular";  // "monocular": the map from the images alone (essential matrix),
                                   // the full NR-SLAM; "depth": the first frame's map from the
                                   // sequence's depth (the paper's tracking experiment)
  bool mapping = true;             // keyframes, DBA and new points; false = tracking only
  // Only for --init depth, where it would rebuild the map from ground truth and flatter a
  // method that loses track: off, as in the paper's tracking experiment (frames after a loss
  // count as lost). A monocular run always re-initialises from the images after a loss.
  bool reinitialise_after_loss = false;
  int first_frame = 0;         // frame range to process, [first_frame, last_frame); -1 = to the end
  int last_frame = -1;
  std::string camera;          // a calibration file (io/camera_file.h) used instead of the sequence's; "" = its own
  // A monocular map whose median point depth, in its own units, moves beyond this factor from
  // its first frame either way (system/run_files.h, DepthChange) is given up: its scale has
  // collapsed. A new map is started from the images, as after a loss, while the old one tracks
  // on, and takes over on the frame it starts, so no frame is left untracked. 0 = never.
  // Not in the paper. 10 leaves every measured 120-frame run as it was (the farthest, a colon
  // rendering, moves 9.7×) and restarts a deforming colon's map every ~200 frames, which keeps a
  // 1000-frame run's camera from drifting away with the scale (docs/tracking.md, "A collapsing map is replaced").
  double restart_on_depth_change = 10;
  void Check() const;
};
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(RunOptions, init, mapping, reinitialise_after_loss, first_frame, last_frame,
                                                camera, restart_on_depth_change)

struct SystemOptions {
  RunOptions run;
  FrontendOptions frontend;
  DeformationModelOptions deformation;
  TrackingOptions tracking;
  InitialisationOptions initialisation;
  MappingOptions mapping;
  EvaluationOptions evaluation;
  void Check() const {
    run.Check();
    frontend.Check();
    deformation.Check();
    tracking.Check();
    initialisation.Check();
    mapping.Check();
    evaluation.Check();
  }
};
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(SystemOptions, run, frontend, deformation, tracking, initialisation,
                                                mapping, evaluation)

// Options from a JSON file over the defaults: a run folder's config.json (its "options") or a
// bare options object, whole or partial. Unknown keys are errors, so a saved run is repeated
// exactly or not at all.
SystemOptions SystemOptionsFromFile(const std::filesystem::path& file);
// "path=value" for every option that differs from its default: applied to the defaults they
// give `options` back. How a file's configuration joins a batch's --set list.
std::vector<std::string> AssignmentsOverDefaults(const SystemOptions& options);

// Every run option's full path ("deformation.k"), in config.json's order.
const std::vector<std::string>& RunOptionPaths();
// A run option's full path from a full path or a unique last name ("k" → "deformation.k");
// throws Error listing the candidates when unknown or ambiguous.
std::string ResolveRunOption(const std::string& name);
// "name=value" with the name resolved as above; throws Error without an "=".
std::string ResolveRunAssignment(const std::string& assignment);
// `options` with a command line's --set list applied in order, names resolved as above;
// throws Error on an unknown name or a value the options' Check() refuses.
SystemOptions WithRunAssignments(const SystemOptions& options, const std::vector<std::string>& assignments);

}  // namespace nrslam
