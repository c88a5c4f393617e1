// nrslam_eval: runs NR-SLAM over every sequence of a manifest (each in its own process),
// with optional parameter sweeps, prints the results table (and each deformable run beside
// its rigid baseline, when the manifest has both, and each preset over its scene seeds),
// writes results.json/.csv, and checks or writes a regression baseline. `nrslam_eval merge
// DIR... --out DIR` aggregates result folders (e.g. of jobs emitted with --emit-jobs and run
// elsewhere); `nrslam_eval compare RUN_A RUN_B` scores two runs of one sequence on the points
// both report; `nrslam_eval diff EVAL_A EVAL_B` sets two evaluations of the same runs side by
// side, run for run; `nrslam_eval score SEQUENCE ESTIMATES --out DIR` scores another system's
// output as a run; `nrslam_eval cache [--prune]` lists the sequences in the cache and the code
// that made each, and removes those of other code.
#include <CLI/CLI.hpp>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <csignal>
#include <iostream>
#include <optional>
#include <thread>

#include "documentation_footer.h"
#include "nrslam/batch/baseline.h"
#include "nrslam/batch/evaluation_plan.h"
#include "nrslam/batch/manifest.h"
#include "nrslam/batch/plan_execution.h"
#include "nrslam/batch/report.h"
#include "nrslam/batch/results.h"
#include "nrslam/batch/results_diff.h"
#include "nrslam/batch/rigid_comparison.h"
#include "nrslam/batch/run_folder.h"
#include "nrslam/batch/seed_groups.h"
#include "nrslam/batch/sequence_cache.h"
#include "nrslam/system/external_result.h"
#include "nrslam/system/system_options.h"
#include "nrslam/util/error.h"
#include "nrslam/util/folder.h"
#include "nrslam/util/folder_lock.h"
#include "nrslam/util/process.h"
#include "nrslam/util/source_revision.h"
#include "nrslam/util/text_file.h"
#include "nrslam/util/text_table.h"

