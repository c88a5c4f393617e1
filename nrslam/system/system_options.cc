#include "nrslam/system/system_options.h"

#include "nrslam/util/json_options.h"

namespace nrslam {

void RunOptions::Check() const {
  CheckOption(init == "depth" || init == "monocular", "run", "init must be depth or monocular, got '" + init + "'");
  CheckOption(first_frame >= 0 && (last_frame < 0 || last_frame > first_frame), "run", "bad frame range");
}

}  // namespace nrslam
