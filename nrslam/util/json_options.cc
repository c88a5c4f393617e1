#include "nrslam/util/json_options.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <type_traits>

#include "nrslam/util/text_file.h"
#include "nrslam/util/text_table.h"

namespace nrslam {
namespace {

// Every leaf of `node` under its dotted path into `dotted`; an empty group is a leaf.
void AddDotted(const Json& node, const std::string& prefix, Json* dotted) {
  for (const auto& [key, value] : node.items()) {
    const std::string path = prefix.empty() ? key : prefix + "." + key;
    if (value.is_object() && !value.empty()) {
      AddDotted(value, path, dotted);
    } else if (dotted->contains(path)) {
      throw Error("option '" + path + "' is given twice, as a dotted name and as a group's field");
    } else {
      (*dotted)[path] = value;
    }
  }
}

// Levenshtein distance: the fewest single-character insertions, deletions and substitutions.
size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

void CollectChanged(const Json& base, const Json& changed, const std::string& prefix, std::vector<std::string>* out) {
  if (!base.is_object()) {
    if (changed != base) out->push_back(Assignment(prefix, changed));
    return;
  }
  for (auto it = base.begin(); it != base.end(); ++it) {
    CollectChanged(it.value(), changed.at(it.key()), prefix.empty() ? it.key() : prefix + "." + it.key(), out);
  }
}

// What an options file must give for a key whose default is `value`, as an error message says
// it; "" for a default of no particular kind (null).
std::string KindOf(const Json& value) {
  if (value.is_boolean()) return "true or false";
  if (value.is_number_integer()) return "a whole number";
  if (value.is_number()) return "a number";
  if (value.is_string()) return "a string";
  if (value.is_array()) return "a list";
  if (value.is_object()) return "a group of options";
  return "";
}

// A whole number is a number too; the reverse would truncate.
bool Fits(const Json& value, const Json& reference) {
  const std::string expected = KindOf(reference);
  return expected.empty() || KindOf(value) == expected || (expected == "a number" && value.is_number());
}

// One walk over `given` against the defaults: keys the defaults lack, and values of another kind.
void CollectMismatches(const Json& given, const Json& reference, const std::string& prefix,
                       std::vector<std::string>* unknown, std::vector<std::string>* mistyped) {
  if (!given.is_object() || !reference.is_object()) return;
  for (auto it = given.begin(); it != given.end(); ++it) {
    const std::string path = prefix.empty() ? it.key() : prefix + "." + it.key();
    if (!reference.contains(it.key())) {
      unknown->push_back(path);
      continue;
    }
    const Json& expected = reference.at(it.key());
    if (!Fits(it.value(), expected)) {
      mistyped->push_back(path + (expected.is_object() ? " is " : " must be ") + KindOf(expected) + ", got " +
                          it.value().dump());
    }
    CollectMismatches(it.value(), expected, path, unknown, mistyped);
  }
}

Json ParseLike(const Json& existing, const std::string& text, const std::string& path) {
  try {
    size_t used = 0;
    switch (existing.type()) {
      case Json::value_t::number_integer:
      case Json::value_t::number_unsigned: {
        const long long value = std::stoll(text, &used);
        if (used != text.size()) break;
        return value;
      }
      case Json::value_t::number_float: {
        const double value = std::stod(text, &used);
        // JSON has no inf or NaN: config.json would record null and the run could not be repeated.
        if (used != text.size() || !std::isfinite(value)) break;
        return value;
      }
      case Json::value_t::boolean:
        if (text == "true" || text == "1" || text == "on") return true;
        if (text == "false" || text == "0" || text == "off") return false;
        break;
      case Json::value_t::string:
        return text;
      case Json::value_t::array: {
        const std::string as_json = text.front() == '[' ? text : "[" + text + "]";
        Json value = Json::parse(as_json);
        if (!existing.empty() && value.size() != existing.size()) break;
        return value;
      }
      default:
        break;
    }
  } catch (const std::exception&) {
  }
  std::ostringstream message;
  message << "option " << path << ": cannot use '" << text << "' (expected "
          << (existing.is_number_float()     ? "a finite number"
              : existing.is_number_integer() ? "a whole number"
                                             : existing.type_name())
          << ", like " << existing.dump() << ")";
  throw Error(message.str());
}

}  // namespace

template <typename T>
T Field(const Json& object, const std::string& key, const std::string& context) {
  const auto found = object.find(key);
  if (found == object.end()) throw Error(context + ": missing field '" + key + "'");
  const Json& value = *found;
  const Json reference = T{};
  bool fits = Fits(value, reference);
  std::string kind = KindOf(reference);
  if constexpr (std::is_same_v<T, int>) {
    fits = fits && (value.is_number_unsigned() ? value.get<unsigned long long>() <= std::numeric_limits<int>::max()
                                               : value.get<long long>() >= std::numeric_limits<int>::min() &&
                                                     value.get<long long>() <= std::numeric_limits<int>::max());
  } else if constexpr (std::is_same_v<T, std::vector<double>>) {
    kind += " of numbers";
    fits = fits && std::all_of(value.begin(), value.end(), [](const Json& element) { return element.is_number(); });
  }
  if (!fits) throw Error(context + ": " + key + " must be " + kind + ", got " + value.dump());
  return value.get<T>();
}

template int Field<int>(const Json&, const std::string&, const std::string&);
template double Field<double>(const Json&, const std::string&, const std::string&);
template std::string Field<std::string>(const Json&, const std::string&, const std::string&);
template std::vector<double> Field<std::vector<double>>(const Json&, const std::string&, const std::string&);

std::string Assignment(const std::string& path, const Json& value) {
  return path + "=" + (value.is_string() ? value.get<std::string>() : value.dump());
}

std::vector<std::string> ChangedAssignments(const Json& base, const Json& changed) {
  std::vector<std::string> assignments;
  CollectChanged(base, changed, "", &assignments);
  return assignments;
}


Json DottedOptions(const Json& options) {
  Json dotted = Json::object();
  AddDotted(options, "", &dotted);
  return dotted;
}

std::vector<std::string> LeafPaths(const Json& config) {
  // '.' sorts before every character of a name, so the dotted names keep the groups' order.
  const Json dotted = DottedOptions(config);
  std::vector<std::string> paths;
  for (const auto& item : dotted.items()) paths.push_back(item.key());
  return paths;
}

Json NestedOptions(const Json& options) {
  Json nested = Json::object();
  // In name order, a value ("camera") comes before the fields of the group it would clash with.
  const Json dotted = DottedOptions(options);  // named: items() would not keep a temporary alive
  for (const auto& [path, value] : dotted.items()) {
    Json* node = &nested;
    size_t begin = 0;
    for (size_t dot = path.find('.'); dot != std::string::npos; begin = dot + 1, dot = path.find('.', begin)) {
      node = &(*node)[path.substr(begin, dot - begin)];
      if (!node->is_null() && !node->is_object()) {
        throw Error("option '" + path.substr(0, dot) + "' is given as a value and as a group");
      }
    }
    (*node)[path.substr(begin)] = value;
  }
  return nested;
}

std::string LastName(const std::string& path) { return path.substr(path.rfind('.') + 1); }  // npos + 1 == 0

std::vector<std::string> CloseOptionNames(const std::string& name, const std::vector<std::string>& paths) {
  const std::string wanted = LastName(name);
  // Short names allow fewer edits: two edits rewrite most of a short name.
  const size_t max_edits = wanted.size() < 3 ? 0 : wanted.size() < 8 ? 1 : 2;
  std::vector<std::string> close;
  for (const std::string& path : paths) {
    const std::string candidate = LastName(path);
    const bool contains = !wanted.empty() && candidate.find(wanted) != std::string::npos;
    if (contains || EditDistance(wanted, candidate) <= max_edits) close.push_back(path);
  }
  return close;
}

std::string UnknownOptionHint(const std::string& name, const std::vector<std::string>& paths,
                              const std::string& kind) {
  std::vector<std::string> close = CloseOptionNames(name, paths);
  if (close.empty()) return "known " + kind + ": " + Join(paths, ", ");
  const std::string last = close.back();
  close.pop_back();
  return "did you mean " + (close.empty() ? last : Join(close, ", ") + " or " + last) + "?";
}

void RejectUnknownKeys(const Json& object, const std::vector<std::string>& known, const std::string& context) {
  for (const auto& item : object.items()) {
    if (std::find(known.begin(), known.end(), item.key()) == known.end()) {
      throw Error(context + ": unknown key '" + item.key() + "'; " + UnknownOptionHint(item.key(), known, "keys"));
    }
  }
}

namespace {

std::vector<std::string> PathsWithLastName(const std::string& name, const std::vector<std::string>& paths) {
  std::vector<std::string> matches;
  for (const std::string& path : paths) {
    if (LastName(path) == name) matches.push_back(path);
  }
  return matches;
}

}  // namespace

std::optional<std::string> FindOptionName(const std::string& name, const std::vector<std::string>& paths) {
  if (std::find(paths.begin(), paths.end(), name) != paths.end()) return name;
  const std::vector<std::string> matches = PathsWithLastName(name, paths);
  if (matches.size() == 1) return matches.front();
  return std::nullopt;
}

std::string ResolveOptionName(const std::string& name, const std::vector<std::string>& paths, const std::string& kind) {
  if (const std::optional<std::string> path = FindOptionName(name, paths)) return *path;
  const std::vector<std::string> matches = PathsWithLastName(name, paths);
  if (matches.empty()) throw Error(kind + " '" + name + "' is unknown; " + UnknownOptionHint(name, paths));
  throw Error(kind + " '" + name + "' is ambiguous: " + Join(matches, ", "));
}

void RejectMismatchedOptions(const Json& given, const Json& reference, const std::string& context) {
  if (!given.is_object()) throw Error(context + ": expected a JSON object");
  std::vector<std::string> unknown, mistyped;
  CollectMismatches(given, reference, "", &unknown, &mistyped);
  if (!unknown.empty()) {
    const std::vector<std::string> known = LeafPaths(reference);
    std::vector<std::string> named;
    for (const std::string& path : unknown) named.push_back("unknown option '" + path + "' (" + UnknownOptionHint(path, known) + ")");
    throw Error(context + ": " + Join(named, "; "));
  }
  if (!mistyped.empty()) throw Error(context + ": " + Join(mistyped, "; "));
}

void ApplyAssignment(Json& config, const std::string& assignment) {
  const size_t equals = assignment.find('=');
  if (equals == std::string::npos || equals == 0) {
    throw Error("option assignment '" + assignment + "' must look like name=value");
  }
  const std::string path = assignment.substr(0, equals);
  const std::string text = assignment.substr(equals + 1);
  Json* node = &config;
  std::stringstream parts(path);
  std::string key;
  while (std::getline(parts, key, '.')) {
    if (!node->is_object() || !node->contains(key)) {
      throw Error("unknown option '" + path + "'; " + UnknownOptionHint(path, LeafPaths(config)));
    }
    node = &(*node)[key];
  }
  if (node->is_object()) {
    throw Error("option '" + path + "' is a group; set one of its fields: " +
                Join(LeafPaths(*node), ", "));
  }
  *node = ParseLike(*node, text, path);
}

Json ReadJsonFile(const std::filesystem::path& file) {
  std::ifstream stream = OpenToRead(file, "JSON file");
  try {
    return Json::parse(stream);
  } catch (const Json::exception& e) {
    throw Error(file.string() + " is not valid JSON (" + e.what() + ")");
  }
}

}  // namespace nrslam
