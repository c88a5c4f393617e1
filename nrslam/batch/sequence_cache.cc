#include "nrslam/batch/sequence_cache.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <iomanip>
#include <set>
#include <sstream>

#include "nrslam/util/error.h"
#include "nrslam/util/json_options.h"
#include "nrslam/util/process.h"
#include "nrslam/util/source_revision.h"
#include "nrslam/util/text_table.h"

namespace nrslam {
namespace {

constexpr size_t kHashDigits = 12;

// FNV-1a: a cache key that is the same on every machine and build.
std::string StableHash(const std::string& text) {
  uint64_t hash = 1469598103934665603ull;
  for (unsigned char c : text) {
    hash ^= c;
    hash *= 1099511628211ull;
  }
  std::ostringstream hex;
  hex << std::hex << std::setw(16) << std::setfill('0') << hash;
  return hex.str().substr(0, kHashDigits);
}

// Whether `name` is <stem>-<hash>, as CachedSequenceFolder names folders.
bool IsCacheName(const std::string& name) {
  if (name.size() < kHashDigits + 2 || name[name.size() - kHashDigits - 1] != '-') return false;
  return name.find_first_not_of("0123456789abcdef", name.size() - kHashDigits) == std::string::npos;
}

std::string HostName() {
  char host[256] = {};
  ::gethostname(host, sizeof(host) - 1);
  return host;
}

std::uintmax_t BytesUnder(const std::filesystem::path& path) {
  std::error_code unreadable;
  if (std::filesystem::is_regular_file(path, unreadable)) return std::filesystem::file_size(path, unreadable);
  std::uintmax_t bytes = 0;
  for (auto it = std::filesystem::recursive_directory_iterator(path, unreadable);
       it != std::filesystem::recursive_directory_iterator(); it.increment(unreadable)) {
    std::error_code ignored;
    if (it->is_regular_file(ignored)) bytes += it->file_size(ignored);
  }
  return bytes;
}

std::string RecordedCode(const std::filesystem::path& sequence_json) {
  try {
    return ReadJsonFile(sequence_json).at("provenance").value("code", "");
  } catch (const std::exception&) {
    return "";
  }
}

std::string Size(std::uintmax_t bytes) {
  return bytes < 1000000000 ? FormatFixed(bytes / 1e6, 1) + " MB" : FormatFixed(bytes / 1e9, 2) + " GB";
}

std::string LocalTime(std::time_t time) {
  std::tm local{};
  ::localtime_r(&time, &local);
  std::ostringstream text;
  text << std::put_time(&local, "%Y-%m-%d %H:%M");
  return text.str();
}

}  // namespace

std::filesystem::path CachedSequenceFolder(const std::filesystem::path& cache, const std::string& stem,
                                           const std::vector<std::string>& arguments) {
  std::string key = std::string("code ") + SequenceCodeFingerprint() + "\n";
  for (const std::string& argument : arguments) key += argument + "\n";
  return cache / (stem + "-" + StableHash(key));
}

std::filesystem::path CacheLog(const std::filesystem::path& folder) { return folder.string() + ".log"; }

std::filesystem::path PartialFolder(const std::filesystem::path& folder) {
  static std::atomic<int> count{0};
  return folder.string() + ".partial." + HostName() + "-" + std::to_string(::getpid()) + "-" +
         std::to_string(count++);
}

void RemoveAbandonedPartials(const std::filesystem::path& cache) {
  const std::string marker = ".partial." + HostName() + "-";
  std::error_code unreadable;
  for (const auto& entry : std::filesystem::directory_iterator(cache, unreadable)) {
    const std::string name = entry.path().filename().string();
    const size_t at = name.find(marker);
    if (at == std::string::npos) continue;
    const std::string pid = name.substr(at + marker.size(), name.find('-', at + marker.size()) - at - marker.size());
    if (pid.empty() || pid.size() > 9 || pid.find_first_not_of("0123456789") != std::string::npos) continue;
    if (!ProcessIsRunning(std::stoi(pid))) {
      std::error_code ignored;
      std::filesystem::remove_all(entry.path(), ignored);
    }
  }
}

bool CachedSequence::MadeByThisCode() const { return code == SequenceCodeFingerprint(); }

CacheContents ReadCacheContents(const std::filesystem::path& cache) {
  if (!std::filesystem::exists(cache)) {
    throw Error("the cache " + cache.string() + " does not exist: no evaluation has rendered or imported into it");
  }
  if (!std::filesystem::is_directory(cache)) throw Error("the cache " + cache.string() + " is not a folder");
  std::vector<std::filesystem::path> entries;
  for (const auto& entry : std::filesystem::directory_iterator(cache)) entries.push_back(entry.path());
  std::sort(entries.begin(), entries.end());
  CacheContents contents;
  std::set<std::filesystem::path> of_sequences;  // their folders and logs
  for (const std::filesystem::path& entry : entries) {
    const std::filesystem::path sequence_json = entry / "sequence.json";
    // stat, not std::filesystem: C++17 has no way from a file's time to the calendar's.
    struct stat status {};
    if (IsCacheName(entry.filename().string()) && std::filesystem::is_directory(entry) &&
        ::stat(sequence_json.c_str(), &status) == 0 && S_ISREG(status.st_mode)) {
      contents.sequences.push_back({entry, RecordedCode(sequence_json), BytesUnder(entry) + BytesUnder(CacheLog(entry)),
                                    status.st_mtime});
      of_sequences.insert({entry, CacheLog(entry)});
    }
  }
  for (const std::filesystem::path& entry : entries) {
    if (of_sequences.count(entry) == 0) contents.others.push_back(entry);
  }
  return contents;
}

std::string DescribeCache(const std::filesystem::path& cache, const CacheContents& contents) {
  TextTable table({"sequence", "made by", "written", "size"});
  std::uintmax_t current_bytes = 0, other_bytes = 0;
  int current = 0;
  for (const CachedSequence& sequence : contents.sequences) {
    const bool ours = sequence.MadeByThisCode();
    (ours ? current_bytes : other_bytes) += sequence.bytes;
    current += ours;
    table.AddRow({sequence.folder.filename().string(),
                  ours ? "this code" : sequence.code.empty() ? "not recorded" : sequence.code,
                  LocalTime(sequence.written), Size(sequence.bytes)});
  }
  const int other = static_cast<int>(contents.sequences.size()) - current;
  std::ostringstream text;
  text << cache.string() << ": " << contents.sequences.size() << " sequence(s), " << Size(current_bytes + other_bytes)
       << '\n';
  if (!contents.sequences.empty()) table.Print(text);
  text << current << " made by this build's code (" << SequenceCodeFingerprint() << "), " << Size(current_bytes)
       << "; " << other << " by other code, " << Size(other_bytes);
  if (other > 0) {
    text << ". This build never reads those again: `nrslam_eval cache --prune` removes them (a build of that code "
            "would render or import them anew)";
  }
  text << '\n';
  if (!contents.others.empty()) {
    std::vector<std::string> names;
    for (const std::filesystem::path& path : contents.others) names.push_back(path.filename().string());
    text << "Not an evaluation's sequences, which --prune leaves (but for partial renders an interrupted evaluation on "
            "this machine left): "
         << Join(names, ", ") << '\n';
  }
  return text.str();
}

CachePruning RemoveSequencesOfOtherCode(const std::filesystem::path& cache, const CacheContents& contents) {
  CachePruning pruning;
  for (const CachedSequence& sequence : contents.sequences) {
    if (sequence.MadeByThisCode()) continue;
    std::error_code failed;
    std::filesystem::remove_all(sequence.folder, failed);
    if (!failed) std::filesystem::remove(CacheLog(sequence.folder), failed);
    if (failed) {
      pruning.failures.push_back(sequence.folder.string() + ": " + failed.message());
    } else {
      ++pruning.removed;
      pruning.bytes_freed += sequence.bytes;
    }
  }
  RemoveAbandonedPartials(cache);
  return pruning;
}

std::string DescribePruning(const CachePruning& pruning) {
  std::string text = "removed " + std::to_string(pruning.removed) + " sequence(s), " + Size(pruning.bytes_freed) + '\n';
  for (const std::string& failure : pruning.failures) text += "could not remove " + failure + '\n';
  return text;
}

}  // namespace nrslam
