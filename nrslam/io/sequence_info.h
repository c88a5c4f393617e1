// io: the description of a sequence, as stored in its sequence.json.
#pragma once

#include <nlohmann/json.hpp>

#include <array>
#include <optional>
#include <string>

#include "nrslam/camera/camera.h"

namespace nrslam {

struct StereoInfo {
  double baseline_mm = 0.0;  // right camera = left translated by +baseline along camera x
  Camera right_camera;
};

struct SequenceInfo {
  Camera camera;
  double fps = 30.0;
  int frame_count = 0;
  double depth_unit_mm = 0.01;  // a depth PNG value v means v * depth_unit_mm millimetres
  std::optional<StereoInfo> stereo;
  std::string mask;             // optional fixed validity mask, path relative to the folder
  nlohmann::json provenance = nlohmann::json::object();  // generator and its parameters

  // Throws Error naming the first invalid field.
  void Check() const;
};

void to_json(nlohmann::json& j, const SequenceInfo& info);
void from_json(const nlohmann::json& j, SequenceInfo& info);

// What a sequence folder holds besides sequence.json and the mask it names: its per-frame PNG
// folders (rgb/ always; depth/, right/ and masks/ when present) and its trajectory.
inline constexpr std::array<const char*, 5> kSequenceEntries = {"rgb", "depth", "right", "masks", "groundtruth.tum"};

// "000037.png": the file name of frame `index` in every per-frame folder.
std::string FrameFileName(int index);

// The frame number in another program's or dataset's file name: the last run of digits in
// the stem, leading zeros or none ("depth_000123" and "0123_depth" → 123); nothing when the
// stem has no digits or its number is past 999999999.
std::optional<int> FrameNumberOf(const std::string& stem);

// Name order that reads each run of digits as a number, so that "frame_2.png" comes before
// "frame_10.png": folders numbered without leading zeros (ffmpeg's %d, C3VD's "12_color.png")
// keep their frames' order. Names that differ only in leading zeros fall back to plain order.
bool FrameNameLess(const std::string& a, const std::string& b);

}  // namespace nrslam
