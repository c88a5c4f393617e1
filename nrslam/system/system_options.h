// system: every option of a run, one struct per module, saved as config.json with the run.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

#include "nrslam/deformation/deformation_options.h"
#include "nrslam/eval/depth_evaluation.h"
#include "nrslam/frontend/frontend_options.h"
#include "nrslam/tracking/tracking_options.h"

namespace nrslam {

struct RunOptions {
  std::string init = "depth";  // "depth": the first frame's map from the sequence's depth
  bool mapping = false;        // DBA and new points (not available yet)
  bool reinitialise_after_loss = false;  // with --init depth this rebuilds the map from ground truth,
                                        // which would flatter a method that loses track: off, as in the
                                        // paper's tracking experiment (frames after a loss count as lost)
  int first_frame = 0;         // frame range to process, [first_frame, last_frame); -1 = to the end
  int last_frame = -1;
  std::string camera;          // a camera JSON (as in sequence.json) used instead of the sequence's; "" = its own
  void Check() const;
};
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(RunOptions, init, mapping, reinitialise_after_loss, first_frame, last_frame,
                                                camera)

struct SystemOptions {
  RunOptions run;
  FrontendOptions frontend;
  DeformationModelOptions deformation;
  TrackingOptions tracking;
  EvaluationOptions evaluation;
  void Check() const {
    run.Check();
    frontend.Check();
    deformation.Check();
    tracking.Check();
    evaluation.Check();
  }
};
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(SystemOptions, run, frontend, deformation, tracking, evaluation)

}  // namespace nrslam
