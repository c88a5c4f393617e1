// batch: the cache of prepared sequences that evaluations share (`nrslam_eval --cache`): the
// folder a render or import goes to, named after what makes it; the private folder it is made
// in before it is moved into place; and what the cache holds, for `nrslam_eval cache`, with
// the removal of sequences made by other code.
#pragma once

#include <cstdint>
#include <ctime>
#include <filesystem>
#include <string>
#include <vector>

namespace nrslam {

// cache/<stem>-<12 hex digits>, the digits a hash of SequenceCodeFingerprint() and the
// arguments of the program that makes the sequence: a render or import by other code (an
// importer since mended, a simulator since changed) is made again, not silently reused.
std::filesystem::path CachedSequenceFolder(const std::filesystem::path& cache, const std::string& stem,
                                           const std::vector<std::string>& arguments);

// Where a sequence is made before it is moved into place: <folder>.partial.<host>-<pid>-<n>.
// Evaluations that share a cache may prepare the same sequence at once; each writes only into
// a folder of its own.
std::filesystem::path PartialFolder(const std::filesystem::path& folder);

// The log beside a folder of the cache, finished or partial: <folder>.log. It goes with its
// sequence (ReadCacheContents, RemoveSequencesOfOtherCode).
std::filesystem::path CacheLog(const std::filesystem::path& folder);

// Removes the partial folders (and their logs) in `cache` that interrupted evaluations on this
// machine left behind: those whose process is gone. A cache shared between machines keeps the
// others'.
void RemoveAbandonedPartials(const std::filesystem::path& cache);

// One sequence in the cache: a folder named as CachedSequenceFolder names them, with a
// sequence.json.
struct CachedSequence {
  std::filesystem::path folder;
  // The SequenceCodeFingerprint() of the program that made it, as its sequence.json records it
  // (provenance.code); empty when it records none (made before sequences recorded it) or its
  // sequence.json cannot be read.
  std::string code;
  std::uintmax_t bytes = 0;  // its files' and its log's
  std::time_t written = 0;   // when its sequence.json was written
  bool MadeByThisCode() const;
};

struct CacheContents {
  std::vector<CachedSequence> sequences;  // in name order
  // Everything else, which is never removed: the partial folders of evaluations running now or
  // on other machines, logs of renders that failed, and whatever else is there (a --cache
  // pointed at a folder of one's own).
  std::vector<std::filesystem::path> others;
};

// Throws Error when `cache` does not exist or is not a folder.
CacheContents ReadCacheContents(const std::filesystem::path& cache);

// One line per sequence (its name, the code that made it, when, its size), then the totals of
// this code's and of other code's, and what `nrslam_eval cache --prune` would remove.
std::string DescribeCache(const std::filesystem::path& cache, const CacheContents& contents);

struct CachePruning {
  int removed = 0;
  std::uintmax_t bytes_freed = 0;
  std::vector<std::string> failures;  // "<folder>: <why>", for those that could not be removed
};

// Removes the sequences made by other code than this build's (or recording none), each with its
// log, and this machine's abandoned partial folders. An evaluation by this build would never
// read them again; one by a build of that other code would make them again.
CachePruning RemoveSequencesOfOtherCode(const std::filesystem::path& cache, const CacheContents& contents);
// "removed 3 sequence(s), 61.2 MB", then a line per failure.
std::string DescribePruning(const CachePruning& pruning);

}  // namespace nrslam
