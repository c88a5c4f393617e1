#include "nrslam/io/camera_file.h"

#include "nrslam/util/json_options.h"

namespace nrslam {

Camera ReadCameraFile(const std::filesystem::path& file) {
  const Json json = ReadJsonFile(file);
  try {
    // A sequence.json holds the camera under "camera"; taking it saves users cutting it out.
    const bool sequence_file = json.is_object() && json.contains("camera") && json.at("camera").is_object();
    Camera camera = (sequence_file ? json.at("camera") : json).get<Camera>();
    camera.Check();
    return camera;
  } catch (const std::exception& e) {
    throw Error("camera file " + file.string() + ": " + e.what());
  }
}

}  // namespace nrslam
