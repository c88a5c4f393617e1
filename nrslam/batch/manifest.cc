#include "nrslam/batch/manifest.h"

#include <fnmatch.h>

#include <algorithm>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "nrslam/datasets/dataset_import.h"
#include "nrslam/sim/sim_options.h"
#include "nrslam/system/system_options.h"
#include "nrslam/util/text_table.h"

namespace nrslam {

namespace {

const std::set<std::string> kManifestKeys = {"description", "defaults", "sequences"};
// The allowed keys of a sequence entry (and of "defaults", which has no name/path/preset/import).
const std::set<std::string> kSequenceKeys = {"name", "path", "preset", "import", "simulate", "set", "init",
                                             "rigid", "first_frame", "last_frame", "camera", "external"};
// The keys that configure an NR-SLAM run, which an external result does not have.
const std::set<std::string> kRunKeys = {"set", "init", "rigid", "first_frame", "last_frame", "camera"};
const std::set<std::string> kExternalKeys = {"estimates", "trajectory", "stride", "name"};

// The keys of an "import" object: nrslam_import's options by their long names.
const std::set<std::string> kImportKeys = {"format", "path", "calibration", "fps", "max_frames", "frame_step",
                                           "depth_unit_mm", "near", "far", "scene_unit_mm", "scale", "mask",
                                           "right", "stereo_layout", "second_calibration", "stereo_unit_mm",
                                           "rectified_size", "rectify_alpha", "stereo_depth", "stereo_set"};

void Require(bool condition, const std::string& context, const std::string& message) {
  if (!condition) throw Error(context + ": " + message);
}

// Why `key` is refused, with what it most likely meant. Where run options are allowed (a sequence
// entry, "defaults"), a run option's name, as --set takes it, is shown under "set", since the
// manifest's keys and nrslam_run's flags are easily confused ("mapping", "k").
std::string UnknownKey(const std::string& key, const Json& value, const std::set<std::string>& allowed,
                       bool run_options_allowed) {
  const std::string refused = "unknown key '" + key + "'";
  if (run_options_allowed) {
    if (const std::optional<std::string> option = FindOptionName(key, RunOptionPaths())) {
      return refused + ": run options go under \"set\", as in \"set\": {\"" + *option + "\": " + value.dump() + "}";
    }
  }
  const std::vector<std::string> keys(allowed.begin(), allowed.end());
  std::string message = refused + "; " + UnknownOptionHint(key, keys, "keys");
  // Nothing close: the key may be a run option under another name ("no_mapping").
  if (run_options_allowed && CloseOptionNames(key, keys).empty()) {
    message += "; run options go under \"set\", as in \"set\": {\"run.mapping\": false}";
  }
  return message;
}

// A path as the manifest gives it: relative ones are relative to the manifest's folder.
std::filesystem::path FromManifest(const std::string& path, const std::filesystem::path& folder) {
  std::filesystem::path file(path);
  if (file.is_relative()) file = folder / file;
  return file.lexically_normal();
}

ExternalResult ParseExternal(const Json& entry, const std::filesystem::path& folder, const std::string& context) {
  for (const std::string& key : kRunKeys) {
    Require(!entry.contains(key), context, "\"" + key + "\" configures an NR-SLAM run; an \"external\" result is scored as it is");
  }
  const Json& external = entry["external"];
  Require(external.is_object() && external.contains("estimates") && external["estimates"].is_string(), context,
          "\"external\" needs at least \"estimates\" (a CSV file or a folder of depth images)");
  ExternalResult result;
  for (const auto& [key, value] : external.items()) {
    Require(kExternalKeys.count(key) > 0, context, "external: " + UnknownKey(key, value, kExternalKeys, false));
    Require(key == "stride" ? value.is_number_integer() : value.is_string(), context,
            "external: \"" + key + "\" must be " + (key == "stride" ? "an integer" : "a string"));
  }
  result.estimates = FromManifest(external["estimates"], folder);
  if (external.contains("trajectory")) result.trajectory = FromManifest(external["trajectory"], folder);
  result.depth_stride_px = external.value("stride", result.depth_stride_px);
  result.name = external.value("name", "");
  try {
    result.Check();
  } catch (const Error& e) {
    throw Error(context + ": " + e.what());
  }
  return result;
}

// `entry` (a sequence or the defaults) with its "set" and "simulate" options by dotted names,
// so that a group written out ({"camera": {"width": 64}}) merges with the defaults field by field.
Json WithDottedOptions(Json entry, const std::string& context) {
  for (const char* key : {"set", "simulate"}) {
    if (!entry.is_object() || !entry.contains(key) || !entry[key].is_object()) continue;
    try {
      entry[key] = DottedOptions(entry[key]);
    } catch (const Error& e) {
      throw Error(context + ": " + key + ": " + e.what());
    }
  }
  return entry;
}

// Merges the defaults under an entry: objects ("set", "simulate") key by key, the rest whole.
Json WithDefaults(const Json& defaults, const Json& entry) {
  Json merged = defaults;
  for (const auto& [key, value] : entry.items()) {
    if (value.is_object() && merged.contains(key) && merged[key].is_object()) {
      merged[key].update(value);
    } else {
      merged[key] = value;
    }
  }
  // Default simulator options concern the presets only.
  if (!merged.contains("preset") && !entry.contains("simulate")) merged.erase("simulate");
  return merged;
}

ManifestSequence ParseSequence(const Json& entry, const std::filesystem::path& folder, const std::string& context) {
  Require(entry.is_object(), context, "each sequence must be a JSON object");
  for (const auto& [key, value] : entry.items()) {
    Require(kSequenceKeys.count(key) > 0, context, UnknownKey(key, value, kSequenceKeys, true));
  }
  ManifestSequence sequence;
  Require(entry.contains("name") && entry["name"].is_string() && !entry["name"].get<std::string>().empty(), context,
          "needs a \"name\"");
  sequence.name = entry["name"];
  Require(sequence.name.find_first_of("/\\ ") == std::string::npos && sequence.name != "." && sequence.name != "..",
          context, "name '" + sequence.name + "' must not contain '/', '\\' or spaces");
  const bool has_path = entry.contains("path"), has_preset = entry.contains("preset"), has_import = entry.contains("import");
  Require(has_path + has_preset + has_import == 1, context,
          "needs exactly one of \"path\" (a sequence folder), \"preset\" or \"import\"");
  if (has_import) {
    const Json& import = entry["import"];
    Require(import.is_object() && import.contains("format") && import.contains("path") && import["path"].is_string(),
            context, "\"import\" needs at least \"format\" and \"path\"");
    Require(!entry.contains("simulate"), context, "\"simulate\" only applies to a preset");
    for (const auto& [key, value] : import.items()) {
      Require(kImportKeys.count(key) > 0, context, "import: " + UnknownKey(key, value, kImportKeys, false));
      std::string text = value.is_string() ? value.get<std::string>() : value.dump();
      if (key == "path" || key == "calibration" || key == "mask" || key == "right" || key == "second_calibration") {
        text = FromManifest(text, folder).string();
      }
      std::string option = key == "path" ? "in" : key;
      std::replace(option.begin(), option.end(), '_', '-');
      Require(value.is_boolean() == (key == "stereo_depth"), context,
              "import: \"" + key +
                  (key == "stereo_depth" ? "\" must be true or false" : "\" takes a value, not true or false"));
      if (value.is_boolean()) {  // a flag: given when true
        if (value.get<bool>()) sequence.import.push_back("--" + option);
        continue;
      }
      if (key == "stereo_set") {  // an object of stereo depth options, as "set" holds run options
        Require(value.is_object(), context, "import: \"stereo_set\" must be an object, e.g. {\"min_depth_mm\": 20}");
        for (const auto& [name, setting] : value.items()) {
          sequence.import.push_back("--stereo-set");
          sequence.import.push_back(Assignment(name, setting));
        }
        continue;
      }
      sequence.import.push_back("--" + option);
      sequence.import.push_back(text);
    }
    const std::vector<std::string> formats = ImportFormats();
    Require(std::find(formats.begin(), formats.end(), import["format"]) != formats.end(), context,
            "import: unknown format " + import["format"].dump());
  } else if (has_path) {
    Require(entry["path"].is_string(), context, "\"path\" must be a string");
    sequence.path = FromManifest(entry["path"], folder);
    Require(!entry.contains("simulate"), context, "\"simulate\" only applies to a preset");
  } else {
    Require(entry["preset"].is_string(), context, "\"preset\" must be a string");
    sequence.preset = entry["preset"];
    SimOptions sim;
    try {
      sim = SimPreset(sequence.preset);
    } catch (const Error& e) {
      throw Error(context + ": " + e.what());
    }
    if (entry.contains("simulate")) {
      Require(entry["simulate"].is_object(), context, "\"simulate\" must be an object of simulator options");
      for (const auto& [key, value] : entry["simulate"].items()) {
        // A lens file to render with is, like every path in a manifest, relative to its folder.
        const bool lens_file = (key == "camera.calibration" || key == "calibration") && value.is_string() &&
                               !value.get<std::string>().empty();
        sequence.simulate.push_back(Assignment(key, lens_file ? Json(FromManifest(value, folder).string()) : value));
      }
      std::sort(sequence.simulate.begin(), sequence.simulate.end());
      try {
        WithAssignments(sim, sequence.simulate);
      } catch (const Error& e) {
        throw Error(context + ": simulate: " + e.what());
      }
    }
  }
  if (entry.contains("external")) {
    sequence.external = ParseExternal(entry, folder, context);
    return sequence;
  }
  if (entry.contains("set")) {
    Require(entry["set"].is_object(), context, "\"set\" must be an object of run options");
    for (const auto& [key, value] : entry["set"].items()) {
      try {
        sequence.assignments.push_back(Assignment(ResolveRunOption(key), value));
      } catch (const Error& e) {
        throw Error(context + ": set: " + e.what());
      }
    }
  }
  if (entry.contains("init")) sequence.assignments.push_back(Assignment("run.init", entry["init"]));
  if (entry.contains("first_frame")) sequence.assignments.push_back(Assignment("run.first_frame", entry["first_frame"]));
  if (entry.contains("last_frame")) sequence.assignments.push_back(Assignment("run.last_frame", entry["last_frame"]));
  if (entry.contains("camera")) {
    Require(entry["camera"].is_string(), context, "\"camera\" must be the path of a camera JSON file");
    sequence.assignments.push_back("run.camera=" + FromManifest(entry["camera"], folder).string());
  }
  if (entry.contains("rigid")) {
    Require(entry["rigid"].is_boolean(), context, "\"rigid\" must be true or false");
    sequence.rigid = entry["rigid"];
  }
  try {
    SystemOptions options;
    options.tracking.rigid = sequence.rigid;
    WithAssignments(options, sequence.assignments);
  } catch (const Error& e) {
    throw Error(context + ": " + e.what());
  }
  return sequence;
}

}  // namespace

Manifest LoadManifest(const std::filesystem::path& file) {
  const std::string where = "manifest " + file.string();
  Json json;
  try {
    json = ReadJsonFile(file);
  } catch (const Error& e) {
    throw Error(where + ": " + e.what());
  }
  Require(json.is_object(), where, "must be a JSON object with a \"sequences\" list");
  for (const auto& [key, value] : json.items()) {
    Require(kManifestKeys.count(key) > 0, where, UnknownKey(key, value, kManifestKeys, false));
  }
  Require(json.contains("sequences") && json["sequences"].is_array() && !json["sequences"].empty(), where,
          "needs a non-empty \"sequences\" list");
  Manifest manifest;
  manifest.file = std::filesystem::absolute(file);
  manifest.description = json.value("description", "");
  const Json defaults = WithDottedOptions(json.value("defaults", Json::object()), where + ", defaults");
  Require(defaults.is_object(), where, "\"defaults\" must be an object");
  std::set<std::string> default_keys = kSequenceKeys;
  for (const char* key : {"name", "path", "preset", "import"}) {
    Require(!defaults.contains(key), where, std::string("\"defaults\" cannot hold \"") + key + "\"");
    default_keys.erase(key);
  }
  // Checked here, or a mistake in them would be reported against the first sequence.
  for (const auto& [key, value] : defaults.items()) {
    Require(default_keys.count(key) > 0, where + ", defaults", UnknownKey(key, value, default_keys, true));
  }
  std::set<std::string> names;
  const auto& entries = json["sequences"];
  for (size_t i = 0; i < entries.size(); ++i) {
    const std::string context = where + ", sequence " + std::to_string(i + 1) +
                                (entries[i].is_object() && entries[i].contains("name") && entries[i]["name"].is_string()
                                     ? " ('" + entries[i]["name"].get<std::string>() + "')"
                                     : "");
    Require(entries[i].is_object(), context, "each sequence must be a JSON object");
    // The defaults' run settings are for the runs; an external result has none.
    Json entry_defaults = defaults;
    if (entries[i].contains("external")) {
      for (const std::string& key : kRunKeys) entry_defaults.erase(key);
    }
    ManifestSequence sequence =
        ParseSequence(WithDefaults(entry_defaults, WithDottedOptions(entries[i], context)), manifest.file.parent_path(),
                      context);
    Require(names.insert(sequence.name).second, context, "the name '" + sequence.name + "' is used twice");
    manifest.sequences.push_back(std::move(sequence));
  }
  return manifest;
}

Manifest WithOnlySequences(const Manifest& manifest, const std::vector<std::string>& patterns) {
  const auto matches = [](const std::string& pattern, const std::string& name) {
    return fnmatch(pattern.c_str(), name.c_str(), 0) == 0;
  };
  Manifest chosen = manifest;
  chosen.sequences.clear();
  std::vector<bool> used(patterns.size(), false);
  std::vector<std::string> names;
  for (const ManifestSequence& s : manifest.sequences) {
    names.push_back(s.name);
    bool wanted = false;
    for (size_t p = 0; p < patterns.size(); ++p) {
      if (matches(patterns[p], s.name)) used[p] = wanted = true;
    }
    if (wanted) chosen.sequences.push_back(s);
  }
  for (size_t p = 0; p < patterns.size(); ++p) {
    if (!used[p]) {
      throw Error(manifest.file.string() + ": no sequence matches \"" + patterns[p] + "\"; it has " + Join(names, ", "));
    }
  }
  return chosen;
}

}  // namespace nrslam
