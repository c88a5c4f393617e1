#include "nrslam/io/camera_file.h"

#include "nrslam/util/json_options.h"

namespace nrslam {

Camera ReadCameraFile(const std::filesystem::path& file) {
  const Json json = ReadJsonFile(file);
  try {
    Camera camera = json.get<Camera>();
    camera.Check();
    return camera;
  } catch (const std::exception& e) {
    throw Error("camera file " + file.string() + ": " + e.what());
  }
}

}  // namespace nrslam
