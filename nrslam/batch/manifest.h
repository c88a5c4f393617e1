// batch: the manifest, a JSON list of sequences to evaluate.
//
//   {
//     "description": "what this list is for",
//     "defaults": { "set": {"deformation.k": 1.1}, "simulate": {"frames": 60} },
//     "sequences": [
//       {"name": "sim-3", "preset": "sim-3", "simulate": {"camera.width": 320, "camera.height": 240}},
//       {"name": "mine", "path": "../data/mine", "first_frame": 10, "last_frame": 200, "rigid": true},
//       {"name": "h01", "import": {"format": "hamlyn", "path": "/data/hamlyn/rectified01"}},
//       {"name": "sim-3-defslam", "preset": "sim-3", "external": {"estimates": "defslam/sim-3.csv"}}
//     ]
//   }
//
// A sequence is a folder in the sequence format (`path`, relative to the manifest), a
// simulator preset (`preset`, with `simulate` options by their nrslam_simulate --set paths),
// or a public dataset on disk (`import`: "format", "path" and any nrslam_import option by its
// long name, e.g. "calibration", "max_frames", "scene_unit_mm"); presets and imports are
// made on demand into a cache. Per sequence and in `defaults`: `set` (run options by
// their nrslam_run --set path, or by a unique last name such as "k"), `init`, `rigid`,
// `first_frame`, `last_frame`, `camera` (a camera JSON used instead of the sequence's).
// A sequence with `external` is not run: another system's output on it is scored
// (system/external_result.h; keys "estimates", "trajectory", "stride", "name", paths relative to
// the manifest), so baselines sit in the same table; run options do not apply to it.
// Everything is validated when the manifest is loaded.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "nrslam/system/external_result.h"
#include "nrslam/util/json_options.h"

namespace nrslam {

struct ManifestSequence {
  std::string name;                       // unique within the manifest; names the run folder
  std::filesystem::path path;             // a sequence folder (absolute), or empty
  std::string preset;                     // simulator preset, or empty
  std::vector<std::string> simulate;      // simulator assignments "path=value", sorted
  std::vector<std::string> import;        // nrslam_import arguments (no --out), or empty
  std::vector<std::string> assignments;   // run assignments "module.option=value"
  bool rigid = false;
  ExternalResult external;                // scored instead of run when its estimates are given
  bool is_external() const { return !external.estimates.empty(); }
};

struct Manifest {
  std::filesystem::path file;
  std::string description;
  std::vector<ManifestSequence> sequences;
};

// Throws Error naming the manifest, the sequence and what is wrong.
Manifest LoadManifest(const std::filesystem::path& file);

// The manifest with only the sequences whose names match one of `patterns`, in the manifest's
// order. A pattern is a name or a shell wildcard ("sim-3*" is sim-3 and sim-3-rigid), so that
// one sequence of a long list can be run again with all its manifest settings. Throws Error
// when a pattern matches nothing, listing the names there are.
Manifest WithOnlySequences(const Manifest& manifest, const std::vector<std::string>& patterns);

}  // namespace nrslam
