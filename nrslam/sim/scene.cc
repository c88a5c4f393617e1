#include "nrslam/sim/scene.h"

#include "nrslam/sim/colon_scene.h"
#include "nrslam/sim/lobes_scene.h"

namespace nrslam {

std::unique_ptr<Scene> MakeScene(const SimOptions& options) {
  options.Check();
  if (options.scene == "lobes") return std::make_unique<LobesScene>(options);
  return std::make_unique<ColonScene>(options);
}

}  // namespace nrslam
