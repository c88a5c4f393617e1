// batch: what an evaluation runs — the renders of the manifest's presets into the cache and
// one nrslam_run per (sequence, sweep point). Running it: plan_execution.h.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "nrslam/batch/manifest.h"

namespace nrslam {

// One swept option: every value is run, in a grid with the other sweeps. A run option
// ("deformation.k") changes how each sequence is run; a simulator option ("simulate." and its
// nrslam_simulate path, e.g. "simulate.deformation.amplitude_mm") changes the data: each value
// renders the manifest's presets anew, as a study of how the system copes with, say, a larger
// deformation needs.
struct Sweep {
  std::string path;                 // resolved: a run option path, or "simulate." + a simulator path
  std::vector<std::string> values;  // as given on the command line
};
// Parses "name=v1,v2,v3" (name as for ResolveRunOption, or "simulate." and a simulator option
// by its path or unique last name); throws Error when malformed or unknown.
Sweep ParseSweep(const std::string& text);
// Throws Error when an option of the command line's --set list (resolved "path=value") is also
// swept: the sweep would set it in every run, so one of the two is a mistake. (A --config file's
// value under a sweep is not: the file is the base the sweep varies.)
void RejectSetAndSwept(const std::vector<std::string>& set_assignments, const std::vector<Sweep>& sweeps);
// Whether a sweep point's "path=value" sets a simulator option ("simulate.…").
bool IsSimulatorAssignment(const std::string& assignment);
// Such an assignment as nrslam_simulate --set takes it: "simulate.deformation.amplitude_mm=5"
// gives "deformation.amplitude_mm=5".
std::string SimulatorAssignment(const std::string& assignment);

// A simulator assignment that sets the scene seed: "seed=3".
bool IsSeedAssignment(const std::string& assignment);
// Scene seeds as --seeds gives them: "1-3,7" is 1, 2, 3, 7, in that order. Throws Error when
// malformed or when a seed comes twice.
std::vector<uint64_t> ParseSeedList(const std::string& text);
// The manifest with each rendered preset once per seed, named "<name>-seed<s>", its simulator
// seed set to s whatever the manifest gave: single renderings are chaotic, and the seed groups
// of the results summarise such copies. Sequences on disk and external results (scored
// against one rendering) stay as they are. Throws Error when a new name is already taken.
Manifest WithSceneSeeds(const Manifest& manifest, const std::vector<uint64_t>& seeds);

// A sequence made before its runs, into the cache: a preset rendered (nrslam_simulate) or a
// dataset imported (nrslam_import). Its folder name is keyed by what makes it.
struct PrepareJob {
  std::string description;              // "sim-3" or "hamlyn /data/h01", for messages
  bool import = false;                  // nrslam_import rather than nrslam_simulate
  std::vector<std::string> arguments;   // the program's arguments, without --out
  std::filesystem::path folder;         // cache/<name>-<hash of the arguments and SequenceCodeFingerprint()>
};

struct RunJob {
  std::string sequence;                      // manifest name
  std::vector<std::string> point;            // the sweep point: "path=value" per sweep
  std::string label;                         // "k=0.5,max_degree_D=3", or "" without sweeps
  std::filesystem::path sequence_folder;
  std::filesystem::path run_folder;          // out/runs/<sequence>[/<label>]
  std::vector<std::string> arguments;        // the program's arguments (no program name)
  Json options;                              // the options those arguments resolve to (null: external)
  // An external result scored by `nrslam_eval score` instead of an nrslam_run: what its
  // config.json records (ToJson of system/external_result.h); null for a run of ours.
  Json external;
  int prepare = -1;                          // index into EvaluationPlan::prepares, or -1
  bool is_external() const { return !external.is_null(); }
};

struct EvaluationPlan {
  std::vector<PrepareJob> prepares;
  std::vector<RunJob> runs;
};

// How messages and tables name a run: "sequence", or "sequence [sweep point]".
std::string RunName(const std::string& sequence, const std::string& label);

// Expands the manifest × the sweep grid (an external result is scored once, at no sweep point); `extra` assignments apply to every run (after the
// manifest's). Validates every run's options.
EvaluationPlan PlanEvaluation(const Manifest& manifest, const std::vector<std::string>& extra,
                              const std::vector<Sweep>& sweeps, const std::filesystem::path& out,
                              const std::filesystem::path& cache);

}  // namespace nrslam
