#include "nrslam/system/system_options.h"

#include "nrslam/util/json_options.h"

namespace nrslam {

void RunOptions::Check() const {
  CheckOption(init == "depth" || init == "monocular", "run", "init must be depth or monocular, got '" + init + "'");
  CheckOption(init != "monocular", "run", "monocular initialisation is not available yet (it comes with mapping)");
  CheckOption(!mapping, "run", "mapping is not available yet: run with --no-mapping");
  CheckOption(first_frame >= 0 && (last_frame < 0 || last_frame > first_frame), "run", "bad frame range");
}

}  // namespace nrslam