namespace {

// CLI11's NonNegativeNumber names its upper bound, the largest double, in full (300 digits).
const CLI::Validator kNonNegative(
    [](std::string& text) -> std::string {
      char* end = nullptr;
      const double value = std::strtod(text.c_str(), &end);
      if (!text.empty() && *end == '\0' && std::isfinite(value) && value >= 0) return "";
      return "must be a number >= 0, got " + text;
    },
    "NONNEGATIVE");

// The sibling programs, from this executable's own folder.
nrslam::Programs SiblingPrograms() {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  const std::filesystem::path folder = error ? std::filesystem::path(".") : self.parent_path();
  return {folder / "nrslam_simulate", folder / "nrslam_run", folder / "nrslam_import", folder / "nrslam_eval"};
}

// Exit codes: 0 all well, 1 bad usage or input, 2 some run failed, 3 baseline check failed.
// `baseline`: the --check-baseline file as read before the runs.
int Finish(const nrslam::EvaluationPlan& plan, const std::filesystem::path& out,
           const std::optional<nrslam::Json>& baseline, const std::string& write_baseline,
           const nrslam::BaselineTolerance& tolerance) {
  const std::vector<nrslam::RunResult> results = nrslam::CollectResults(plan);
  const std::vector<nrslam::RigidComparison> comparisons = nrslam::CompareWithRigid(plan, results);
  nrslam::WriteResults(results, out);
  nrslam::WriteRigidComparison(comparisons, out / "rigid_comparison.csv");
  const std::vector<nrslam::SeedGroup> seed_groups = nrslam::GroupBySeed(plan, results);
  if (!seed_groups.empty()) nrslam::WriteSeedGroups(seed_groups, out / "seed_groups.csv");
  nrslam::WriteReport(results, comparisons, seed_groups, out / "report");
  std::cout << '\n';
  nrslam::PrintResults(results, std::cout);
  nrslam::PrintRigidComparison(comparisons, std::cout);
  nrslam::PrintSeedGroups(seed_groups, std::cout);
  std::cout << "\nresults: " << (out / "results.json").string() << ", " << (out / "results.csv").string()
            << (comparisons.empty() ? "" : ", " + (out / "rigid_comparison.csv").string())
            << (seed_groups.empty() ? "" : ", " + (out / "seed_groups.csv").string())
            << "\nreport:  " << (out / "report" / "index.html").string()
            << "\ncode:    " << nrslam::DescribeRevisions(results) << '\n';
  int code = 0;
  for (const auto& result : results) code = result.status == "failed" ? 2 : code;
  if (!write_baseline.empty()) {
    nrslam::WriteTextFile(write_baseline, nrslam::MakeBaseline(results, tolerance).dump(2) + '\n');
    std::cout << "baseline written: " << write_baseline << '\n';
  }
  if (baseline) {
    const nrslam::BaselineCheck check = nrslam::CheckBaseline(results, *baseline);
    std::cout << '\n' << check.report;
    if (!check.passed) code = 3;
  }
  return code;
}

// The manifest's sequences (those --only names, if given), each once per --seeds seed.
nrslam::Manifest LoadChosen(const std::filesystem::path& file, const std::vector<std::string>& only,
                            const std::string& seeds) {
  nrslam::Manifest manifest = nrslam::LoadManifest(file);
  if (!only.empty()) manifest = nrslam::WithOnlySequences(manifest, only);
  return seeds.empty() ? manifest : nrslam::WithSceneSeeds(manifest, nrslam::ParseSeedList(seeds));
}

int Compare(const std::filesystem::path& a, const std::filesystem::path& b) {
  const nrslam::CommonPointsComparison comparison = nrslam::CompareRunFolders(a, b);
  if (comparison.frames == 0) throw nrslam::Error("no frame that both runs report could be evaluated");
  std::cout << comparison.frames << " frame(s) both runs report; " << nrslam::FormatFixed(comparison.mean_common_points, 0)
            << " points per frame in common\n";
  if (comparison.mismatched_ids > 0) {
    std::cout << comparison.mismatched_ids << " id(s) both runs report name different points (first reported in "
              << "another frame or place) and are left out\n";
  }
  std::cout << '\n';
  nrslam::TextTable table({"run", "points/frame", "own RMSE mm", "common RMSE mm"});
  table.AddRow({a.string(), nrslam::FormatFixed(comparison.mean_points_a, 0), nrslam::FormatFixed(comparison.a_own.rmse_mm, 3),
                nrslam::FormatFixed(comparison.a_common.rmse_mm, 3)});
  table.AddRow({b.string(), nrslam::FormatFixed(comparison.mean_points_b, 0), nrslam::FormatFixed(comparison.b_own.rmse_mm, 3),
                nrslam::FormatFixed(comparison.b_common.rmse_mm, 3)});
  table.Print(std::cout);
  return 0;
}

// Set on SIGINT and SIGTERM: the batch stops its runs and ends, and what finished is kept.
std::atomic<bool> stop_requested{false};

void RequestStop(int) { stop_requested = true; }

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Evaluate NR-SLAM over a manifest of sequences"};
  app.set_version_flag("--version", nrslam::VersionString());
  app.footer(DocumentationFooter("docs/eval.md (manifests, sweeps, scene seeds, baselines, comparisons, other "
                                 "systems' output, datasets)"));
  app.require_subcommand(0, 1);
  std::string manifest_path, out = "runs/eval", cache = "runs/cache", emit_jobs, check_baseline, write_baseline,
      config_path;
  std::vector<std::string> assignments, sweeps, only;
  std::string seeds;
  int jobs = std::max(1u, std::thread::hardware_concurrency());
  nrslam::BaselineTolerance tolerance;  // of a written baseline; the other fields keep their defaults
  double run_timeout = 0;
  bool dry_run = false;
  app.add_option("manifest", manifest_path, "manifest JSON (see data_manifests/)");
  app.add_option("--out", out, "result folder: runs/<sequence>[/<sweep point>], results.json, results.csv")
      ->capture_default_str();
  app.add_option("--cache", cache, "where presets are rendered and datasets imported, shared between evaluations")
      ->capture_default_str();
  app.add_option("--jobs,-j", jobs, "processes at once")->capture_default_str()->check(CLI::Range(1, 256));
  app.add_option("--timeout", run_timeout, "seconds (wall clock) a run may take before it is killed and recorded as "
                                           "failed, so a run that hangs cannot stall the batch; 0: no limit")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e7));
  app.add_option("--config", config_path, "JSON options for every sequence (a run's config.json or an options "
                                          "object): those that differ from the defaults, before --set");
  app.add_option("--set", assignments, "set a run option for every sequence, e.g. --set k=2 or deformation.k=2");
  app.add_option("--sweep", sweeps,
                 "run a grid: --sweep k=0.5,1.1,2 --sweep max_degree_D=3,5,10; a simulator option renders the presets "
                 "anew per value: --sweep simulate.amplitude_mm=0,5,10");
  app.add_option("--only", only,
                 "evaluate only these sequences of the manifest: names or shell wildcards, e.g. --only sim-3 "
                 "'lap-*' (before --seeds adds -seedN)");
  app.add_option("--seeds", seeds,
                 "render every preset of the manifest once per scene seed, e.g. --seeds 1-3 (names get -seedN; "
                 "the seed table summarises each preset over them)");
  app.add_flag("--dry-run", dry_run,
               "list the sequences it would render and the runs it would run (and which are done already), run nothing");
  app.add_option("--emit-jobs", emit_jobs, "write one shell command per run to FILE (for GNU parallel, Slurm) "
                                            "instead of running them");
  app.add_option("--check-baseline", check_baseline,
                 "fail (exit 3) when a run, or all runs together, are worse than this baseline file allows");
  app.add_option("--write-baseline", write_baseline, "write the results as a baseline file");
  app.add_option("--tolerance", tolerance.rmse_relative, "relative RMSE growth per run a written baseline allows")
      ->capture_default_str()
      ->check(kNonNegative);
  app.add_option("--pooled-tolerance", tolerance.pooled_rmse_relative,
                 "relative growth of the geometric mean RMSE ratio over all runs a written baseline allows; 0: no "
                 "such check (for chaotic runs: a loose --tolerance per run and a tight one over many runs)")
      ->capture_default_str()
      ->check(kNonNegative);
  CLI::App* merge = app.add_subcommand("merge", "aggregate result folders (their run folders) into --out");
  merge->fallthrough();  // --out, --set, --sweep, --check-baseline given after "merge" too
  std::vector<std::string> merge_folders;
  std::string merge_manifest;
  merge->add_option("manifest", merge_manifest, "the manifest the jobs were emitted from")->required();
  merge->add_option("folders", merge_folders, "result folders to merge (default: --out)");
  CLI::App* compare = app.add_subcommand("compare", "score two run folders of one sequence (e.g. deformable and "
                                                    "rigid from the same depth map) on the points both report");
  std::vector<std::string> compared;
  compare->add_option("runs", compared, "two run folders")->required()->expected(2);
  CLI::App* diff = app.add_subcommand("diff", "two evaluations of the same runs (e.g. before and after a change of "
                                              "code) side by side, run for run");
  std::vector<std::string> diffed;
  diff->add_option("evaluations", diffed, "two result folders (each with results.json)")->required()->expected(2);
  CLI::App* score = app.add_subcommand("score", "score another system's output on a sequence as a run of ours is "
                                                "scored, into a run folder (--out)");
  score->fallthrough();  // --out given after "score"
  std::string scored_sequence;
  nrslam::ExternalResult external;
  score->add_option("sequence", scored_sequence, "the sequence folder (with depth/ for the RMSE)")->required();
  score->add_option("estimates", external.estimates, "a CSV file (frame,u,v,z[,point_id]) or a folder of depth images")
      ->required();
  score->add_option("--trajectory", external.trajectory, "its camera trajectory (TUM, world_from_camera, t = frame / fps)");
  score->add_option("--stride", external.depth_stride_px, "depth images: one point every this many pixels")
      ->capture_default_str();
  score->add_option("--name", external.name, "what produced it, recorded in config.json (e.g. DefSLAM)");
  CLI::App* cache_command = app.add_subcommand(
      "cache", "list the sequences in the cache (--cache) with the code that made each, when, and their size");
  cache_command->fallthrough();  // --cache given after "cache"
  bool prune = false;
  cache_command->add_flag("--prune", prune,
                          "remove the sequences made by other code than this build's, which it never reads again, "
                          "and their logs");
  CLI11_PARSE(app, argc, argv);

  try {
    if (compare->parsed()) return Compare(compared[0], compared[1]);
    if (cache_command->parsed()) {
      const nrslam::CacheContents contents = nrslam::ReadCacheContents(cache);
      std::cout << nrslam::DescribeCache(cache, contents);
      if (!prune) return 0;
      const nrslam::CachePruning pruning = nrslam::RemoveSequencesOfOtherCode(cache, contents);
      std::cout << nrslam::DescribePruning(pruning);
      return pruning.failures.empty() ? 0 : 1;
    }
    if (score->parsed()) {
      if (app.count("--out") == 0) throw nrslam::Error("score writes a run folder: give it with --out");
      const nrslam::RunSummary summary =
          nrslam::ScoreExternalResult(scored_sequence, external, nrslam::EvaluationOptions{}, out);
      std::cout << nrslam::DescribeSummary(summary) << "\nrun folder: " << out << '\n';
      return 0;
    }
    if (diff->parsed()) {
      const nrslam::ResultsDiff result = nrslam::DiffResults(nrslam::ReadResults(diffed[0]), nrslam::ReadResults(diffed[1]));
      nrslam::PrintDiff(result, diffed[0], diffed[1], std::cout);
      return 0;
    }
    const nrslam::Programs programs = SiblingPrograms();
    std::vector<nrslam::Sweep> grid;
    for (const std::string& sweep : sweeps) grid.push_back(nrslam::ParseSweep(sweep));
    std::vector<std::string> resolved;
    if (!config_path.empty()) resolved = nrslam::AssignmentsOverDefaults(nrslam::SystemOptionsFromFile(config_path));
    std::vector<std::string> set;
    for (const std::string& assignment : assignments) set.push_back(nrslam::ResolveRunAssignment(assignment));
    nrslam::RejectSetAndSwept(set, grid);
    resolved.insert(resolved.end(), set.begin(), set.end());
    // Before any run: a baseline that cannot be read, or written, would otherwise fail only
    // after the whole evaluation.
    std::optional<nrslam::Json> baseline;
    if (!check_baseline.empty()) baseline = nrslam::ReadBaseline(check_baseline);
    if (!write_baseline.empty()) {
      const std::filesystem::path folder = std::filesystem::absolute(write_baseline).parent_path();
      if (!std::filesystem::is_directory(folder)) {
        throw nrslam::Error("--write-baseline: the folder " + folder.string() + " does not exist");
      }
    }
    if (merge->parsed()) {
      // Runs of the same plan executed elsewhere: gather their run folders under --out.
      const nrslam::Manifest manifest = LoadChosen(merge_manifest, only, seeds);
      nrslam::EvaluationPlan plan = nrslam::PlanEvaluation(manifest, resolved, grid, out, cache);
      const nrslam::FolderLock lock(out, "nrslam_eval merge " + merge_manifest);
      for (nrslam::RunJob& run : plan.runs) {
        for (const std::string& folder : merge_folders) {
          const std::filesystem::path candidate =
              std::filesystem::absolute(folder) / std::filesystem::relative(run.run_folder, std::filesystem::absolute(out));
          if (std::filesystem::exists(candidate / "summary.json")) run.run_folder = candidate;
        }
      }
      return Finish(plan, out, baseline, write_baseline, tolerance);
    }
    if (manifest_path.empty()) throw nrslam::Error("a manifest is required (see data_manifests/)");
    const nrslam::Manifest manifest = LoadChosen(manifest_path, only, seeds);
    const nrslam::EvaluationPlan plan = nrslam::PlanEvaluation(manifest, resolved, grid, out, cache);
    if (dry_run) {
      std::cout << nrslam::DescribePlan(plan);
      return 0;
    }
    nrslam::CreateFolder(out);
    if (!emit_jobs.empty()) {
      std::string jobs_text;
      for (const nrslam::RunJob& run : plan.runs) jobs_text += nrslam::RunShellLine(plan, run, programs) + '\n';
      nrslam::WriteTextFile(emit_jobs, jobs_text);
      // merge must plan the same runs, so it is given every option that shapes the plan, quoted
      // as the shell needs (a wildcard of --only, a value with spaces).
      std::vector<std::string> merge_command = {"nrslam_eval", "merge", manifest_path, "--out", out};
      const auto add = [&](const std::string& flag, const std::vector<std::string>& values) {
        for (const std::string& value : values) merge_command.insert(merge_command.end(), {flag, value});
      };
      if (!config_path.empty()) add("--config", {config_path});
      add("--set", assignments);
      add("--sweep", sweeps);
      add("--only", only);
      if (!seeds.empty()) add("--seeds", {seeds});
      std::cout << plan.runs.size() << " job(s) written to " << emit_jobs << "; run them anywhere, then: "
                << nrslam::ShellLine(merge_command) << '\n';
      return 0;
    }
    const nrslam::FolderLock lock(out, "nrslam_eval " + manifest_path);
    std::cerr << manifest.sequences.size() << " sequence(s), " << plan.runs.size() << " run(s), " << jobs
              << " at a time; output in " << out << '\n';
    // The runs' KLT is OpenMP-parallel, and libgomp's idle workers spin after every parallel
    // region: with several runs at once, one run's spinning thread holds the core another run
    // needs (two sim runs side by side: 10.3 / 10.0 fps spinning, 13.7 / 14.8 passive). The
    // children inherit this; a value the user set is kept.
    if (jobs > 1) setenv("OMP_WAIT_POLICY", "passive", /*overwrite=*/0);
    struct sigaction on_stop {};
    on_stop.sa_handler = RequestStop;
    sigaction(SIGINT, &on_stop, nullptr);
    sigaction(SIGTERM, &on_stop, nullptr);
    nrslam::ExecutePlan(
        plan, programs, jobs, [](const std::string& line) { std::cerr << line << '\n'; }, run_timeout,
        &stop_requested);
    if (stop_requested) {
      std::cerr << "nrslam_eval: interrupted; the runs that finished are kept, and the same command resumes\n";
      return 130;
    }
    return Finish(plan, out, baseline, write_baseline, tolerance);
  } catch (const std::exception& e) {
    std::cerr << "nrslam_eval: " << e.what() << '\n';
    return 1;
  }
}
