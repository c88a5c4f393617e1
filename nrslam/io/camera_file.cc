#include "nrslam/io/camera_file.h"

#include <nlohmann/json.hpp>

#include <fstream>

#include "nrslam/util/error.h"

namespace nrslam {

Camera ReadCameraFile(const std::filesystem::path& file) {
  std::ifstream stream(file);
  if (!stream) throw Error("cannot read the camera file " + file.string());
  try {
    Camera camera = nlohmann::json::parse(stream).get<Camera>();
    camera.Check();
    return camera;
  } catch (const std::exception& e) {
    throw Error("camera file " + file.string() + ": " + e.what());
  }
}

}  // namespace nrslam
