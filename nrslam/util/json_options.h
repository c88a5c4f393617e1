// util: JSON round-trip and command-line overrides for options structs.
//
// Every module keeps its tunables in one options struct with defaults, a Check() and
// nlohmann to_json/from_json. These helpers give all of them the same behaviour:
// unknown keys are errors (a typo in a sweep must not silently run the default), and any
// field can be set from the command line as `path.to.field=value`, parsed with the type
// the field already has.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "nrslam/util/error.h"

namespace nrslam {

using Json = nlohmann::json;

// Throws Error naming every key of `given` that `reference` (the serialised defaults) lacks,
// or else every value whose kind (number, whole number, bool, string, list, group) differs
// from the same key's in `reference`, with the value it got.
void RejectMismatchedOptions(const Json& given, const Json& reference, const std::string& context);

// Applies one `a.b.c=value` assignment to `config`. The key must already exist; the value is
// parsed as the existing value's type (integer, number, bool, string, or a JSON/comma list
// for arrays). Throws Error with the known keys when the path is unknown.
void ApplyAssignment(Json& config, const std::string& assignment);

// "path=value" for a JSON value (strings unquoted): the inverse of ApplyAssignment.
std::string Assignment(const std::string& path, const Json& value);

// "path=value" for every leaf (as LeafPaths counts them) where `changed` differs from `base`;
// applied to `base` they give `changed`. Both must have the same keys.
std::vector<std::string> ChangedAssignments(const Json& base, const Json& changed);

// Parses a JSON file; throws Error "cannot open FILE", "FILE is a folder, not a JSON file" or "FILE
// is not valid JSON (why)".
Json ReadJsonFile(const std::filesystem::path& file);

// All leaf paths of a JSON object, dotted ("scene.amplitude_mm"), for help and error text.
std::vector<std::string> LeafPaths(const Json& config);

// `options` with its nested groups spelled as dotted names, {"camera": {"width": 64}} as
// {"camera.width": 64}, so that an object of options may be written either way (--print-options
// and config.json nest them, --set dots them). An empty group stays, to be named as one. Throws
// Error when one option is given both ways.
Json DottedOptions(const Json& options);

// The inverse: every dotted name as a nested group, {"camera.width": 64} as {"camera": {"width":
// 64}}; groups already nested stay. Throws Error when a name is given as a value and as a group.
Json NestedOptions(const Json& options);

// The last part of a dotted option path ("amplitude_mm"); the path itself when it has no dot.
std::string LastName(const std::string& path);

// The options a mistyped name most likely meant: those whose last part contains the name's last
// part ("sigma" finds every *sigma* option) or is within a few typing edits of it (two for a
// long name: "stretch_treshold"; none under 3 characters). Empty when none is that close.
std::vector<std::string> CloseOptionNames(const std::string& name, const std::vector<std::string>& paths);

// What an error says after "unknown option 'name'": "did you mean a or b?" with the
// CloseOptionNames, or when there are none "known <kind>: " and all of `paths`.
std::string UnknownOptionHint(const std::string& name, const std::vector<std::string>& paths,
                              const std::string& kind = "options");

// `name` as one of `paths`: the path itself, or the only path whose last part it is ("k" for
// "deformation.k"); nothing when no path or several match.
std::optional<std::string> FindOptionName(const std::string& name, const std::vector<std::string>& paths);
// The same, throwing Error "<kind> 'name' is unknown; <hint>" or "... is ambiguous: a, b".
std::string ResolveOptionName(const std::string& name, const std::vector<std::string>& paths, const std::string& kind);

// `object[key]` as T (int, double, std::string or std::vector<double>), for files a person may
// have written, such as sequence.json: a value of another kind is an Error "<context>: key
// must be a whole number, got 320.5" rather than a truncated number or nlohmann's
// "type_error.302" with no field named; a missing key is "<context>: missing field 'key'",
// or gives `fallback` in the second form.
template <typename T>
T Field(const Json& object, const std::string& key, const std::string& context);
template <typename T>
T Field(const Json& object, const std::string& key, const std::string& context, const T& fallback) {
  return object.contains(key) ? Field<T>(object, key, context) : fallback;
}

// Throws Error "<context>: unknown key 'name'; did you mean …?" (or the known keys) for the first
// key of `object` not in `known`. For files a person writes, such as sequence.json, where a
// misspelt key would otherwise be passed over and its default used without a word.
void RejectUnknownKeys(const Json& object, const std::vector<std::string>& known, const std::string& context);

// Parses options from JSON on top of `base` (the defaults unless given, e.g. a preset),
// rejecting unknown keys and values of the wrong kind, then Check()s. Groups may be nested or
// their fields named by dotted paths ("camera.width"), as --set names them.
template <typename Options>
Options OptionsFromJson(const Json& given, const std::string& context, const Options& base = Options{}) {
  const Json defaults = base;
  Json nested = given;
  if (given.is_object()) {
    try {
      nested = NestedOptions(given);
    } catch (const Error& e) {
      throw Error(context + ": " + e.what());
    }
  }
  RejectMismatchedOptions(nested, defaults, context);
  Json merged = defaults;
  merged.merge_patch(nested);
  Options options = merged.get<Options>();
  options.Check();
  return options;
}

// Applies command-line assignments to options and re-validates.
template <typename Options>
Options WithAssignments(const Options& options, const std::vector<std::string>& assignments) {
  Json config = options;
  for (const std::string& assignment : assignments) ApplyAssignment(config, assignment);
  Options result = config.get<Options>();
  result.Check();
  return result;
}

// Throws Error(context + ": " + what) unless `condition` holds. Used by Check() methods.
inline void CheckOption(bool condition, const std::string& context, const std::string& what) {
  if (!condition) throw Error(context + ": " + what);
}

}  // namespace nrslam
