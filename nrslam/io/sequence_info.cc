#include "nrslam/io/sequence_info.h"

#include <cmath>
#include <cstdio>

#include "nrslam/util/error.h"

namespace nrslam {

void SequenceInfo::Check() const {
  camera.Check();
  if (!(fps > 0) || !std::isfinite(fps)) throw Error("sequence.json: fps must be > 0, got " + std::to_string(fps));
  if (frame_count <= 0) {
    throw Error("sequence.json: the sequence is empty (frame_count = " + std::to_string(frame_count) + ")");
  }
  if (!(depth_unit_mm > 0) || !std::isfinite(depth_unit_mm)) {
    throw Error("sequence.json: depth_unit_mm must be > 0, got " + std::to_string(depth_unit_mm));
  }
  if (stereo) {
    if (!(stereo->baseline_mm > 0)) throw Error("sequence.json: stereo baseline_mm must be > 0");
    stereo->right_camera.Check();
  }
}

void to_json(nlohmann::json& j, const SequenceInfo& info) {
  j = nlohmann::json{{"format", "nrslam-sequence"},
                     {"version", 1},
                     {"camera", info.camera},
                     {"fps", info.fps},
                     {"frame_count", info.frame_count},
                     {"depth_unit_mm", info.depth_unit_mm},
                     {"provenance", info.provenance}};
  if (info.stereo) {
    j["stereo"] = {{"baseline_mm", info.stereo->baseline_mm}, {"right_camera", info.stereo->right_camera}};
  }
  if (!info.mask.empty()) j["mask"] = info.mask;
}

void from_json(const nlohmann::json& j, SequenceInfo& info) {
  if (!j.is_object()) throw Error("sequence.json: expected a JSON object");
  for (const char* key : {"camera", "fps", "frame_count"}) {
    if (!j.contains(key)) throw Error(std::string("sequence.json: missing field '") + key + "'");
  }
  try {
    info.camera = j.at("camera").get<Camera>();
    info.fps = j.at("fps").get<double>();
    info.frame_count = j.at("frame_count").get<int>();
    info.depth_unit_mm = j.value("depth_unit_mm", 0.01);
    info.mask = j.value("mask", std::string());
    info.provenance = j.value("provenance", nlohmann::json::object());
    info.stereo.reset();
    if (j.contains("stereo")) {
      const auto& stereo = j.at("stereo");
      StereoInfo stereo_info;
      stereo_info.baseline_mm = stereo.at("baseline_mm").get<double>();
      stereo_info.right_camera = stereo.contains("right_camera") ? stereo.at("right_camera").get<Camera>() : info.camera;
      info.stereo = stereo_info;
    }
  } catch (const nlohmann::json::exception& e) {
    throw Error(std::string("sequence.json: malformed field: ") + e.what());
  }
  info.Check();
}

std::string FrameFileName(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.png", index);
  return name;
}

}  // namespace nrslam
