#include "nrslam/io/sequence_info.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <string_view>

#include "nrslam/util/error.h"
#include "nrslam/util/json_options.h"

namespace nrslam {
namespace {

// What sequence.json's "format" and "version" say: a later version may mean fields this code
// would misread, so it is refused rather than run.
constexpr const char* kSequenceFormat = "nrslam-sequence";
constexpr int kSequenceVersion = 1;

bool IsDigit(char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }

}  // namespace

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
  j = nlohmann::json{{"format", kSequenceFormat},
                     {"version", kSequenceVersion},
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
  const std::string format = Field(j, "format", "sequence.json", std::string(kSequenceFormat));
  if (format != kSequenceFormat) {
    throw Error("sequence.json: format is '" + format + "', not '" + kSequenceFormat + "' (docs/data.md)");
  }
  const int version = Field(j, "version", "sequence.json", kSequenceVersion);
  if (version > kSequenceVersion) {
    throw Error("sequence.json: version " + std::to_string(version) + " is newer than this nrslam reads (" +
                std::to_string(kSequenceVersion) + ")");
  }
  RejectUnknownKeys(j, {"format", "version", "camera", "fps", "frame_count", "depth_unit_mm", "mask", "stereo",
                        "provenance"},
                    "sequence.json");
  if (!j.contains("camera")) throw Error("sequence.json: missing field 'camera'");
  info.camera = j.at("camera").get<Camera>();
  info.fps = Field<double>(j, "fps", "sequence.json");
  info.frame_count = Field<int>(j, "frame_count", "sequence.json");
  info.depth_unit_mm = Field(j, "depth_unit_mm", "sequence.json", 0.01);
  info.mask = Field(j, "mask", "sequence.json", std::string());
  info.provenance = j.value("provenance", nlohmann::json::object());
  info.stereo.reset();
  if (j.contains("stereo")) {
    const nlohmann::json& stereo = j.at("stereo");
    if (!stereo.is_object()) throw Error("sequence.json: stereo must be a group, got " + stereo.dump());
    RejectUnknownKeys(stereo, {"baseline_mm", "right_camera"}, "sequence.json: stereo");
    StereoInfo stereo_info;
    stereo_info.baseline_mm = Field<double>(stereo, "baseline_mm", "sequence.json: stereo");
    stereo_info.right_camera = stereo.contains("right_camera") ? stereo.at("right_camera").get<Camera>() : info.camera;
    info.stereo = stereo_info;
  }
  info.Check();
}

std::optional<int> FrameNumberOf(const std::string& stem) {
  size_t end = stem.size();
  while (end > 0 && !IsDigit(stem[end - 1])) --end;
  size_t begin = end;
  while (begin > 0 && IsDigit(stem[begin - 1])) --begin;
  if (begin == end) return std::nullopt;
  while (begin + 1 < end && stem[begin] == '0') ++begin;  // Hamlyn pads to ten digits
  if (end - begin > 9) return std::nullopt;
  return std::stoi(stem.substr(begin, end - begin));
}

bool FrameNameLess(const std::string& a, const std::string& b) {
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (!IsDigit(a[i]) || !IsDigit(b[j])) {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i, ++j;
      continue;
    }
    size_t end_a = i, end_b = j;
    while (end_a < a.size() && IsDigit(a[end_a])) ++end_a;
    while (end_b < b.size() && IsDigit(b[end_b])) ++end_b;
    while (i + 1 < end_a && a[i] == '0') ++i;
    while (j + 1 < end_b && b[j] == '0') ++j;
    const std::string_view number_a(a.data() + i, end_a - i), number_b(b.data() + j, end_b - j);
    if (number_a.size() != number_b.size()) return number_a.size() < number_b.size();
    if (number_a != number_b) return number_a < number_b;
    i = end_a, j = end_b;
  }
  if (i == a.size() && j == b.size()) return a < b;
  return i == a.size();
}

std::string FrameFileName(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.png", index);
  return name;
}

}  // namespace nrslam
