// Batch evaluation: manifests and their validation, a batch that survives a broken sequence,
// resumed sweeps, the baseline check, and jobs emitted for GNU parallel then merged.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

#include "nrslam/batch/baseline.h"
#include "nrslam/batch/evaluation_plan.h"
#include "nrslam/batch/manifest.h"
#include "nrslam/batch/paired_comparison.h"
#include "nrslam/batch/plan_execution.h"
#include "nrslam/batch/report.h"
#include "nrslam/batch/results.h"
#include "nrslam/batch/results_diff.h"
#include "nrslam/batch/rigid_comparison.h"
#include "nrslam/batch/run_folder.h"
#include "nrslam/batch/seed_groups.h"
#include "nrslam/batch/sequence_cache.h"
#include "nrslam/batch/svg_plot.h"
#include "nrslam/sim/renderer.h"
#include "nrslam/system/system_options.h"
#include "nrslam/util/error.h"
#include "nrslam/util/folder_lock.h"
#include "nrslam/util/process.h"
#include "nrslam/util/source_revision.h"
#include "nrslam/util/text_file.h"
#include "nrslam/util/text_table.h"
#include "error_message.h"
#include "shell_command.h"
#include "temp_folder.h"

namespace nrslam {
namespace {

const Programs kPrograms{NRSLAM_TOOLS_DIR "/nrslam_simulate", NRSLAM_TOOLS_DIR "/nrslam_run",
                         NRSLAM_TOOLS_DIR "/nrslam_import", NRSLAM_TOOLS_DIR "/nrslam_eval"};

// `action` must throw an Error whose message contains `message`.
void ExpectRefused(const std::function<void()>& action, const std::string& message) {
  try {
    action();
    ADD_FAILURE() << "accepted; expected: " << message;
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find(message), std::string::npos) << error.what();
  }
}

std::filesystem::path WriteFile(const std::filesystem::path& file, const std::string& text) {
  std::filesystem::create_directories(file.parent_path());
  std::ofstream(file) << text;
  return file;
}

std::string ErrorOf(const std::filesystem::path& manifest) {
  return ErrorMessage([&] { LoadManifest(manifest); });
}

// A tiny simulated sequence: enough frames and points to track, quick to render and run.
constexpr const char* kTinySimulate = R"({"frames": 8, "camera.width": 320, "camera.height": 240})";

// A sweep's plot has one series per sequence: the legend wraps into rows inside the plot's
// width, names each named series once, and leaves out the unnamed ones (a run's later maps).
TEST(SvgPlot, LegendWrapsInsideThePlotAndNamesEachNamedSeriesOnce) {
  std::vector<PlotSeries> series;
  for (int i = 0; i < 8; ++i) series.push_back({"sequence-" + std::to_string(i), "#123456", {0, 1}, {static_cast<double>(i), i + 1.0}});
  series.push_back({"", "#654321", {0, 1}, {2, 3}});
  PlotOptions options{"RMSE against k", "k", "RMSE (mm)", 520, 300, false};
  const std::string svg = LinePlotSvg(series, options);
  const std::regex legend_text("<text x=\"([0-9.e+-]+)\" y=\"([0-9.e+-]+)\">([^<]*)</text>");
  std::set<double> rows;
  int entries = 0;
  for (auto match = std::sregex_iterator(svg.begin(), svg.end(), legend_text); match != std::sregex_iterator();
       ++match) {
    const std::string name = (*match)[3];
    if (name.rfind("sequence-", 0) != 0) continue;
    ++entries;
    const double x = std::stod((*match)[1]);
    EXPECT_GE(x, 0);
    EXPECT_LE(x + 7.0 * static_cast<double>(name.size()), options.width) << name;
    rows.insert(std::stod((*match)[2]));
    EXPECT_EQ(svg.find(">" + name + "</text>", match->position() + match->length()), std::string::npos) << name << " twice";
  }
  EXPECT_EQ(entries, 8);
  EXPECT_GT(rows.size(), 1u);                          // 8 names do not fit one row of 520 px
  EXPECT_EQ(svg.find("\"></text>"), std::string::npos);  // no entry for the unnamed series
  size_t polylines = 0;
  for (size_t at = svg.find("<polyline"); at != std::string::npos; at = svg.find("<polyline", at + 1)) ++polylines;
  EXPECT_EQ(polylines, series.size());  // every series is drawn, named or not
}

TEST(Manifest, EachMistakeIsNamed) {
  const auto folder = UniqueTempFolder("manifest_errors");
  auto manifest = [&](const std::string& sequences) {
    return WriteFile(folder / "m.json", R"({"sequences": [)" + sequences + "]}");
  };
  EXPECT_NE(ErrorOf(folder / "absent.json").find("cannot open"), std::string::npos);
  EXPECT_NE(ErrorOf(WriteFile(folder / "bad.json", "{ not json")).find("not valid JSON"), std::string::npos);
  EXPECT_NE(ErrorOf(manifest(R"({"name": "a", "preset": "sim-0", "colour": 1})")).find("unknown key 'colour'"),
            std::string::npos);
  EXPECT_NE(ErrorOf(manifest(R"({"name": "a", "preset": "sim-0", "path": "x"})")).find("exactly one of"),
            std::string::npos);
  EXPECT_NE(ErrorOf(manifest(R"({"name": "a", "preset": "sim-9"})")).find("sim-9"), std::string::npos);
  EXPECT_NE(ErrorOf(manifest(R"({"name": "a", "preset": "sim-0", "set": {"stiffness": 2}})")).find("'stiffness' is unknown"),
            std::string::npos);
  EXPECT_NE(ErrorOf(manifest(R"({"name": "a", "preset": "sim-0", "simulate": {"frames": "many"}})")).find("simulate"),
            std::string::npos);
  EXPECT_NE(ErrorOf(manifest(R"({"name": "a", "preset": "sim-0"}, {"name": "a", "preset": "sim-1"})")).find("used twice"),
            std::string::npos);
  EXPECT_NE(ErrorOf(manifest(R"({"name": "a", "preset": "sim-0", "set": {"k": -1}})")).find("sequence 1 ('a')"),
            std::string::npos);
  EXPECT_NE(ErrorOf(manifest(R"({"name": "a", "import": {"format": "stereo", "path": "x", "scale": true}})"))
                .find("\"scale\" takes a value, not true or false"),
            std::string::npos);
  EXPECT_NE(ErrorOf(manifest(R"({"name": "a", "import": {"format": "stereo", "path": "x", "stereo_depth": "yes"}})"))
                .find("\"stereo_depth\" must be true or false"),
            std::string::npos);
  std::filesystem::remove_all(folder);
}

// An unknown key gets what it most likely meant. A run option named as nrslam_run or --set names
// it is shown under "set", where a manifest gives it; a mistake in "defaults" is reported there,
// not against the first sequence that inherits it.
TEST(Manifest, AnUnknownKeyGetsWhatItMostLikelyMeant) {
  const auto folder = UniqueTempFolder("manifest_hints");
  auto manifest = [&](const std::string& defaults, const std::string& sequence) {
    return WriteFile(folder / "m.json", R"({"defaults": )" + defaults + R"(, "sequences": [)" + sequence + "]}");
  };
  const std::string preset = R"({"name": "a", "preset": "sim-0")";
  EXPECT_NE(ErrorOf(manifest("{}", preset + R"(, "mapping": false})"))
                .find(R"(sequence 1 ('a'): unknown key 'mapping': run options go under "set", as in "set": {"run.mapping": false})"),
            std::string::npos);
  EXPECT_NE(ErrorOf(manifest("{}", preset + R"(, "max_degree_D": 4})")).find(R"("set": {"deformation.max_degree_D": 4})"),
            std::string::npos);
  EXPECT_NE(ErrorOf(manifest("{}", preset + R"(, "rigd": true})")).find("unknown key 'rigd'; did you mean rigid?"),
            std::string::npos);
  const std::string colour = ErrorOf(manifest("{}", preset + R"(, "colour": 1})"));
  EXPECT_NE(colour.find("unknown key 'colour'; known keys: camera, external, "), std::string::npos) << colour;
  EXPECT_NE(colour.find(R"(; run options go under "set")"), std::string::npos) << colour;
  const std::string in_defaults = ErrorOf(manifest(R"({"init": "depth", "no_mapping": true})", preset + "}"));
  EXPECT_NE(in_defaults.find("m.json, defaults: unknown key 'no_mapping'; known keys: camera, external, first_frame, "
                             "init, last_frame, rigid, set, simulate; run options go under \"set\""),
            std::string::npos)
      << in_defaults;
  EXPECT_EQ(in_defaults.find("sequence 1"), std::string::npos) << in_defaults;
  EXPECT_NE(ErrorOf(WriteFile(folder / "top.json", R"({"sequence": []})")).find("unknown key 'sequence'; did you mean sequences?"),
            std::string::npos);
  EXPECT_NE(ErrorOf(manifest("{}", R"({"name": "a", "import": {"format": "stereo", "path": "x", "depth_unit": 1}})"))
                .find("import: unknown key 'depth_unit'; did you mean depth_unit_mm?"),
            std::string::npos);
  std::filesystem::remove_all(folder);
}

TEST(Manifest, DefaultsShortNamesAndRelativePaths) {
  const auto folder = UniqueTempFolder("manifest_ok");
  const Manifest manifest = LoadManifest(WriteFile(folder / "lists" / "m.json", R"({
    "defaults": {"set": {"k": 2, "max_degree_D": 4}, "simulate": {"frames": 9}},
    "sequences": [
      {"name": "s", "preset": "sim-1", "set": {"max_degree_D": 6}},
      {"name": "f", "path": "../data/f", "rigid": true, "first_frame": 3, "camera": "cams/f.json"},
      {"name": "l", "preset": "sim-1", "simulate": {"camera.calibration": "lenses/l.yml"}},
      {"name": "st", "import": {"format": "stereo", "path": "raw/left.avi", "right": "raw/right.avi",
                                "calibration": "raw/stereo.yml", "rectified_size": "720x576", "stereo_depth": true,
                                "stereo_set": {"min_depth_mm": 20}}}
    ]})"));
  ASSERT_EQ(manifest.sequences.size(), 4u);
  const ManifestSequence& s = manifest.sequences[0];
  EXPECT_EQ(s.simulate, std::vector<std::string>{"frames=9"});
  EXPECT_EQ(s.assignments, (std::vector<std::string>{"deformation.k=2", "deformation.max_degree_D=6"}));
  const ManifestSequence& f = manifest.sequences[1];
  EXPECT_TRUE(f.simulate.empty());  // simulator defaults concern presets only
  EXPECT_EQ(f.path, (std::filesystem::absolute(folder) / "data" / "f").lexically_normal());
  EXPECT_TRUE(f.rigid);
  EXPECT_NE(std::find(f.assignments.begin(), f.assignments.end(), "run.first_frame=3"), f.assignments.end());
  const std::string camera = "run.camera=" + (std::filesystem::absolute(folder) / "lists" / "cams" / "f.json").lexically_normal().string();
  EXPECT_NE(std::find(f.assignments.begin(), f.assignments.end(), camera), f.assignments.end());
  // A lens to render with is a path too, relative to the manifest.
  const std::string lens =
      "camera.calibration=" + (std::filesystem::absolute(folder) / "lists" / "lenses" / "l.yml").lexically_normal().string();
  EXPECT_EQ(manifest.sequences[2].simulate, (std::vector<std::string>{lens, "frames=9"}));
  // A raw stereo recording: its three files relative to the manifest, a flag given bare (the
  // options in the keys' alphabetical order).
  const auto raw = [&](const char* file) {
    return (std::filesystem::absolute(folder) / "lists" / "raw" / file).lexically_normal().string();
  };
  EXPECT_EQ(manifest.sequences[3].import,
            (std::vector<std::string>{"--calibration", raw("stereo.yml"), "--format", "stereo", "--in", raw("left.avi"),
                                      "--rectified-size", "720x576", "--right", raw("right.avi"), "--stereo-depth",
                                      "--stereo-set", "min_depth_mm=20"}));
  std::filesystem::remove_all(folder);
}

// --print-options and config.json nest option groups; --set dots them. A manifest takes both,
// and a group written out merges with the defaults field by field, not as a whole.
TEST(Manifest, OptionGroupsMayBeWrittenOutOrDotted) {
  const auto folder = UniqueTempFolder("manifest_groups");
  const Manifest manifest = LoadManifest(WriteFile(folder / "m.json", R"({
    "defaults": {"simulate": {"camera.width": 320}, "set": {"deformation": {"k": 2}}},
    "sequences": [
      {"name": "a", "preset": "sim-3", "simulate": {"camera": {"height": 240, "calibration": "l.yml"}, "frames": 9},
       "set": {"tracking": {"rigid": true}, "deformation": {"sigma_factor": 3}}}
    ]})"));
  ASSERT_EQ(manifest.sequences.size(), 1u);
  const std::string lens = "camera.calibration=" + (std::filesystem::absolute(folder) / "l.yml").lexically_normal().string();
  EXPECT_EQ(manifest.sequences[0].simulate,
            (std::vector<std::string>{lens, "camera.height=240", "camera.width=320", "frames=9"}));
  const std::vector<std::string>& set = manifest.sequences[0].assignments;
  for (const char* assignment : {"deformation.k=2", "deformation.sigma_factor=3", "tracking.rigid=true"}) {
    EXPECT_NE(std::find(set.begin(), set.end(), assignment), set.end()) << assignment;
  }
  const auto error = [&](const std::string& sequence) {
    return ErrorOf(WriteFile(folder / "bad.json", R"({"sequences": [)" + sequence + "]}"));
  };
  const std::string twice = error(R"({"name": "b", "preset": "sim-3", "simulate": {"camera.width": 64, "camera": {"width": 32}}})");
  EXPECT_NE(twice.find("sequence 1 ('b'): simulate: option 'camera.width' is given twice"), std::string::npos) << twice;
  const std::string empty = error(R"({"name": "b", "preset": "sim-3", "simulate": {"camera": {}}})");
  EXPECT_NE(empty.find("option 'camera' is a group"), std::string::npos) << empty;
  std::filesystem::remove_all(folder);
}

TEST(Manifest, OnlyKeepsTheNamedSequencesInTheManifestsOrder) {
  const auto folder = UniqueTempFolder("manifest_only");
  const Manifest manifest = LoadManifest(WriteFile(folder / "m.json", R"({
    "defaults": {"set": {"k": 2}},
    "sequences": [{"name": "sim-3", "preset": "sim-3"}, {"name": "lap-lobes", "preset": "lap-lobes"},
                  {"name": "sim-3-rigid", "preset": "sim-3", "rigid": true}]})"));
  const auto names = [](const Manifest& m) {
    std::vector<std::string> listed;
    for (const ManifestSequence& s : m.sequences) listed.push_back(s.name);
    return listed;
  };
  EXPECT_EQ(names(WithOnlySequences(manifest, {"sim-3*"})), (std::vector<std::string>{"sim-3", "sim-3-rigid"}));
  const Manifest two = WithOnlySequences(manifest, {"sim-3-rigid", "lap-lobes"});
  EXPECT_EQ(names(two), (std::vector<std::string>{"lap-lobes", "sim-3-rigid"}));
  EXPECT_TRUE(two.sequences[1].rigid);  // each keeps its settings
  EXPECT_EQ(two.sequences[1].assignments, manifest.sequences[2].assignments);
  try {
    WithOnlySequences(manifest, {"sim-3", "sim-9"});
    ADD_FAILURE() << "a name the manifest lacks must be an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no sequence matches \"sim-9\"; it has sim-3, lap-lobes, sim-3-rigid"),
              std::string::npos)
        << e.what();
  }
  std::filesystem::remove_all(folder);
}

// Every shipped manifest of simulated sequences loads and plans with its options validated
// (the dataset templates name paths on the user's disk and are tested by their importers).
TEST(Manifest, ShippedSimulationManifestsAreValid) {
  const auto folder = UniqueTempFolder("shipped_manifests");
  int checked = 0;
  for (const auto& entry : std::filesystem::directory_iterator(NRSLAM_MANIFEST_DIR)) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() != ".json" || name.find("template") != std::string::npos ||
        name.find("baseline") != std::string::npos) {
      continue;
    }
    SCOPED_TRACE(name);
    const Manifest manifest = LoadManifest(entry.path());
    EXPECT_FALSE(manifest.sequences.empty());
    EXPECT_EQ(PlanEvaluation(manifest, {}, {}, folder / "out", folder / "cache").runs.size(), manifest.sequences.size());
    ++checked;
  }
  // ci-sim, ci-sim-monocular, paper-sim, paper-sim-monocular, colon-seeds-monocular, colon-long-wave-monocular,
  // lap-lobes-seeds-monocular
  EXPECT_GE(checked, 7);
  std::filesystem::remove_all(folder);
}

TEST(Seeds, ListsAndRangesOfSceneSeeds) {
  EXPECT_EQ(ParseSeedList("1-3,7"), (std::vector<uint64_t>{1, 2, 3, 7}));
  EXPECT_EQ(ParseSeedList("5"), (std::vector<uint64_t>{5}));
  for (const char* bad : {"", "3-1", "a", "1,1", "1-2,2", "-1", "1-", "1,,2", "0-1000"}) {
    EXPECT_THROW(ParseSeedList(bad), Error) << bad;
  }
}

// Each preset once per seed, named after it, with the manifest's own seed replaced; sequences
// on disk and external results (scored against one rendering) once, as they are.
TEST(Seeds, EveryPresetOncePerSeed) {
  Manifest manifest;
  ManifestSequence preset;
  preset.name = "s";
  preset.preset = "sim-3";
  preset.simulate = {"frames=30", "seed=9"};
  ManifestSequence on_disk;
  on_disk.name = "p";
  on_disk.path = "/data/p";
  ManifestSequence external = preset;
  external.name = "defslam";
  external.external.estimates = "defslam.csv";
  manifest.sequences = {preset, on_disk, external};
  const Manifest seeded = WithSceneSeeds(manifest, {1, 2});
  ASSERT_EQ(seeded.sequences.size(), 4u);
  EXPECT_EQ(seeded.sequences[0].name, "s-seed1");
  EXPECT_EQ(seeded.sequences[0].simulate, (std::vector<std::string>{"frames=30", "seed=1"}));
  EXPECT_EQ(seeded.sequences[1].name, "s-seed2");
  EXPECT_EQ(seeded.sequences[1].simulate, (std::vector<std::string>{"frames=30", "seed=2"}));
  EXPECT_EQ(seeded.sequences[2].name, "p");
  EXPECT_EQ(seeded.sequences[3].name, "defslam");
  EXPECT_EQ(seeded.sequences[3].simulate, preset.simulate);
  // A copy's name must not be taken already.
  on_disk.name = "s-seed2";
  manifest.sequences = {preset, on_disk};
  EXPECT_THROW(WithSceneSeeds(manifest, {1, 2}), Error);
}

// --seeds 1-3 on the monocular suite plans the shipped colon-seeds manifest's runs: the same
// names, the same renders (so the cache is shared) and the same options.
TEST(Seeds, TheSuiteOverThreeSeedsIsTheShippedSeedManifest) {
  const auto folder = UniqueTempFolder("seeded_suite");
  const std::filesystem::path manifests(NRSLAM_MANIFEST_DIR);
  const EvaluationPlan seeded =
      PlanEvaluation(WithSceneSeeds(LoadManifest(manifests / "paper-sim-monocular.json"), ParseSeedList("1-3")), {}, {},
                     folder / "out", folder / "cache");
  const EvaluationPlan shipped =
      PlanEvaluation(LoadManifest(manifests / "colon-seeds-monocular.json"), {}, {}, folder / "out", folder / "cache");
  ASSERT_EQ(shipped.runs.size(), 21u);
  for (const RunJob& run : shipped.runs) {
    SCOPED_TRACE(run.sequence);
    const auto same = std::find_if(seeded.runs.begin(), seeded.runs.end(),
                                   [&run](const RunJob& other) { return other.sequence == run.sequence; });
    ASSERT_NE(same, seeded.runs.end());
    EXPECT_EQ(seeded.prepares[same->prepare].folder, shipped.prepares[run.prepare].folder);
    EXPECT_EQ(same->options, run.options);
  }
  std::filesystem::remove_all(folder);
}

TEST(Sweep, GridOverOptionsWithOneFolderPerPoint) {
  const auto folder = UniqueTempFolder("sweep_plan");
  const Manifest manifest =
      LoadManifest(WriteFile(folder / "m.json", R"({"sequences": [{"name": "s", "preset": "sim-0"}, {"name": "t", "preset": "sim-0"}]})"));
  const EvaluationPlan plan =
      PlanEvaluation(manifest, {}, {ParseSweep("k=0.5,2"), ParseSweep("max_degree_D=3,5,10")}, folder / "out", folder / "cache");
  EXPECT_EQ(plan.prepares.size(), 1u);  // both sequences are the same render
  ASSERT_EQ(plan.runs.size(), 12u);
  EXPECT_EQ(plan.runs[0].label, "k=0.5,max_degree_D=3");
  EXPECT_EQ(plan.runs[5].label, "k=2,max_degree_D=10");
  EXPECT_EQ(plan.runs[5].run_folder, std::filesystem::absolute(folder / "out" / "runs" / "s" / "k=2,max_degree_D=10"));
  EXPECT_THROW(ParseSweep("k"), Error);
  EXPECT_THROW(ParseSweep("nonsense=1,2"), Error);
  // A value the option cannot take is caught before anything runs.
  EXPECT_THROW(PlanEvaluation(manifest, {}, {ParseSweep("k=-1")}, folder / "out", folder / "cache"), Error);
  // A value given twice would be two runs in one folder; one option swept twice (under any of
  // its names) would leave one sweep without effect.
  const auto refused = [&](const std::vector<Sweep>& grid, const std::string& message) {
    ExpectRefused([&] { PlanEvaluation(manifest, {}, grid, folder / "out", folder / "cache"); }, message);
  };
  refused({ParseSweep("k=1,2,1")}, "deformation.k: value 1 is given twice");
  refused({ParseSweep("k=1"), ParseSweep("deformation.k=2")}, "deformation.k is swept twice");
  // Set and swept on one command line: the sweep would win in every run, without a word before.
  ExpectRefused([] { RejectSetAndSwept({ResolveRunAssignment("k=2")}, {ParseSweep("deformation.k=1,3")}); },
                "--set deformation.k=2 and --sweep deformation.k: the sweep would set it in every run; give one of them");
  RejectSetAndSwept({ResolveRunAssignment("sigma_factor=2")}, {ParseSweep("k=1,3")});
  // Two options with one last name would label their runs alike.
  refused({ParseSweep("tracking.min_points=10"), ParseSweep("initialisation.min_points=50")},
          "two swept options are named 'min_points'");
  std::filesystem::remove_all(folder);
}

// A simulator option swept renders the presets once per value (into the cache, keyed by the
// simulator's arguments) and runs each value on its own rendering; run options are not touched.
TEST(Sweep, SimulatorOptionsRenderThePresetsAnewPerValue) {
  const auto folder = UniqueTempFolder("sweep_simulator");
  const Manifest manifest = LoadManifest(WriteFile(folder / "m.json", R"({"sequences": [
      {"name": "s", "preset": "sim-3", "simulate": {"deformation.amplitude_mm": 2.5, "frames": 30}},
      {"name": "s-rigid", "preset": "sim-3", "simulate": {"deformation.amplitude_mm": 2.5, "frames": 30}, "rigid": true}]})"));
  const EvaluationPlan plan = PlanEvaluation(
      manifest, {}, {ParseSweep("simulate.amplitude_mm=0,10"), ParseSweep("k=0.5,2")}, folder / "out", folder / "cache");
  ASSERT_EQ(plan.runs.size(), 8u);
  ASSERT_EQ(plan.prepares.size(), 2u);  // one rendering per amplitude, shared by both sequences and both k
  const auto renders = [&](size_t prepare, const std::string& assignment) {
    const std::vector<std::string>& arguments = plan.prepares[prepare].arguments;
    return std::find(arguments.begin(), arguments.end(), assignment) != arguments.end();
  };
  EXPECT_TRUE(renders(0, "deformation.amplitude_mm=0"));  // the sweep's value replaces the manifest's 2.5
  EXPECT_FALSE(renders(0, "deformation.amplitude_mm=2.5"));
  EXPECT_TRUE(renders(0, "frames=30"));                   // and the manifest's other options stay
  EXPECT_TRUE(renders(1, "deformation.amplitude_mm=10"));
  for (const RunJob& run : plan.runs) {
    const bool zero = run.label.rfind("amplitude_mm=0,", 0) == 0;
    EXPECT_EQ(run.prepare, zero ? 0 : 1) << run.label;
    EXPECT_EQ(run.sequence_folder, plan.prepares[run.prepare].folder);
    EXPECT_EQ(run.arguments.front(), run.sequence_folder.string());
    // nrslam_run gets the run option, never the simulator's.
    EXPECT_EQ(std::count_if(run.arguments.begin(), run.arguments.end(),
                            [](const std::string& a) {
                              return a.rfind("simulate.", 0) == 0 || a.rfind("deformation.amplitude", 0) == 0;
                            }),
              0);
    EXPECT_NE(std::find(run.arguments.begin(), run.arguments.end(), run.point[1]), run.arguments.end()) << run.label;
  }
  EXPECT_EQ(plan.runs[1].label, "amplitude_mm=0,k=2");
  EXPECT_EQ(plan.runs[1].point[0], "simulate.deformation.amplitude_mm=0");
  EXPECT_EQ(plan.runs[1].run_folder, std::filesystem::absolute(folder / "out" / "runs" / "s" / "amplitude_mm=0,k=2"));
  // A value that is a path (a lens to render with) names one folder inside --out, whatever it holds.
  const EvaluationPlan lenses = PlanEvaluation(
      manifest, {}, {ParseSweep("simulate.camera.calibration=/data/lens%1.yml,../../outside.yml")}, folder / "out",
      folder / "cache");
  ASSERT_EQ(lenses.runs.size(), 4u);
  EXPECT_EQ(lenses.runs[0].label, "calibration=/data/lens%1.yml");
  EXPECT_EQ(lenses.runs[0].run_folder,
            std::filesystem::absolute(folder / "out" / "runs" / "s" / "calibration=%2Fdata%2Flens%251.yml"));
  EXPECT_EQ(lenses.runs[1].run_folder,
            std::filesystem::absolute(folder / "out" / "runs" / "s" / "calibration=..%2F..%2Foutside.yml"));

  ExpectRefused([] { ParseSweep("simulate.amplitude=1,2"); },
                "did you mean colon.bend_amplitude_mm or deformation.amplitude_mm?");
  ExpectRefused([] { ParseSweep("amplitude_mm=1,2"); },
                "a simulator option; to render the presets anew for each value, sweep simulate.deformation.amplitude_mm");
  ExpectRefused([] { ParseSweep("simulate.seed=1,2"); }, "with --seeds");
  ExpectRefused(
      [&] { PlanEvaluation(manifest, {}, {ParseSweep("simulate.amplitude_mm=5,40")}, folder / "out", folder / "cache"); },
      "sequence 's' at amplitude_mm=40: simulate: sim deformation: amplitude_mm must be in [0, 30]");
  const Manifest on_disk = LoadManifest(WriteFile(folder / "d.json", R"({"sequences": [{"name": "d", "path": "seq"}]})"));
  ExpectRefused(
      [&] { PlanEvaluation(on_disk, {}, {ParseSweep("simulate.amplitude_mm=5")}, folder / "out", folder / "cache"); },
      "sequence 'd' is not rendered from a preset");
  std::filesystem::remove_all(folder);
}

RunResult Result(const std::string& sequence, double rmse, int tracked) {
  RunResult r;
  r.sequence = sequence;
  r.status = "ok";
  r.rmse_mm = rmse;
  r.frames_tracked = tracked;
  r.frames_total = 60;
  r.init_frame = 0;
  return r;
}

TEST(Baseline, PassesOnEqualFailsOnWorseOrMissing) {
  const std::vector<RunResult> before = {Result("a", 1.0, 60), Result("b", 0.10, 60)};
  const Json baseline = MakeBaseline(before, BaselineTolerance{});  // 10 % + 0.02 mm
  EXPECT_TRUE(CheckBaseline(before, baseline).passed);
  // Within the tolerance: 1.0 → 1.11 (allowed 1.12), and an improvement.
  EXPECT_TRUE(CheckBaseline({Result("a", 1.11, 60), Result("b", 0.05, 60)}, baseline).passed);
  const BaselineCheck worse = CheckBaseline({Result("a", 1.13, 60), Result("b", 0.10, 60)}, baseline);
  EXPECT_FALSE(worse.passed);
  EXPECT_NE(worse.report.find("WORSE: RMSE +13.0 %"), std::string::npos) << worse.report;
  EXPECT_FALSE(CheckBaseline({Result("a", 1.0, 59), Result("b", 0.10, 60)}, baseline).passed);
  EXPECT_FALSE(CheckBaseline({Result("a", 1.0, 60)}, baseline).passed);  // b missing
  RunResult failed = Result("b", 0, 0);
  failed.status = "failed";
  failed.error = "boom";
  const BaselineCheck crash = CheckBaseline({Result("a", 1.0, 60), failed}, baseline);
  EXPECT_FALSE(crash.passed);
  EXPECT_NE(crash.report.find("FAILED: boom"), std::string::npos);
  // The report says which code made the baseline and which made the runs checked against it.
  EXPECT_NE(crash.report.find("code of the baseline: not recorded; of these runs: not recorded"), std::string::npos)
      << crash.report;
  std::vector<RunResult> recorded = before;
  recorded[0].revision = "0123456789ab";
  recorded[1].revision = "0123456789ab-dirty-fedcba98";
  const Json from_recorded = MakeBaseline(recorded, BaselineTolerance{});
  EXPECT_EQ(from_recorded["runs"]["a"]["revision"], "0123456789ab");
  EXPECT_NE(CheckBaseline(before, from_recorded)
                .report.find("code of the baseline: 0123456789ab, 0123456789ab-dirty-fedcba98; of these runs: not recorded\n"),
            std::string::npos);
  // With code fingerprints on both sides it also says whether the code itself changed: another
  // commit (here, one that changed only documentation) can hold the same code.
  for (RunResult& r : recorded) r.code = "c0dec0dec0de";
  std::vector<RunResult> later = recorded;
  for (RunResult& r : later) r.revision = "fedcba987654";
  const Json with_code = MakeBaseline(recorded, BaselineTolerance{});
  EXPECT_EQ(with_code["runs"]["b"]["code"], "c0dec0dec0de");
  EXPECT_NE(CheckBaseline(later, with_code).report.find("of these runs: fedcba987654 (the same code)\n"), std::string::npos)
      << CheckBaseline(later, with_code).report;
  later[1].code = "0123456789ab";
  EXPECT_NE(CheckBaseline(later, with_code).report.find("of these runs: fedcba987654 (other code)\n"), std::string::npos);
}

TEST(Baseline, APooledToleranceCatchesRunsWorseTogetherThatEachPassAlone) {
  const std::vector<RunResult> before = {Result("a", 1.0, 60), Result("b", 2.0, 60), Result("c", 4.0, 60),
                                         Result("d", 8.0, 60)};
  BaselineTolerance loose;
  loose.rmse_relative = 0.5;
  loose.pooled_rmse_relative = 0.1;
  const Json baseline = MakeBaseline(before, loose);
  EXPECT_EQ(baseline["tolerance"]["pooled_rmse_relative"], 0.1);
  // Every run 20 % worse: each within its 50 %, together beyond 10 %.
  std::vector<RunResult> worse = before;
  for (RunResult& r : worse) r.rmse_mm *= 1.2;
  const BaselineCheck together = CheckBaseline(worse, baseline);
  EXPECT_FALSE(together.passed) << together.report;
  EXPECT_NE(together.report.find("by 50 % + 0.02 mm per run and by 10 % over all runs"), std::string::npos)
      << together.report;
  EXPECT_NE(together.report.find("better / same / worse): 0 / 0 / 4; RMSE ratio now / before, geometric mean: "
                                 "1.200 (95 % CI 1.200 to 1.200), allowed 1.100: WORSE"),
            std::string::npos)
      << together.report;
  EXPECT_NE(together.report.find("FAILED: the runs together are worse than the baseline allows"), std::string::npos);
  // Chaos, not a change for the worse: one run 40 % worse and another 30 % better (ratio 0.98).
  std::vector<RunResult> scattered = before;
  scattered[0].rmse_mm = 1.4;
  scattered[3].rmse_mm = 5.6;
  EXPECT_TRUE(CheckBaseline(scattered, baseline).passed) << CheckBaseline(scattered, baseline).report;
  // Just inside: every run 9 % worse, or one run 21 % worse and the rest unchanged (4.9 %).
  std::vector<RunResult> inside = before;
  for (RunResult& r : inside) r.rmse_mm *= 1.09;
  EXPECT_TRUE(CheckBaseline(inside, baseline).passed);
  std::vector<RunResult> one_run = before;
  one_run[2].rmse_mm *= 1.21;
  EXPECT_TRUE(CheckBaseline(one_run, baseline).passed);
  // Baselines from before the pooled check have no such field: they check run by run only,
  // and still report the pooled ratio.
  Json older = baseline;
  older["tolerance"].erase("pooled_rmse_relative");
  const BaselineCheck unpooled = CheckBaseline(worse, older);
  EXPECT_TRUE(unpooled.passed) << unpooled.report;
  EXPECT_NE(unpooled.report.find("geometric mean: 1.200 (95 % CI 1.200 to 1.200); signed-rank p = "), std::string::npos)
      << unpooled.report;
  older["tolerance"]["pooled_rmse_relative"] = -0.1;
  EXPECT_THROW(CheckBaseline(before, older), Error);
}

TEST(Results, CsvNamesTheCodeOfEveryRun) {
  const auto folder = UniqueTempFolder("results_csv");
  RunResult recorded = Result("a", 1.5, 60);
  recorded.revision = "0123456789ab";
  recorded.code = "c0dec0dec0de";
  RunResult failed = Result("b", 0, 0);
  failed.status = "failed";
  failed.error = "cannot read rgb/000003.png, corrupt";
  WriteResults({recorded, failed}, folder);
  std::ifstream csv(folder / "results.csv");
  std::string header, first, second;
  std::getline(csv, header);
  std::getline(csv, first);
  std::getline(csv, second);
  EXPECT_EQ(header.substr(header.rfind(",fps,")),
            ",fps,peak_memory_mb,births_evaluated,birth_log_error_mean,birth_log_error_median,map_depth_change,"
            "map_depth_change_beyond_from,maps_given_up,revision,code,error");
  EXPECT_EQ(first.substr(first.size() - std::string(",0123456789ab,c0dec0dec0de,").size()), ",0123456789ab,c0dec0dec0de,");
  // Not recorded: empty.
  EXPECT_EQ(second.substr(second.find(",,,,,0,,,\"")), ",,,,,0,,,\"cannot read rgb/000003.png, corrupt\"");
  std::filesystem::remove_all(folder);
}

TEST(Results, BirthErrorsRoundTripAndStayEmptyWhereNoneWasScored) {
  const auto folder = UniqueTempFolder("results_births");
  RunResult scored = Result("a", 1.5, 60);
  scored.births_evaluated = 12;
  scored.birth_log_error_mean = -0.25;
  scored.birth_log_error_median = 0.125;
  const RunResult none = Result("b", 1.0, 60);
  WriteResults({scored, none}, folder);
  const std::vector<RunResult> read = ReadResults(folder);
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[0].births_evaluated, 12);
  EXPECT_EQ(read[0].birth_log_error_mean, std::optional<double>(-0.25));
  EXPECT_EQ(read[0].birth_log_error_median, std::optional<double>(0.125));
  EXPECT_EQ(read[1].births_evaluated, 0);
  EXPECT_FALSE(read[1].birth_log_error_mean || read[1].birth_log_error_median);
  std::ifstream csv(folder / "results.csv");
  std::string header, first, second;
  std::getline(csv, header);
  std::getline(csv, first);
  std::getline(csv, second);
  EXPECT_NE(first.find(",12,-0.25,0.125,"), std::string::npos) << first;
  EXPECT_NE(second.find(",0,,,"), std::string::npos) << second;
  std::filesystem::remove_all(folder);
}

// A map whose depth fell a millionfold is noted wherever the run's notes go; one that moved
// within kDepthChangeNoteFactor, or did not record it, is not.
TEST(Results, MapDepthChangeRoundTripsAndAFarOneIsNoted) {
  const auto folder = UniqueTempFolder("results_depth_change");
  RunResult collapsed = Result("a", 1.5, 60);
  collapsed.map_depth = {1.5e-6, 187};
  collapsed.maps_given_up = 2;
  RunResult steady = Result("b", 1.0, 60);
  steady.map_depth = {0.2, -1};
  const RunResult older = Result("c", 1.0, 60);
  WriteResults({collapsed, steady, older}, folder);
  const std::vector<RunResult> read = ReadResults(folder);
  ASSERT_EQ(read.size(), 3u);
  EXPECT_EQ(read[0].map_depth.ratio, 1.5e-6);
  EXPECT_EQ(read[0].map_depth.beyond_from, 187);
  EXPECT_EQ(read[0].maps_given_up, 2);
  EXPECT_EQ(read[1].maps_given_up, 0);
  EXPECT_EQ(read[1].map_depth.ratio, 0.2);
  EXPECT_EQ(read[1].map_depth.beyond_from, -1);
  EXPECT_EQ(read[2].map_depth.ratio, 0.0);
  const std::vector<std::string> notes = RunNotes(read[0]);
  ASSERT_EQ(notes.size(), 2u);
  EXPECT_EQ(notes[0], GivenUpText(2));
  EXPECT_EQ(notes[1].find("the map's median depth went ×1.5e-06 from its first tracked frame to its last, beyond 10× "
                          "from frame 187 on"),
            0u)
      << notes[1];
  EXPECT_TRUE(RunNotes(read[1]).empty());
  EXPECT_TRUE(RunNotes(read[2]).empty());
  // A folder that is not an evaluation's output is named as such (nrslam_eval diff reads two).
  EXPECT_NE(ErrorMessage([&] { ReadResults(folder / "runs"); }).find("is not a folder"), std::string::npos);
  EXPECT_NE(ErrorMessage([&] { ReadResults(folder.parent_path()); }).find("holds no results.json"), std::string::npos);
  std::ifstream csv(folder / "results.csv");
  std::string header, first;
  std::getline(csv, header);
  std::getline(csv, first);
  EXPECT_NE(first.find(",1.5e-06,187,"), std::string::npos) << first;
  std::filesystem::remove_all(folder);
}

TEST(Results, CodeIsTheSameOnlyWhenEveryRunRecordsOneFingerprint) {
  EXPECT_EQ(CompareCode({"a", "a"}, {"a"}), "the same code");
  EXPECT_EQ(CompareCode({"a", "a"}, {"a", "b"}), "other code");
  EXPECT_EQ(CompareCode({"a"}, {"b"}), "other code");
  EXPECT_EQ(CompareCode({"a", ""}, {"a"}), "");  // an older run: cannot tell
  EXPECT_EQ(CompareCode({}, {"a"}), "");
  RunResult run = Result("a", 1.0, 60);
  run.code = "c0dec0dec0de";
  EXPECT_EQ(ResultsFromJson(ToJson({run}))[0].code, "c0dec0dec0de");
  EXPECT_TRUE(ToJson({Result("a", 1.0, 60)})["results"][0]["code"].is_null());
  std::vector<RunResult> before = {run}, after = {run};
  after[0].revision = "fedcba987654";
  std::stringstream same;
  PrintDiff(DiffResults(before, after), "before", "after", same);
  EXPECT_NE(same.str().find("B: after (code: fedcba987654)\nA and B: the same code (by the code fingerprints of their runs)\n"),
            std::string::npos)
      << same.str();
}

TEST(Results, RevisionsAreListedOnceSortedWithTheUnrecordedLast) {
  EXPECT_EQ(DescribeRevisions(std::vector<std::string>{}), "not recorded");
  EXPECT_EQ(DescribeRevisions(std::vector<std::string>{"b", "", "a", "b"}), "a, b, not recorded");
  EXPECT_EQ(DescribeRevisions(std::vector<std::string>{"b", "b"}), "b");
  RunResult failed = Result("a", 1.0, 60);
  failed.status = "failed";
  EXPECT_EQ(DescribeRevisions(std::vector<RunResult>{failed, failed}), "none: every run failed");
  RunResult run = Result("a", 1.0, 60);
  run.revision = "0123456789ab";
  EXPECT_EQ(ResultsFromJson(ToJson({run}))[0].revision, "0123456789ab");
  EXPECT_TRUE(ToJson({Result("a", 1.0, 60)})["results"][0]["revision"].is_null());
  EXPECT_EQ(ResultsFromJson(ToJson({Result("a", 1.0, 60)}))[0].revision, "");
}

// A run without ground truth (a plain video) shows no RMSE rather than a perfect 0.000.
TEST(Results, RunsWithoutGroundTruthShowNoRmse) {
  RunResult video;
  video.sequence = "video";
  video.status = "ok";
  video.init_frame = 18;
  video.frames_tracked = 42;
  video.frames_total = 60;
  video.fps = 20;
  RunResult simulated = video;
  simulated.sequence = "sim";
  simulated.frames_evaluated = 42;
  simulated.rmse_mm = 1.25;
  simulated.rmse_median_mm = 1.5;
  std::stringstream table;
  PrintResults({video, simulated}, table);
  EXPECT_NE(table.str().find("no GT"), std::string::npos) << table.str();
  EXPECT_NE(table.str().find("1.250"), std::string::npos) << table.str();
  EXPECT_EQ(table.str().find("0.000"), std::string::npos) << table.str();
  const std::vector<RunResult> read = ResultsFromJson(ToJson({video, simulated}));
  EXPECT_FALSE(read[0].evaluated());
  EXPECT_EQ(read[1].frames_evaluated, 42);
  // Ground truth too sparse to score any frame is not shown as none, and the row says why.
  RunResult sparse = video;
  sparse.sequence = "sparse";
  sparse.input.frames_sparse_groundtruth = 42;
  std::stringstream sparse_table;
  PrintResults({sparse}, sparse_table);
  EXPECT_NE(sparse_table.str().find("sparse GT"), std::string::npos) << sparse_table.str();
  EXPECT_EQ(sparse_table.str().find("no GT"), std::string::npos) << sparse_table.str();
  EXPECT_NE(sparse_table.str().find("42 tracked frames not scored"), std::string::npos) << sparse_table.str();
  EXPECT_EQ(ResultsFromJson(ToJson({sparse}))[0].input.frames_sparse_groundtruth, 42);
  // results.json from before the field: every tracked frame had ground truth.
  Json old = ToJson({simulated});
  old["results"][0].erase("frames_evaluated");
  EXPECT_EQ(ResultsFromJson(old)[0].frames_evaluated, 42);
}

// A run that never initialised tracked nothing: no init frame and no RMSE, not "no GT".
TEST(Results, NeverInitialisedRunShowsDashesNotMissingGroundTruth) {
  RunResult waiting;
  waiting.sequence = "uniform";
  waiting.status = "not_initialised";
  waiting.init_frame = -1;
  waiting.frames_total = 30;
  waiting.fps = 200;
  std::stringstream table;
  PrintResults({waiting}, table);
  const std::string row = table.str().substr(table.str().find("uniform"));
  EXPECT_EQ(row.find("no GT"), std::string::npos) << table.str();
  EXPECT_EQ(row.find("-1"), std::string::npos) << table.str();
  EXPECT_TRUE(std::regex_search(row, std::regex(R"(not_initialised +- +0/30 +- +- +- +- +- +200\.0)"))) << table.str();
}

TEST(Results, WhereAndWhyARunStoppedIsShownAndKept) {
  RunResult lost = Result("sim-6-rigid", 0.25, 3);
  lost.status = "lost";
  lost.stop_frame = 3;
  lost.stop_reason = "only 7 points left after outlier rejection";
  RunResult waiting = Result("still", 0.0, 0);
  waiting.status = "lost";
  waiting.init_frame = -1;
  waiting.stop_reason = "initialising: 100 % low parallax";
  const RunResult fine = Result("sim-0", 0.1, 60);
  std::stringstream table;
  PrintResults({lost, waiting, fine}, table);
  EXPECT_NE(table.str().find("sim-6-rigid: lost from frame 3: only 7 points left after outlier rejection"),
            std::string::npos) << table.str();
  EXPECT_NE(table.str().find("still: never initialised: initialising: 100 % low parallax"), std::string::npos)
      << table.str();
  EXPECT_EQ(table.str().find("sim-0:"), std::string::npos) << table.str();
  const std::vector<RunResult> read = ResultsFromJson(ToJson({lost, waiting, fine}));
  EXPECT_EQ(read[0].stop_frame, 3);
  EXPECT_EQ(read[0].stop_reason, lost.stop_reason);
  EXPECT_EQ(read[1].stop_frame, -1);
  EXPECT_EQ(read[1].stop_reason, waiting.stop_reason);
  EXPECT_TRUE(read[2].stop_reason.empty());
  EXPECT_TRUE(ToJson({fine})["results"][0]["stop_reason"].is_null());
}

TEST(Results, FramesLostOrLeftUnscoredByUnreadableFilesOrDropoutsAreShownAndKept) {
  RunResult damaged = Result("sim-2", 0.5, 60);
  damaged.frames_evaluated = 58;
  damaged.input.frames_unreadable = 1;
  damaged.input.frames_unreadable_after_init = 1;
  damaged.input.frames_groundtruth_unreadable = 2;
  damaged.input.frames_dropout = 3;
  damaged.input.sudden_occlusions = 2;
  damaged.input.view_jumps = 1;
  damaged.input.static_fraction = 0.125;
  damaged.input.frames_past_end = 40;
  const RunResult fine = Result("sim-0", 0.1, 60);
  std::stringstream table;
  PrintResults({damaged, fine}, table);
  EXPECT_NE(table.str().find("sim-2: 1 frame unreadable (lost); ground-truth depth unreadable on 2 tracked frames "
                             "(not scored); metrics.csv names the files"),
            std::string::npos)
      << table.str();
  EXPECT_NE(table.str().find("sim-2: 3 frames skipped as image dropouts (lost; the map kept)"), std::string::npos)
      << table.str();
  EXPECT_NE(table.str().find("sim-2: 2 sudden occlusions: most of the view hidden at once"), std::string::npos)
      << table.str();
  EXPECT_NE(table.str().find("sim-2: 1 jump of the view: its tracks moved far more than over the frames before"),
            std::string::npos)
      << table.str();
  EXPECT_NE(table.str().find("sim-2: 12.5 % of the image never changed (an on-screen display, a black border or "
                             "background) and was left out (static_mask.png)"),
            std::string::npos)
      << table.str();
  EXPECT_NE(table.str().find("sim-2: 40 frames of the range asked for (run.last_frame) lie past the sequence's end: "
                             "the run stopped at its last frame"),
            std::string::npos)
      << table.str();
  EXPECT_EQ(table.str().find("sim-0:"), std::string::npos) << table.str();
  EXPECT_EQ(RunNotes(damaged).size(), 6u);
  EXPECT_TRUE(RunNotes(fine).empty());
  // The report's section of the run says the same.
  const auto folder = UniqueTempFolder("results_notes_report");
  WriteReport({damaged, fine}, {}, {}, folder / "report");
  const std::string html = FileText(folder / "report" / "index.html");
  EXPECT_NE(html.find("<p>3 frames skipped as image dropouts (lost; the map kept)</p>"), std::string::npos) << html;
  std::filesystem::remove_all(folder);
  const std::vector<RunResult> read = ResultsFromJson(ToJson({damaged, fine}));
  EXPECT_EQ(read[0].input.frames_unreadable, 1);
  EXPECT_EQ(read[0].input.frames_unreadable_after_init, 1);
  EXPECT_EQ(read[1].input.frames_unreadable_after_init, 0);
  EXPECT_EQ(read[0].input.frames_groundtruth_unreadable, 2);
  EXPECT_EQ(read[1].input.frames_groundtruth_unreadable, 0);
  EXPECT_EQ(read[0].input.frames_dropout, 3);
  EXPECT_EQ(read[1].input.frames_dropout, 0);
  EXPECT_EQ(read[0].input.sudden_occlusions, 2);
  EXPECT_EQ(read[1].input.sudden_occlusions, 0);
  EXPECT_EQ(read[0].input.view_jumps, 1);
  EXPECT_EQ(read[1].input.view_jumps, 0);
  EXPECT_EQ(read[0].input.frames_past_end, 40);
  EXPECT_EQ(read[1].input.frames_past_end, 0);
  const auto csv_folder = UniqueTempFolder("results_notes_csv");
  WriteResults({damaged}, csv_folder);
  std::ifstream csv(csv_folder / "results.csv");
  std::string header, row;
  std::getline(csv, header);
  std::getline(csv, row);
  EXPECT_NE(header.find(",frames_dropout,sudden_occlusions,view_jumps,static_fraction,frames_past_end,"),
            std::string::npos)
      << header;
  EXPECT_NE(row.find(",3,2,1,0.125,40,"), std::string::npos) << row;
  EXPECT_EQ(std::count(header.begin(), header.end(), ','), std::count(row.begin(), row.end(), ','));
  std::filesystem::remove_all(csv_folder);
  EXPECT_EQ(read[0].input.static_fraction, 0.125);
  EXPECT_EQ(read[1].input.static_fraction, 0);
}

// A run is "lost" when it leaves frames after its initialisation untracked, or ends without
// tracking; frames skipped as image dropouts with the map kept, and unreadable frames, are the
// input's and do not count.
TEST(Results, StatusFromTheFigures) {
  RunResult r;
  r.frames_total = 120;
  EXPECT_EQ(RunStatus(r), "not_initialised");
  r.init_frame = 3;
  r.frames_tracked = 117;
  EXPECT_EQ(RunStatus(r), "ok");
  r.frames_tracked = 116;
  EXPECT_EQ(RunStatus(r), "lost");  // one frame lost on the way (e.g. a new map started after it)
  r.input.frames_dropout = 1;
  EXPECT_EQ(RunStatus(r), "ok");    // that frame was skipped as an image dropout
  r.input.frames_dropout = 0;
  r.input.frames_unreadable = 2;
  EXPECT_EQ(RunStatus(r), "lost");  // unreadable, but the figures do not say the frame came after the start
  r.input.frames_unreadable_after_init = 1;
  EXPECT_EQ(RunStatus(r), "ok");    // it did: the input's, not the tracker's
  r.input.frames_unreadable_after_init = 0;
  r.input.frames_dropout = 1;
  r.stop_frame = 119;
  r.stop_reason = "only 0 of 180 points tracked: skipped as an image dropout, the map kept (1 of at most 5 in a row)";
  EXPECT_EQ(RunStatus(r), "lost");  // skipped at the end: the run ends without tracking
}

// One run of a (k, D) sweep grid, evaluated on 100 frames.
RunResult GridRun(const std::string& sequence, const std::string& k, const std::string& d, bool lost, double rmse_mm) {
  RunResult r;
  r.sequence = sequence;
  r.point = {"deformation.k=" + k, "deformation.max_degree_D=" + d};
  r.label = "k=" + k + " D=" + d;
  r.status = lost ? "lost" : "ok";
  r.frames_evaluated = 100;
  r.rmse_mm = rmse_mm;
  return r;
}

// results.md and results.tex hold the printed tables, the notes under them, and a sweep's
// summary: what nrslam_eval prints, ready for notes and papers.
TEST(Results, TablesAreWrittenAsMarkdownAndLatex) {
  const auto folder = UniqueTempFolder("results_tables");
  std::vector<RunResult> results = {GridRun("sim_3", "2", "5", false, 0.707), GridRun("sim_3", "10", "5", true, 1.5)};
  for (RunResult& r : results) {
    r.init_frame = 0;
    r.frames_tracked = r.frames_total = 100;
  }
  results[1].frames_tracked = 90;
  results[1].stop_frame = 90;
  results[1].stop_reason = "only 7 points left after outlier rejection";
  RunResult failed = GridRun("lap", "2", "5", false, 0);
  failed.status = "failed";
  failed.error = "cannot read rgb/000003.png";
  results.push_back(failed);
  WriteResults(results, folder);
  const std::string markdown = FileText(folder / "results.md");
  const std::string latex = FileText(folder / "results.tex");
  EXPECT_EQ(markdown.rfind("| sequence | sweep point | status | init | tracked | RMSE mm |", 0), 0u) << markdown;
  EXPECT_NE(markdown.find("| sim_3 | k=2 D=5 | ok |"), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("| 0.707 |"), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("- sim_3 [k=10 D=5]: lost from frame 90: only 7 points left"), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("- FAILED lap [k=2 D=5]: cannot read rgb/000003.png"), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("Per swept value, over the 0 sequence(s)"), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("| deformation.k | 2 |"), std::string::npos) << markdown;
  EXPECT_NE(latex.find("\\begin{tabular}{lrrrrrrrrrrr}\n\\toprule\n"), std::string::npos) << latex;
  EXPECT_NE(latex.find("sim\\_3 & k=2 D=5 & ok & 0 & 100/100 & 0.707 &"), std::string::npos) << latex;
  EXPECT_NE(latex.find("% FAILED lap [k=2 D=5]: cannot read rgb/000003.png\n"), std::string::npos) << latex;
  EXPECT_NE(latex.find("deformation.k & 2 &"), std::string::npos) << latex;
  std::filesystem::remove_all(folder);
}

// Known answers for a 2 × 2 grid (k, D) over three sequences, one of which is lost at k = 10:
// only the two sequences complete at every point count, each value sees 2 points × 2 sequences.
TEST(Results, SweepSummaryAveragesEachValueOverTheSameSequences) {
  std::vector<RunResult> results;
  for (const std::string sequence : {"a", "b", "c"}) {
    for (const std::string k : {"10", "2"}) {  // "2" comes first: numeric order
      for (const std::string d : {"3", "5"}) {
        const double rmse = (sequence == "a" ? 1.0 : 2.0) * std::stod(k) + std::stod(d) / 10;  // c equals b
        RunResult r = GridRun(sequence, k, d, sequence == "c" && k == "10", rmse);
        r.ate_mm = sequence == "b" && d == "5" ? -1 : r.rmse_mm / 2;
        r.rmse_map_scale_mm = sequence == "a" && k == "2" ? -1 : 2 * r.rmse_mm;
        results.push_back(r);
      }
    }
  }
  const std::vector<SweepValueSummary> values = SummariseSweep(results);
  ASSERT_EQ(values.size(), 4u);
  EXPECT_EQ(values[0].option, "deformation.k");
  EXPECT_EQ(values[0].value, "2");
  EXPECT_EQ(values[1].value, "10");
  EXPECT_EQ(values[2].option, "deformation.max_degree_D");
  for (const SweepValueSummary& v : values) EXPECT_EQ(v.runs, 4) << v.option << "=" << v.value;
  // k = 2 over a and b: 2.3 2.5 4.3 4.5.
  EXPECT_DOUBLE_EQ(values[0].mean_rmse_mm, 3.4);
  EXPECT_DOUBLE_EQ(values[0].median_rmse_mm, 4.3);  // the upper median
  EXPECT_LT(values[0].mean_ate_mm, 0);              // b at D = 5 has none
  EXPECT_EQ(values[0].short_runs, 0);
  EXPECT_EQ(values[1].short_runs, 2);               // c at k = 10, both D
  // D = 3 over a and b: 2.3 10.3 4.3 20.3; every one of them has a trajectory error.
  EXPECT_DOUBLE_EQ(values[2].mean_rmse_mm, 9.3);
  EXPECT_DOUBLE_EQ(values[2].mean_ate_mm, 4.65);
  EXPECT_LT(values[0].mean_map_scale_mm, 0);        // a at k = 2 has none recorded
  EXPECT_DOUBLE_EQ(values[1].mean_map_scale_mm, 2 * values[1].mean_rmse_mm);
  EXPECT_EQ(values[2].short_runs, 1);
  std::stringstream table;
  PrintResults(results, table);
  EXPECT_NE(table.str().find("over the 2 sequence(s)"), std::string::npos) << table.str();
}

// Known answers for the paired counts: k = 2 against k's default 1.1, each run against the run
// of the same sequence and the same D. a is better at both D, b the same (within 0.0005 mm) at
// both, c worse at D = 3 and better at D = 5 (paired with D = 3 it would be worse twice), and d,
// lost at k = 2, counts nowhere. D's default (10) is not swept, so D's values are not paired.
TEST(Results, SweepSummaryCountsRunsBetterAndWorseThanTheDefault) {
  const std::map<std::string, std::map<std::string, double>> rmse = {
      {"a", {{"1.1 3", 1.0}, {"1.1 5", 1.0}, {"2 3", 0.5}, {"2 5", 0.5}}},
      {"b", {{"1.1 3", 2.0}, {"1.1 5", 2.0}, {"2 3", 2.0003}, {"2 5", 1.9998}}},
      {"c", {{"1.1 3", 1.0}, {"1.1 5", 5.0}, {"2 3", 3.0}, {"2 5", 4.0}}},
      {"d", {{"1.1 3", 1.0}, {"1.1 5", 1.0}, {"2 3", 9.0}, {"2 5", 9.0}}}};
  std::vector<RunResult> results;
  for (const auto& [sequence, cells] : rmse) {
    for (const auto& [point, value] : cells) {
      const std::string k = point.substr(0, point.find(' ')), d = point.substr(point.find(' ') + 1);
      results.push_back(GridRun(sequence, k, d, sequence == "d" && k == "2", value));
    }
  }
  const std::vector<SweepValueSummary> values = SummariseSweep(results);
  ASSERT_EQ(values.size(), 4u);
  EXPECT_EQ(values[0].value, "1.1");
  EXPECT_TRUE(values[0].is_default);
  EXPECT_FALSE(values[0].paired);
  EXPECT_EQ(values[1].value, "2");
  ASSERT_TRUE(values[1].paired);
  EXPECT_EQ(values[1].against_default.better, 3);
  EXPECT_EQ(values[1].against_default.same, 2);
  EXPECT_EQ(values[1].against_default.worse, 1);
  EXPECT_DOUBLE_EQ(values[1].against_default.SignTestP(), 0.625);  // 3 against 1: 2 · 5/16
  // All six pairs, the two "same" ones too, in the geometric mean ratio; the signed-rank test
  // over the four that moved (see SignedRankTestKnownAnswers).
  EXPECT_NEAR(values[1].against_default.GeometricMeanRatio(),
              std::pow(0.5 * 0.5 * (2.0003 / 2) * (1.9998 / 2) * 3 * 0.8, 1.0 / 6), 1e-12);
  EXPECT_DOUBLE_EQ(values[1].against_default.SignedRankP(), 0.875);
  for (size_t i : {2u, 3u}) EXPECT_FALSE(values[i].paired || values[i].is_default) << values[i].value;
  std::stringstream table;
  PrintResults(results, table);
  EXPECT_NE(table.str().find("3 / 2 / 1"), std::string::npos) << table.str();
  EXPECT_NE(table.str().find("(default)"), std::string::npos) << table.str();
}

// Known answers of the two-sided Wilcoxon signed-rank test on log(RMSE / reference).
TEST(Results, SignedRankTestKnownAnswers) {
  // Pairs (reference, RMSE) whose |log ratio| has rank r (1-based), worse when r is in `worse`.
  const auto ranked = [](int n, const std::set<int>& worse) {
    RmseChangeCounts counts;
    for (int r = 1; r <= n; ++r) counts.Add(1.0, std::exp((worse.count(r) ? 0.01 : -0.01) * r));
    return counts;
  };
  // Every run better: of the 2^5 sign patterns only this one and its mirror are as extreme.
  EXPECT_DOUBLE_EQ(ranked(5, {}).SignedRankP(), 2.0 / 32);
  // The worse runs' ranks sum to 8: 25 of the 1024 subsets of 1..10 sum to at most 8.
  EXPECT_DOUBLE_EQ(ranked(10, {1, 3, 4}).SignedRankP(), 50.0 / 1024);
  EXPECT_DOUBLE_EQ(ranked(10, {1, 3, 4}).SignedRankP(), ranked(10, {2, 5, 6, 7, 8, 9, 10}).SignedRankP());
  // Tied sizes share their mean rank: ranks 1, 2.5, 2.5, 4 with the worse run's 4; rank sums
  // ≤ 4 come from 7 of the 16 sign patterns.
  RmseChangeCounts tied;
  for (double rmse : {0.8, 0.5, 0.5, 3.0}) tied.Add(1.0, rmse);
  tied.Add(2.0, 2.0003);  // "same": left out of the test
  EXPECT_DOUBLE_EQ(tied.SignedRankP(), 14.0 / 16);
  // Either side of the switch to the normal approximation (200 → 201 runs), every other rank
  // worse: both p ≈ 0.952 (z ≈ 0.06).
  std::set<int> even;
  for (int r = 2; r <= 200; r += 2) even.insert(r);
  EXPECT_NEAR(ranked(200, even).SignedRankP(), 0.952, 0.005);
  EXPECT_NEAR(ranked(201, even).SignedRankP(), 0.952, 0.005);
  EXPECT_LT(ranked(300, {}).SignedRankP(), 1e-40);
  EXPECT_DOUBLE_EQ(RmseChangeCounts().SignedRankP(), 1.0);
  EXPECT_DOUBLE_EQ(RmseChangeCounts().GeometricMeanRatio(), 1.0);
}

// Known answers of the geometric mean ratio's confidence interval: Student's t over the log ratios.
TEST(Results, GeometricMeanRatioIntervalKnownAnswers) {
  // Log ratios 0, 0.2, 0.4: mean 0.2, standard error 0.2 / √3, t* = 4.302653 at 2 degrees of
  // freedom, so the interval is exp(0.2 ± 0.496827).
  RmseChangeCounts three;
  for (double log_ratio : {0.0, 0.2, 0.4}) three.Add(2.0, 2.0 * std::exp(log_ratio));
  const auto interval = three.GeometricMeanRatioInterval();
  ASSERT_TRUE(interval.has_value());
  EXPECT_NEAR(interval->low, 0.743172167, 1e-8);
  EXPECT_NEAR(interval->high, 2.007374285, 1e-8);
  EXPECT_EQ(three.GeometricMeanRatioText(), "1.221 (95 % CI 0.743 to 2.007)");
  EXPECT_EQ(three.GeometricMeanRatioText(true), "0.819 (95 % CI 0.498 to 1.346)");
  // A wider confidence gives a wider interval around the same ratio.
  const auto wider = three.GeometricMeanRatioInterval(0.99);
  EXPECT_LT(wider->low, interval->low);
  EXPECT_GT(wider->high, interval->high);
  // One pair has no spread to measure: no interval, the ratio alone.
  RmseChangeCounts one;
  one.Add(1.0, 1.5);
  EXPECT_FALSE(one.GeometricMeanRatioInterval().has_value());
  EXPECT_EQ(one.GeometricMeanRatioText(), "1.500");
}

// Known answers of the two-sided exact sign test: 2 · P(Binomial(n, 1/2) ≥ the larger count).
TEST(Results, SignTestOverTheRunsThatMoved) {
  const auto p = [](int better, int same, int worse) {
    RmseChangeCounts counts;
    counts.better = better;
    counts.same = same;
    counts.worse = worse;
    return counts.SignTestP();
  };
  EXPECT_NEAR(p(11, 9, 5), 13770.0 / 65536, 1e-12);  // ties do not count
  EXPECT_NEAR(p(5, 0, 11), 13770.0 / 65536, 1e-12);  // either direction
  EXPECT_NEAR(p(10, 0, 0), 2.0 / 1024, 1e-15);
  EXPECT_DOUBLE_EQ(p(8, 0, 8), 1.0);                 // an even split, capped at 1
  EXPECT_DOUBLE_EQ(p(0, 7, 0), 1.0);                 // nothing moved
  EXPECT_NEAR(p(600, 0, 400), 2.7284641560660184e-10, 1e-13);  // long sweeps neither overflow nor round to 0
}

// Known answers for two evaluations set side by side. Runs pair by sequence and sweep point:
// a at D = 3 is the same (within 0.0005 mm), a at D = 5 better, b worse; paired by sequence
// alone, a's two runs would cross and count differently. d is lost in B and e failed in A, so
// neither counts; c and f are each in one evaluation only.
TEST(Results, DiffPairsTwoEvaluationsRunForRun) {
  const auto run = [](const std::string& sequence, const std::string& d, double rmse_mm, double ate_mm) {
    RunResult r = GridRun(sequence, "2", d, false, rmse_mm);
    r.ate_mm = ate_mm;
    return r;
  };
  RunResult failed = run("e", "3", 0, -1);
  failed.status = "failed";
  RunResult lost = run("d", "3", 0.1, 0.1);
  lost.status = "lost";
  const std::vector<RunResult> a = {run("a", "3", 1.0, 0.5), run("a", "5", 3.0, 1.5), run("b", "3", 2.0, 1.0),
                                    run("c", "3", 4.0, 2.0), run("d", "3", 1.0, 0.5),  failed};
  const std::vector<RunResult> b = {run("a", "5", 2.0, 1.0), run("a", "3", 1.0003, 0.4), run("b", "3", 2.5, 1.2),
                                    lost, run("e", "3", 1.0, 0.5), run("f", "3", 1.0, 0.5)};
  const ResultsDiff diff = DiffResults(a, b);
  ASSERT_EQ(diff.rows.size(), 7u);
  EXPECT_EQ(diff.rows.front().key, "a [k=2 D=3]");  // A's order first ...
  EXPECT_EQ(diff.rows.back().key, "f [k=2 D=3]");   // ... then what only B has
  EXPECT_EQ(diff.comparable, 3);
  EXPECT_DOUBLE_EQ(diff.mean_rmse_a_mm, 2.0);
  EXPECT_NEAR(diff.mean_rmse_b_mm, (1.0003 + 2.0 + 2.5) / 3, 1e-12);
  EXPECT_DOUBLE_EQ(diff.median_rmse_a_mm, 2.0);
  EXPECT_DOUBLE_EQ(diff.median_rmse_b_mm, 2.0);
  EXPECT_DOUBLE_EQ(diff.mean_ate_a_mm, 1.0);
  EXPECT_NEAR(diff.mean_ate_b_mm, 2.6 / 3, 1e-12);
  EXPECT_EQ(diff.b_against_a.better, 1);
  EXPECT_EQ(diff.b_against_a.same, 1);
  EXPECT_EQ(diff.b_against_a.worse, 1);
  EXPECT_EQ(diff.short_only_a, 1);
  EXPECT_EQ(diff.short_only_b, 1);
  EXPECT_EQ(diff.short_both, 0);
  EXPECT_EQ(diff.only_in_a, 1);
  EXPECT_EQ(diff.only_in_b, 1);
  std::stringstream table;
  PrintDiff(diff, "before", "after", table);
  EXPECT_NE(table.str().find("A: before (code: not recorded)\nB: after (code: not recorded)\n"
                             "Options: no run both have records them"),
            std::string::npos);
  EXPECT_NEAR(diff.b_against_a.GeometricMeanRatio(), std::cbrt(1.0003 * (2.0 / 3) * 1.25), 1e-12);
  for (const char* expected : {"1 / 1 / 1", "p = 1.000", "absent", "FAILED", "-1.000", "0.500",
                               "geometric mean over the runs: 0.941 (95 % CI 0.426 to 2.077)"}) {
    EXPECT_NE(table.str().find(expected), std::string::npos) << expected << "\n" << table.str();
  }
  // A run without a trajectory error leaves the mean ATE out rather than averaging a gap.
  std::vector<RunResult> no_ate = b;
  no_ate[2].ate_mm = -1;
  EXPECT_LT(DiffResults(a, no_ate).mean_ate_b_mm, 0);
}

// The diff says what else differed between the two evaluations' runs: options (from each
// run's config.json, whatever the evaluations were asked), and the sequence folder.
TEST(Results, DiffNamesTheOptionsThatDifferBetweenTheRuns) {
  const auto folder = UniqueTempFolder("diff_options");
  const auto run = [&](const std::string& name, const std::string& sequence, const Json& options) {
    RunResult r = Result(name.substr(2), 1.0, 60);
    r.run_folder = (folder / name).string();
    WriteFile(folder / name / "config.json", Json{{"sequence", sequence}, {"options", options}}.dump());
    return r;
  };
  Json stiff = SystemOptions{};
  stiff["deformation"]["k"] = 2.0;
  Json stiff_wide = stiff;
  stiff_wide["mapping"]["dba_window"] = 7;
  Json older = SystemOptions{};
  older["tracking"].erase("displacement_prior_sigma");  // written before the option existed
  const std::vector<RunResult> a = {run("a/s", "/seq/s", SystemOptions{}), run("a/t", "/seq/t", older),
                                    run("a/u", "/seq/u", SystemOptions{}), run("a/v", "/seq/v", SystemOptions{})};
  std::vector<RunResult> b = {run("b/s", "/seq/s", stiff), run("b/t", "/seq/t-other", stiff_wide),
                              run("b/u", "/seq/u", SystemOptions{}), run("b/v", "/seq/v", SystemOptions{})};
  WriteFile(folder / "b/v" / "config.json", "{ not json");
  const ResultsDiff diff = DiffResults(a, b);
  EXPECT_EQ(diff.option_changes, (std::map<std::string, int>{{"deformation.k: 1.1 → 2.0", 2},
                                                              {"mapping.dba_window: 5 → 7", 1}}));
  EXPECT_EQ(diff.other_sequence, 1);
  EXPECT_EQ(diff.configs_unread, 1);
  std::stringstream text;
  PrintDiff(diff, "A", "B", text);
  EXPECT_EQ(diff.configs_compared, 3);
  for (const char* expected : {"Options that differ over the 3 run(s) both have, A → B (runs):\n"
                               "  deformation.k: 1.1 → 2.0 (2)\n",
                               "1 run(s) of the same name ran on another sequence folder",
                               "1 run(s) with a config.json that could not be read"}) {
    EXPECT_NE(text.str().find(expected), std::string::npos) << expected << "\n" << text.str();
  }
  // Runs with the same options say so; a failed run has none to compare.
  b[1].status = "failed";
  const ResultsDiff same = DiffResults({a[2]}, {b[2]});
  EXPECT_TRUE(same.option_changes.empty());
  std::stringstream same_text;
  PrintDiff(same, "A", "B", same_text);
  EXPECT_NE(same_text.str().find("Options: the same in all 1 run(s) both have"), std::string::npos);
  EXPECT_EQ(DiffResults({a[1]}, {b[1]}).option_changes.size(), 0u);
  std::filesystem::remove_all(folder);
}

TEST(RigidComparison, MeansOverTheFramesBothRunsEvaluated) {
  const CommonFramesRmse common = MeanOverCommonFrames({{0, 0.0}, {1, 1.0}, {2, 2.0}, {3, 3.0}}, {{0, 0.0}, {1, 3.0}, {2, 1.0}});
  EXPECT_EQ(common.frames, 3);
  EXPECT_DOUBLE_EQ(common.a_mm, 1.0);
  EXPECT_DOUBLE_EQ(common.b_mm, 4.0 / 3.0);
  const CommonFramesRmse none = MeanOverCommonFrames({{5, 1.0}}, {{6, 1.0}});
  EXPECT_EQ(none.frames, 0);
  EXPECT_EQ(none.a_mm, 0.0);
}

// A finished run as CollectResults reads it, with the per-frame RMSEs its metrics.csv holds
// (frames without one are written empty, as the runner writes frames it did not track).
RunResult FinishedRun(const RunJob& run, const std::vector<double>& frame_rmse) {
  std::ostringstream metrics;
  metrics << "frame,state,rmse_mm,note\n";
  RunResult result;
  result.sequence = run.sequence;
  result.label = run.label;
  result.point = run.point;
  result.status = "ok";
  result.frames_total = static_cast<int>(frame_rmse.size());
  for (size_t i = 0; i < frame_rmse.size(); ++i) {
    const bool tracked = !std::isnan(frame_rmse[i]);
    metrics << i << ',' << (tracked ? "tracking" : "lost") << ',';
    if (tracked) {
      metrics << frame_rmse[i];
      result.rmse_mm += frame_rmse[i];
      ++result.frames_evaluated;
    }
    metrics << ",\"\"\n";
  }
  result.frames_tracked = result.frames_evaluated;
  result.rmse_mm /= std::max(1, result.frames_evaluated);
  WriteFile(run.run_folder / "metrics.csv", metrics.str());
  result.run_folder = run.run_folder.string();
  return result;
}

// Over a sweep the report plots how the rigid / deformable ratio moves with each numeric swept
// value (the question a sweep of the data asks); a single value or a flag has no such plot.
TEST(RigidComparison, TheReportPlotsTheRatioAgainstEachNumericSweptValue) {
  const auto folder = UniqueTempFolder("rigid_ratio_plot");
  const auto pair = [](const std::string& amplitude, const std::string& weighting, double deformable_mm,
                       double rigid_mm) {
    RigidComparison comparison;
    for (RunResult* run : {&comparison.deformable, &comparison.rigid}) {
      *run = Result(run == &comparison.rigid ? "s-rigid" : "s", run == &comparison.rigid ? rigid_mm : deformable_mm, 60);
      run->frames_evaluated = 60;
      run->point = {"simulate.deformation.amplitude_mm=" + amplitude, "deformation.weighting=" + weighting};
      run->label = "amplitude_mm=" + amplitude + ",weighting=" + weighting;
    }
    return comparison;
  };
  const std::vector<RigidComparison> comparisons = {pair("0", "paper", 1.0, 0.5), pair("5", "paper", 2.0, 4.0)};
  std::vector<RunResult> results;
  for (const RigidComparison& comparison : comparisons) results.insert(results.end(), {comparison.deformable, comparison.rigid});
  const auto page = [&](const std::vector<RigidComparison>& shown) {
    WriteReport(results, shown, {}, folder / "report");
    return FileText(folder / "report" / "index.html");
  };
  const std::string html = page(comparisons);
  EXPECT_NE(html.find("Rigid / deformable RMSE against amplitude_mm"), std::string::npos);
  EXPECT_EQ(html.find("Rigid / deformable RMSE against weighting"), std::string::npos);  // not a number
  EXPECT_EQ(page({comparisons[0]}).find("Rigid / deformable RMSE against"), std::string::npos);  // one value
  std::filesystem::remove_all(folder);
}

TEST(RigidComparison, PairsRunsThatDifferOnlyInRigidity) {
  const auto folder = UniqueTempFolder("rigid_pairs");
  const Manifest manifest = LoadManifest(WriteFile(folder / "m.json", R"({"sequences": [
      {"name": "a", "preset": "sim-1"},
      {"name": "b", "preset": "sim-2"},
      {"name": "a-rigid", "preset": "sim-1", "rigid": true},
      {"name": "c", "preset": "sim-3", "set": {"k": 2}},
      {"name": "c-rigid", "preset": "sim-3", "rigid": true},
      {"name": "d-rigid", "preset": "sim-4", "rigid": true}
    ]})"));
  const EvaluationPlan plan = PlanEvaluation(manifest, {}, {}, folder / "out", folder / "cache");
  const double lost = std::nan("");
  const std::vector<RunResult> results = {
      FinishedRun(plan.runs[0], {0.0, 1.0, 2.0, 3.0}), FinishedRun(plan.runs[1], {0.0, 1.0, 1.0, 1.0}),
      FinishedRun(plan.runs[2], {0.0, 0.5, lost, lost}), FinishedRun(plan.runs[3], {0.0, 2.0, 2.0, 2.0}),
      FinishedRun(plan.runs[4], {0.0, 1.0, 1.0, 1.0}), FinishedRun(plan.runs[5], {0.0, 1.0, 1.0, 1.0})};
  const std::vector<RigidComparison> comparisons = CompareWithRigid(plan, results);
  ASSERT_EQ(comparisons.size(), 1u);  // b and d have no partner, c's options differ in k
  EXPECT_EQ(comparisons[0].deformable.sequence, "a");
  EXPECT_EQ(comparisons[0].rigid.sequence, "a-rigid");
  EXPECT_EQ(comparisons[0].common.frames, 2);
  EXPECT_DOUBLE_EQ(comparisons[0].common.a_mm, 0.5);
  EXPECT_DOUBLE_EQ(comparisons[0].common.b_mm, 0.25);
  // Own RMSEs 1.5 and 0.25 (ratio 0.17); over the common frames 0.5 and 0.25 (0.50).
  const std::vector<std::string> cells = RigidComparisonCells(comparisons[0]);
  ASSERT_EQ(cells.size(), RigidComparisonHeader().size());
  EXPECT_EQ(cells[4], "0.17");
  EXPECT_EQ(cells[5], "4 / 2");
  EXPECT_EQ(cells[9], "0.50");
  EXPECT_EQ(cells[14], "-");  // no points.csv in these run folders: no common points
  std::stringstream table;
  PrintRigidComparison(comparisons, table);
  EXPECT_NE(table.str().find("a-rigid"), std::string::npos) << table.str();
  table.str("");
  PrintRigidComparison({}, table);
  EXPECT_TRUE(table.str().empty());

  // A sweep of the rigid flag itself pairs each point with its rigid twin.
  const Manifest one = LoadManifest(WriteFile(folder / "one.json", R"({"sequences": [{"name": "s", "preset": "sim-1"}]})"));
  const EvaluationPlan swept =
      PlanEvaluation(one, {}, {ParseSweep("tracking.rigid=false,true")}, folder / "swept", folder / "cache");
  ASSERT_EQ(swept.runs.size(), 2u);
  const std::vector<RigidComparison> twins = CompareWithRigid(
      swept, {FinishedRun(swept.runs[0], {0.0, 1.0}), FinishedRun(swept.runs[1], {0.0, 2.0})});
  ASSERT_EQ(twins.size(), 1u);
  EXPECT_EQ(RunKey(twins[0].deformable), "s [rigid=false]");
  EXPECT_EQ(RunKey(twins[0].rigid), "s [rigid=true]");
  EXPECT_EQ(RigidComparisonCells(twins[0])[9], "2.00");

  // Tallied: "a" is worse than its rigid run by its own RMSE (1.5 against 0.25) and over the
  // common frames (0.5 against 0.25); the twin "s", counted twice, is better both ways (0.5
  // against 1.0). Neither has points.csv, so the same-points count is empty.
  const std::vector<RigidComparison> three = {comparisons[0], twins[0], twins[0]};
  const RigidComparisonTally tally = TallyRigidComparisons(three);
  EXPECT_EQ(tally.own.ToString(), "2 / 0 / 1");
  EXPECT_EQ(tally.common.ToString(), "2 / 0 / 1");
  EXPECT_EQ(tally.same_points.ToString(), "0 / 0 / 0");
  table.str("");
  PrintRigidComparison(three, table);
  // Own: ratios rigid / deformable 1/6, 2, 2, geometric mean 1.5^(-1/3) = 0.874, its interval
  // the reciprocal of the deformable / rigid one (Student's t at 2 degrees of freedom); |log
  // ratio| ranks 1.5, 1.5, 3 with the worse run's 3, as likely as not under the null: p = 1.
  EXPECT_NE(table.str().find("own RMSE 2 / 0 / 1 (sign test p = 1.000; ratio, geometric mean 0.874 (95 % CI 0.025 "
                             "to 30.838), signed-rank p = 1.000); common frames 2 / 0 / 1 (sign test p = 1.000; "
                             "ratio, geometric mean 1.260"),
            std::string::npos)
      << table.str();
  std::filesystem::remove_all(folder);
}

// The seed groups of a plan whose runs all finished, each with an RMSE of 1 mm.
std::vector<SeedGroup> GroupsOfFinishedRuns(const EvaluationPlan& plan) {
  std::vector<RunResult> results;
  for (const RunJob& run : plan.runs) results.push_back(FinishedRun(run, {1.0}));
  return GroupBySeed(plan, results);
}

TEST(SeedGroups, SummariseRunsThatDifferOnlyInTheSeed) {
  const auto folder = UniqueTempFolder("seed_groups");
  const Manifest manifest = LoadManifest(WriteFile(folder / "m.json", R"({"sequences": [
      {"name": "a1", "preset": "sim-3", "simulate": {"seed": 1}},
      {"name": "a2", "preset": "sim-3", "simulate": {"seed": 2}},
      {"name": "a3", "preset": "sim-3", "simulate": {"seed": 3}},
      {"name": "a4", "preset": "sim-3", "simulate": {"seed": 4}},
      {"name": "a1-rigid", "preset": "sim-3", "simulate": {"seed": 1}, "rigid": true},
      {"name": "a2-rigid", "preset": "sim-3", "simulate": {"seed": 2}, "rigid": true},
      {"name": "small1", "preset": "sim-3", "simulate": {"seed": 1, "camera.width": 320}},
      {"name": "small2", "preset": "sim-3", "simulate": {"seed": 2, "camera.width": 320}},
      {"name": "k2", "preset": "sim-3", "simulate": {"seed": 3}, "set": {"k": 2}},
      {"name": "alone", "preset": "sim-4", "simulate": {"seed": 1}}
    ]})"));
  const EvaluationPlan plan = PlanEvaluation(manifest, {}, {}, folder / "out", folder / "cache");
  ASSERT_EQ(plan.runs.size(), 10u);
  std::vector<RunResult> results;
  const std::vector<std::vector<double>> frames = {{1.0, 3.0}, {4.0, 4.0}, {9.0, 9.0}, {7.0, 7.0}, {1.0, 1.0},
                                                   {1.0, 1.0}, {0.5, 0.5}, {0.7, 0.7}, {5.0, 5.0}, {6.0, 6.0}};
  for (size_t i = 0; i < plan.runs.size(); ++i) {
    results.push_back(FinishedRun(plan.runs[i], frames[i]));
    results.back().ate_mm = 0.1 * static_cast<double>(i + 1);
    results.back().rmse_map_scale_mm = results.back().rmse_mm + 1.0;
  }
  results[2].status = "lost";    // a3 lost the track: scored on its own frames, not "to end"
  results[3].status = "failed";  // a4 failed: not scored
  results[7].ate_mm = -1;        // small2 without a trajectory error

  const std::vector<SeedGroup> groups = GroupBySeed(plan, results);
  // k2 differs from a3 in an option and "alone" has no other seed: neither forms a group.
  ASSERT_EQ(groups.size(), 3u);
  EXPECT_EQ(groups[0].name, "sim-3");
  EXPECT_EQ(groups[0].sequences, (std::vector<std::string>{"a1", "a2", "a3", "a4"}));
  EXPECT_EQ(groups[0].seeds, (std::vector<std::string>{"1", "2", "3", "4"}));
  EXPECT_EQ(groups[0].scored, 3);
  EXPECT_EQ(groups[0].to_end, 2);
  EXPECT_DOUBLE_EQ(groups[0].mean_rmse_mm, 5.0);            // 2, 4 and 9
  EXPECT_DOUBLE_EQ(groups[0].sd_rmse_mm, std::sqrt(13.0));  // sample sd of {2, 4, 9}
  EXPECT_DOUBLE_EQ(groups[0].median_rmse_mm, 4.0);
  EXPECT_DOUBLE_EQ(groups[0].min_rmse_mm, 2.0);
  EXPECT_DOUBLE_EQ(groups[0].max_rmse_mm, 9.0);
  EXPECT_NEAR(groups[0].mean_ate_mm, 0.2, 1e-12);           // 0.1, 0.2 and 0.3
  EXPECT_DOUBLE_EQ(groups[0].mean_map_scale_mm, 6.0);        // 3, 5 and 10
  EXPECT_EQ(groups[1].name, "sim-3 rigid");
  EXPECT_EQ(groups[1].sequences, (std::vector<std::string>{"a1-rigid", "a2-rigid"}));
  EXPECT_DOUBLE_EQ(groups[1].sd_rmse_mm, 0.0);
  EXPECT_EQ(groups[2].name, "sim-3 camera.width=320");
  EXPECT_DOUBLE_EQ(groups[2].mean_rmse_mm, 0.6);
  EXPECT_LT(groups[2].mean_ate_mm, 0.0);  // one scored member has none

  const std::vector<std::string> cells = SeedGroupCells(groups[0]);
  ASSERT_EQ(cells.size(), SeedGroupHeader().size());
  EXPECT_EQ(cells[1], "1 2 3 4");
  EXPECT_EQ(cells[2], "3/4");
  EXPECT_EQ(cells[3], "2");
  EXPECT_EQ(cells[4], "5.000");
  EXPECT_EQ(cells[5], "3.606");
  EXPECT_EQ(cells[9], "6.000");
  EXPECT_EQ(SeedGroupCells(groups[2])[10], "-");
  std::stringstream table;
  PrintSeedGroups(groups, table);
  EXPECT_NE(table.str().find("sim-3 rigid"), std::string::npos) << table.str();
  table.str("");
  PrintSeedGroups({}, table);
  EXPECT_TRUE(table.str().empty());
  WriteSeedGroups(groups, folder / "seed_groups.csv");
  const auto rows = ReadCsv(folder / "seed_groups.csv");
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].at("sequences"), "a1 a2 a3 a4");
  EXPECT_NEAR(Number(rows[0], "sd_rmse_mm"), std::sqrt(13.0), 1e-5);  // six significant digits, as every CSV
  EXPECT_TRUE(std::isnan(Number(rows[2], "mean_ate_mm")));
  EXPECT_NEAR(Number(rows[0], "mean_map_scale_mm"), 6.0, 1e-9);

  // A sweep keeps its points apart: one group per value. Sweeping the rigid flag names it once.
  const std::vector<SeedGroup> per_value =
      GroupsOfFinishedRuns(PlanEvaluation(manifest, {}, {ParseSweep("k=0.5,2")}, folder / "swept", folder / "cache"));
  // Three groups per value: the sweep sets k after k2's own, so k2 joins a1 … a4 at both.
  ASSERT_EQ(per_value.size(), 6u);
  EXPECT_EQ(per_value[0].name, "sim-3 [k=0.5]");
  EXPECT_EQ(per_value[1].name, "sim-3 [k=2]");
  EXPECT_EQ(per_value[1].sequences, (std::vector<std::string>{"a1", "a2", "a3", "a4", "k2"}));
  const std::vector<SeedGroup> per_mode = GroupsOfFinishedRuns(
      PlanEvaluation(manifest, {}, {ParseSweep("tracking.rigid=false,true")}, folder / "rigidity", folder / "cache"));
  ASSERT_GE(per_mode.size(), 2u);
  EXPECT_EQ(per_mode[1].name, "sim-3 [rigid=true]");
  // A swept simulator option is named by the label alone, not again among the render's options.
  const std::vector<SeedGroup> per_amplitude = GroupsOfFinishedRuns(PlanEvaluation(
      manifest, {}, {ParseSweep("simulate.amplitude_mm=0,10")}, folder / "amplitude", folder / "cache"));
  ASSERT_GE(per_amplitude.size(), 2u);
  EXPECT_EQ(per_amplitude[0].name, "sim-3 [amplitude_mm=0]");
  EXPECT_EQ(per_amplitude[0].sequences, (std::vector<std::string>{"a1", "a2", "a3", "a4"}));
  EXPECT_EQ(per_amplitude[1].name, "sim-3 [amplitude_mm=10]");

  // Two groups that differ in a manifest option of their own are told apart by name.
  const Manifest two = LoadManifest(WriteFile(folder / "two.json", R"({"sequences": [
      {"name": "p1", "preset": "sim-3", "simulate": {"seed": 1}},
      {"name": "p2", "preset": "sim-3", "simulate": {"seed": 2}},
      {"name": "q1", "preset": "sim-3", "simulate": {"seed": 1}, "set": {"k": 2}},
      {"name": "q2", "preset": "sim-3", "simulate": {"seed": 2}, "set": {"k": 2}}
    ]})"));
  const std::vector<SeedGroup> named = GroupsOfFinishedRuns(PlanEvaluation(two, {}, {}, folder / "two", folder / "cache"));
  ASSERT_EQ(named.size(), 2u);
  EXPECT_EQ(named[0].name, "sim-3 (p1, ...)");
  EXPECT_EQ(named[1].name, "sim-3 (q1, ...)");
}

TEST(BatchEvaluation, ABrokenSequenceIsReportedAndTheOthersStillRun) {
  const auto folder = UniqueTempFolder("batch_broken");
  // A sequence folder with an incomplete sequence.json, between two good simulated ones (eight
  // frames: the map comes from depth).
  WriteFile(folder / "broken" / "sequence.json", R"({"format": "nrslam-sequence"})");
  const Manifest manifest = LoadManifest(WriteFile(folder / "m.json", std::string(R"({
    "defaults": {"init": "depth", "simulate": )") + kTinySimulate + R"(},
    "sequences": [
      {"name": "good", "preset": "sim-1"},
      {"name": "broken", "path": "broken"},
      {"name": "good-rigid", "preset": "sim-1", "rigid": true}
    ]})"));
  const EvaluationPlan plan = PlanEvaluation(manifest, {}, {}, folder / "out", folder / "cache");
  std::vector<std::string> lines;
  ExecutePlan(plan, kPrograms, 2, [&](const std::string& line) { lines.push_back(line); });
  const std::vector<RunResult> results = CollectResults(plan);
  ASSERT_EQ(results.size(), 3u);
  EXPECT_EQ(results[0].status, "ok") << results[0].error;
  EXPECT_EQ(results[0].frames_tracked, 8);
  EXPECT_GT(results[0].rmse_mm, 0.0);
  EXPECT_EQ(results[1].status, "failed");
  EXPECT_NE(results[1].error.find("exit code 1"), std::string::npos) << results[1].error;
  EXPECT_NE(results[1].error.find("missing field 'camera'"), std::string::npos) << results[1].error;  // the reader's message
  EXPECT_NE(results[2].status, "failed") << results[2].error;
  std::stringstream table;
  PrintResults(results, table);
  EXPECT_NE(table.str().find("FAILED broken:"), std::string::npos) << table.str();
  WriteResults(results, folder / "out");
  const std::vector<RunResult> read = ReadResults(folder / "out");
  ASSERT_EQ(read.size(), 3u);
  EXPECT_EQ(read[1].error, results[1].error);
  EXPECT_DOUBLE_EQ(read[0].rmse_mm, results[0].rmse_mm);
  // Each run names the code that made it; the broken one never wrote a config.
  EXPECT_EQ(read[0].revision, SourceRevision());
  EXPECT_EQ(read[0].code, CodeFingerprint());
  EXPECT_EQ(read[1].revision, "");
  EXPECT_EQ(DescribeRevisions(read), SourceRevision());  // the failed run made no results to name code for
  std::vector<RunResult> older = read;
  older[2].revision.clear();
  EXPECT_EQ(DescribeRevisions(older), std::string(SourceRevision()) + ", not recorded");
  EXPECT_GT(results[0].rmse_flat_mm, 0.0);
  EXPECT_DOUBLE_EQ(read[0].rmse_flat_mm, results[0].rmse_flat_mm);
  EXPECT_LT(read[1].rmse_flat_mm, 0.0);  // failed: none recorded
  EXPECT_GT(results[0].rmse_map_scale_mm, 0.0);
  EXPECT_DOUBLE_EQ(read[0].rmse_map_scale_mm, results[0].rmse_map_scale_mm);
  EXPECT_DOUBLE_EQ(read[0].rmse_median_scale_mm, results[0].rmse_median_scale_mm);
  EXPECT_LT(read[1].rmse_map_scale_mm, 0.0);
  EXPECT_NE(table.str().find("1 scale mm"), std::string::npos) << table.str();

  // The rigid run is the good run's baseline; the broken one has none.
  const std::vector<RigidComparison> comparisons = CompareWithRigid(plan, results);
  ASSERT_EQ(comparisons.size(), 1u);
  EXPECT_EQ(comparisons[0].deformable.sequence, "good");
  EXPECT_EQ(comparisons[0].rigid.sequence, "good-rigid");
  EXPECT_EQ(comparisons[0].common.frames, std::min(results[0].frames_evaluated, results[2].frames_evaluated));
  if (results[2].frames_evaluated == results[0].frames_evaluated) {  // the same frames: the runs' own means
    EXPECT_NEAR(comparisons[0].common.a_mm, results[0].rmse_mm, 1e-6);
    EXPECT_NEAR(comparisons[0].common.b_mm, results[2].rmse_mm, 1e-6);
  }
  // One map from depth: every point both report is the same track.
  const CommonPointsComparison& same = comparisons[0].same_points;
  EXPECT_EQ(same.frames, comparisons[0].common.frames);
  EXPECT_EQ(same.mismatched_ids, 0);
  EXPECT_GT(same.mean_common_points, 8.0);
  EXPECT_LE(same.mean_common_points, std::min(same.mean_points_a, same.mean_points_b));

  // nrslam_preview draws a frame of both runs, one view under the other, each colour | depth
  // under a caption; a folder that is no run is refused.
  {
    const std::string preview = NRSLAM_TOOLS_DIR "/nrslam_preview";
    const std::filesystem::path picture = folder / "views.png";
    const std::string both = preview + " --run " + results[0].run_folder + " --run " + results[2].run_folder +
                             " --frame 3 --out " + picture.string() + " > /dev/null 2>&1";
    ASSERT_EQ(std::system(both.c_str()), 0) << both;
    const cv::Mat views = cv::imread(picture.string());
    const cv::Mat frame = cv::imread((plan.runs[0].sequence_folder / "rgb" / "000003.png").string());
    ASSERT_FALSE(frame.empty());
    EXPECT_EQ(views.cols, 2 * frame.cols);
    EXPECT_GT(views.rows, 2 * frame.rows);
    const std::string with_broken = preview + " --run " + results[0].run_folder + " --run " +
                                    (folder / "broken").string() + " --out " + picture.string() + " > /dev/null 2>&1";
    EXPECT_NE(std::system(with_broken.c_str()), 0);
    // Every frame as a video: as many frames as the sequence has, each the size of the view.
    const std::filesystem::path video = folder / "views.avi";
    const std::string all = preview + " --run " + results[0].run_folder + " --run " + results[2].run_folder +
                            " --all --out " + video.string() + " > /dev/null 2>&1";
    ASSERT_EQ(std::system(all.c_str()), 0) << all;
    cv::VideoCapture capture(video.string());
    ASSERT_TRUE(capture.isOpened());
    int frames = 0;
    for (cv::Mat image; capture.read(image); ++frames) EXPECT_EQ(image.size(), views.size());
    EXPECT_EQ(frames, 8);
  }

  // The report opens in a real (headless) browser: every image loads, the plots are drawn,
  // and the failed sequence is shown as such.
  WriteReport(results, comparisons, GroupBySeed(plan, results), folder / "out" / "report");
  {
    const std::string html = FileText(folder / "out" / "report" / "index.html");
    EXPECT_NE(html.find("<p>Code: " + DescribeRevisions(results) + "</p>"), std::string::npos);
  }
  if (std::system("chromium --version > /dev/null 2>&1") != 0) GTEST_SKIP() << "chromium is not installed";
  const std::string dom = (folder / "dom.html").string(), log = (folder / "browser.log").string();
  ASSERT_EQ(std::system(("timeout 120 chromium --headless --no-sandbox --disable-gpu --virtual-time-budget=5000 "
                         "--enable-logging=stderr --dump-dom file://" +
                         (folder / "out" / "report" / "index.html").string() + " > " + dom + " 2> " + log)
                            .c_str()),
            0);
  const std::string page = FileText(dom);
  const std::string browser = FileText(log);
  // Two tracked runs: each an RMSE plot (the run and the flat map), a drift plot (scale and
  // median depth), a trajectory plot (two series) and three images.
  EXPECT_NE(page.find("data-check=\"images=6 broken=0 plots=6 series=12\""), std::string::npos)
      << page.substr(0, 2000);
  EXPECT_NE(page.find("Failed: exit code 1"), std::string::npos);
  EXPECT_NE(page.find("<h2>Deformable against rigid</h2>"), std::string::npos);
  EXPECT_EQ(browser.find("Uncaught"), std::string::npos) << browser;
  std::filesystem::remove_all(folder);
}

// Another system's output on a sequence of the manifest is scored, not run, and sits in the
// same table: here a run's own output given back as if it came from elsewhere.
TEST(BatchEvaluation, AnExternalResultIsScoredBesideTheRuns) {
  const auto folder = UniqueTempFolder("batch_external");
  const Manifest ours = LoadManifest(WriteFile(folder / "ours.json", std::string(R"({
    "defaults": {"init": "depth", "simulate": )") + kTinySimulate + R"(},
    "sequences": [{"name": "s", "preset": "sim-1"}]})"));
  const EvaluationPlan first = PlanEvaluation(ours, {}, {}, folder / "ours", folder / "cache");
  ExecutePlan(first, kPrograms, 2, [](const std::string&) {});
  const RunResult own = CollectResults(first)[0];
  ASSERT_EQ(own.status, "ok") << own.error;
  const std::string run = (folder / "ours" / "runs" / "s").string();
  WriteFile(folder / "nothing.csv", "frame,u,v,z\n");  // a system that estimated nothing
  const Manifest both = LoadManifest(WriteFile(folder / "both.json", std::string(R"({
    "defaults": {"init": "depth", "set": {"k": 2}, "simulate": )") + kTinySimulate + R"(},
    "sequences": [
      {"name": "s", "preset": "sim-1"},
      {"name": "s-elsewhere", "preset": "sim-1",
       "external": {"estimates": ")" + run + R"(/points.csv", "trajectory": ")" + run +
                                                   R"(/trajectory.tum", "name": "ours, again"}},
      {"name": "s-nothing", "preset": "sim-1", "external": {"estimates": "nothing.csv"}}
    ]})"));
  // The defaults' run settings do not apply to it, and a sweep scores it once.
  const EvaluationPlan plan = PlanEvaluation(both, {}, {ParseSweep("k=1,2")}, folder / "out", folder / "cache");
  ASSERT_EQ(plan.runs.size(), 4u);
  const RunJob& external = plan.runs[2];
  EXPECT_TRUE(external.label.empty());
  EXPECT_EQ(external.prepare, plan.runs[0].prepare);  // the same rendered sequence
  const std::string line = RunShellLine(plan, external, kPrograms);
  EXPECT_NE(line.find("nrslam_eval score "), std::string::npos) << line;
  ExecutePlan(plan, kPrograms, 2, [](const std::string&) {});
  const std::vector<RunResult> results = CollectResults(plan);
  ASSERT_EQ(results.size(), 4u);
  EXPECT_EQ(results[2].status, "ok") << results[2].error;
  EXPECT_EQ(results[3].status, "not_initialised") << results[3].error;
  EXPECT_EQ(results[2].frames_tracked, own.frames_tracked);
  EXPECT_NEAR(results[2].rmse_mm, own.rmse_mm, 1e-5);
  EXPECT_NEAR(results[2].ate_mm, own.ate_mm, 1e-4);
  EXPECT_EQ(results[2].fps, 0.0);
  // Our runs record their process's peak memory; another system's output has none of ours.
  EXPECT_GT(results[0].peak_memory_mb, 10.0);
  EXPECT_LT(results[2].peak_memory_mb, 0.0);
  std::stringstream table;
  PrintResults(results, table);
  EXPECT_NE(table.str().find("s-elsewhere"), std::string::npos) << table.str();
  EXPECT_TRUE(CompareWithRigid(plan, results).empty());
  std::vector<std::string> lines;
  ExecutePlan(plan, kPrograms, 2, [&](const std::string& text) { lines.push_back(text); });
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines[0], "4 run(s) already finished, not run again");
  // The same path exported again is new output, scored again rather than reported stale.
  std::ofstream(folder / "nothing.csv", std::ios::app) << "0,100,80,3.5\n";
  const EvaluationPlan again = PlanEvaluation(both, {}, {ParseSweep("k=1,2")}, folder / "out", folder / "cache");
  lines.clear();
  ExecutePlan(again, kPrograms, 2, [&](const std::string& text) { lines.push_back(text); });
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines[0], "3 run(s) already finished, not run again");
  EXPECT_EQ(CollectResults(again)[3].status, "lost");  // frame 0 only, then nothing
  // Run settings on it are refused, and so are estimates that are not there.
  EXPECT_NE(ErrorOf(WriteFile(folder / "rigid.json", R"({"sequences": [{"name": "x", "preset": "sim-1",
              "rigid": true, "external": {"estimates": "points.csv"}}]})"))
                .find("\"rigid\" configures an NR-SLAM run"),
            std::string::npos);
  EXPECT_NE(ErrorOf(WriteFile(folder / "missing.json", R"({"sequences": [{"name": "x", "preset": "sim-1",
              "external": {"estimates": "nowhere.csv"}}]})"))
                .find("nowhere.csv does not exist"),
            std::string::npos);
  std::filesystem::remove_all(folder);
}

// A Hamlyn-layout copy of a short simulated sequence (left images, 16-bit depth in mm,
// intrinsics.txt), as a user would have the real dataset on disk.
void WriteHamlynLayout(const std::filesystem::path& folder, int frames) {
  SimOptions sim = SimPreset("sim-1");
  sim.camera.width = 320;
  sim.camera.height = 240;
  Renderer renderer(sim);
  std::filesystem::create_directories(folder / "image01");
  std::filesystem::create_directories(folder / "depth01");
  for (int i = 0; i < frames; ++i) {
    const RenderedFrame frame = renderer.Render(i);
    char name[32];
    std::snprintf(name, sizeof name, "%010d.png", i);
    cv::imwrite((folder / "image01" / name).string(), frame.left.bgr);
    cv::Mat depth;
    frame.left.depth_mm.convertTo(depth, CV_16U);  // whole mm, as the dataset stores it
    cv::imwrite((folder / "depth01" / name).string(), depth);
  }
  const Camera& camera = renderer.camera();
  std::ofstream(folder / "intrinsics.txt") << camera.fx() << " 0 " << camera.cx() << "\n0 " << camera.fy() << " "
                                           << camera.cy() << "\n0 0 1\n";
}

TEST(BatchEvaluation, ImportedDatasetsRunAndAMissingOneIsReported) {
  const auto folder = UniqueTempFolder("batch_import");
  WriteHamlynLayout(folder / "hamlyn" / "rectified01", 8);
  // Eight frames: too short for a monocular map, so the map comes from the dataset's depth.
  const Manifest manifest = LoadManifest(WriteFile(folder / "m.json", R"({
    "defaults": {"init": "depth"},
    "sequences": [
      {"name": "h01", "import": {"format": "hamlyn", "path": "hamlyn/rectified01"}},
      {"name": "h02", "import": {"format": "hamlyn", "path": "hamlyn/rectified02"}}
    ]})"));
  const EvaluationPlan plan = PlanEvaluation(manifest, {}, {}, folder / "out", folder / "cache");
  ASSERT_EQ(plan.prepares.size(), 2u);
  ExecutePlan(plan, kPrograms, 2, [](const std::string&) {});
  const std::vector<RunResult> results = CollectResults(plan);
  EXPECT_EQ(results[0].status, "ok") << results[0].error;
  EXPECT_EQ(results[0].frames_tracked, 8);
  EXPECT_GT(results[0].rmse_mm, 0.0);
  EXPECT_LT(results[0].rmse_mm, 2.0);  // whole-mm ground truth: a sane, not a tight, bound
  EXPECT_EQ(results[1].status, "failed");
  EXPECT_NE(results[1].error.find("importing hamlyn"), std::string::npos) << results[1].error;
  EXPECT_NE(results[1].error.find("rectified02 does not exist"), std::string::npos) << results[1].error;
  std::filesystem::remove_all(folder);
}

// A runner that crashes (here: a stand-in that kills itself with SIGSEGV) or cannot be
// started is a recorded failure of that run, with the reason; the batch finishes.
// A script standing in for nrslam_run in `folder`, and a plan of `runs` runs for it to fail.
// An executable shell script.
std::filesystem::path WriteScript(const std::filesystem::path& file, const std::string& body) {
  const std::filesystem::path script = WriteFile(file, "#!/bin/sh\n" + body);
  std::filesystem::permissions(script, std::filesystem::perms::owner_all);
  return script;
}

std::filesystem::path StandInRunner(const std::filesystem::path& folder, const std::string& script, int runs,
                                    EvaluationPlan* plan) {
  const std::filesystem::path runner = WriteScript(folder / "runner.sh", script);
  WriteFile(folder / "seq" / "sequence.json", "{}");
  std::string sequences;
  for (int i = 0; i < runs; ++i) sequences += std::string(i ? "," : "") + R"({"name": "r)" + std::to_string(i) + R"(", "path": "seq"})";
  const Manifest manifest = LoadManifest(WriteFile(folder / "m.json", R"({"sequences": [)" + sequences + "]}"));
  *plan = PlanEvaluation(manifest, {}, {}, folder / "out", folder / "cache");
  return runner;
}

// A baseline that could not serve a check is refused when it is read, saying why; nrslam_eval
// reads it (and checks where a new one would go) before it runs anything.
TEST(Baseline, AFileThatCannotServeACheckIsRefusedBeforeAnyRun) {
  const auto folder = UniqueTempFolder("baseline_refused");
  std::filesystem::create_directories(folder);
  const Json good = MakeBaseline({Result("a", 1.0, 60)}, BaselineTolerance{});
  std::ofstream(folder / "good.json") << good.dump();
  EXPECT_EQ(ReadBaseline(folder / "good.json"), good);
  const auto refusal = [&](const std::string& text) {
    std::ofstream(folder / "bad.json") << text;
    try {
      ReadBaseline(folder / "bad.json");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(refusal("{").find("is not valid JSON"), std::string::npos);
  EXPECT_NE(refusal(R"({"runs": {}})").find("needs \"tolerance\" and \"runs\""), std::string::npos);
  Json no_rmse = good;
  no_rmse["runs"]["a"].erase("rmse_mm");
  EXPECT_NE(refusal(no_rmse.dump()).find("run 'a' needs \"rmse_mm\" and \"frames_tracked\" numbers"),
            std::string::npos);
  EXPECT_THROW(ReadBaseline(folder / "missing.json"), Error);

  const std::filesystem::path manifest =
      WriteFile(folder / "m.json", R"({"sequences": [{"name": "a", "preset": "sim-0"}]})");
  const std::string eval = kPrograms.eval.string() + " " + manifest.string() + " --out " + (folder / "out").string() +
                           " --cache " + (folder / "cache").string();
  const auto [missing, missing_log] = RunCaught(eval + " --check-baseline " + (folder / "missing.json").string(),
                                                folder / "log.txt");
  EXPECT_EQ(WEXITSTATUS(missing), 1);
  EXPECT_NE(missing_log.find("cannot open " + (folder / "missing.json").string()), std::string::npos) << missing_log;
  const auto [nowhere, nowhere_log] =
      RunCaught(eval + " --write-baseline " + (folder / "no-such-folder" / "b.json").string(), folder / "log.txt");
  EXPECT_EQ(WEXITSTATUS(nowhere), 1);
  EXPECT_NE(nowhere_log.find("--write-baseline: the folder"), std::string::npos) << nowhere_log;
  EXPECT_FALSE(std::filesystem::exists(folder / "cache"));  // nothing rendered
  EXPECT_FALSE(std::filesystem::exists(folder / "out"));
  std::filesystem::remove_all(folder);
}

// Out-of-range arguments are refused with a message naming them, not replaced by a default or
// wrapped around: each command exits non-zero, writes nothing, and says what was wrong.
TEST(Tools, OutOfRangeArgumentsAreRefused) {
  const auto folder = UniqueTempFolder("tool_arguments");
  std::filesystem::create_directories(folder);
  const auto refused = [&](const std::string& command, const std::string& message) {
    const auto [status, output] = RunCaught(command, folder / "log.txt");
    EXPECT_NE(status, 0) << command;
    EXPECT_NE(output.find(message), std::string::npos) << command << "\n" << output;
  };
  const std::string simulate = kPrograms.simulate.string() + " --preset sim-0 --quiet --out " + (folder / "seq").string();
  refused(simulate + " --frames 0", "frames must be in [1, 100000]");
  refused(simulate + " --frames -3", "frames must be in [1, 100000]");
  refused(simulate + " --width 0", "image size must be");
  refused(simulate + " --seed -1", "--seed must be >= 0, got -1");
  EXPECT_FALSE(std::filesystem::exists(folder / "seq"));
  const std::filesystem::path manifest =
      WriteFile(folder / "m.json", R"({"sequences": [{"name": "a", "preset": "sim-0"}]})");
  const std::string eval = kPrograms.eval.string() + " " + manifest.string() + " --out " + (folder / "out").string();
  refused(eval + " --jobs 0", "--jobs: Value 0 not in range 1 to 256");
  refused(eval + " --sweep deformation.k=1,inf", "cannot use 'inf' (expected a finite number");
  EXPECT_FALSE(std::filesystem::exists(folder / "out" / "results.json"));
  std::filesystem::remove_all(folder);
}

// `nrslam_run --print-options` needs no sequence: it prints every option as resolved (here
// after a --set) and exits 0. Without it, the sequence and the run folder are both required.
TEST(Tools, RunPrintsItsOptionsWithoutASequence) {
  const auto folder = UniqueTempFolder("tool_print_options");
  std::filesystem::create_directories(folder);
  const std::string run = kPrograms.run.string();
  const auto [status, output] = RunCaught(run + " --print-options --set deformation.k=2.5", folder / "options.json");
  ASSERT_EQ(status, 0) << output;
  const nlohmann::json options = nlohmann::json::parse(output);
  EXPECT_DOUBLE_EQ(options.at("deformation").at("k").get<double>(), 2.5);
  EXPECT_EQ(options.at("tracking").at("max_points").get<int>(), SystemOptions{}.tracking.max_points);
  const auto [no_sequence, no_sequence_output] = RunCaught(run, folder / "log.txt");
  EXPECT_NE(no_sequence, 0);
  EXPECT_NE(no_sequence_output.find("a sequence folder is required"), std::string::npos) << no_sequence_output;
  const auto [no_out, no_out_output] = RunCaught(run + " " + (folder / "seq").string(), folder / "log.txt");
  EXPECT_NE(no_out, 0);
  EXPECT_NE(no_out_output.find("--out is required"), std::string::npos) << no_out_output;
  std::filesystem::remove_all(folder);
}

// Into a log file (as under Slurm or GNU parallel) progress comes as whole lines, not as
// carriage returns that pile a run's every update onto one line.
TEST(Tools, ProgressIntoALogFileIsWholeLines) {
  const auto folder = UniqueTempFolder("tool_progress_log");
  std::filesystem::create_directories(folder);
  const std::string sequence = (folder / "seq").string();
  const auto [rendered, render_log] = RunCaught(
      kPrograms.simulate.string() + " --preset sim-1 --frames 12 --width 160 --height 120 --out " + sequence,
      folder / "render.txt");
  ASSERT_EQ(rendered, 0) << render_log;
  EXPECT_EQ(render_log.find('\r'), std::string::npos) << render_log;
  EXPECT_NE(render_log.find("rendering sim-1: frame 12/12"), std::string::npos) << render_log;
  const auto [ran, run_log] =
      RunCaught(kPrograms.run.string() + " " + sequence + " --init depth --out " + (folder / "run").string(),
                folder / "run.txt");
  ASSERT_EQ(ran, 0) << run_log;
  EXPECT_EQ(run_log.find('\r'), std::string::npos) << run_log;
  // The first update and the last, not one per frame (the interval is 10 s).
  EXPECT_NE(run_log.find("frame 1/12"), std::string::npos) << run_log;
  EXPECT_NE(run_log.find("frame 12/12"), std::string::npos) << run_log;
  EXPECT_EQ(run_log.find("frame 6/12"), std::string::npos) << run_log;
  std::filesystem::remove_all(folder);
}

// One damaged file costs a preview video only its frame: an unreadable colour image becomes a
// black frame (a folder of PNGs leaves it out), an unreadable depth map a view without ground
// truth, and both are named on stderr; a single frame that cannot be drawn is still an error.
TEST(Tools, PreviewOfADamagedSequenceSkipsOnlyTheDamagedFrames) {
  const auto folder = UniqueTempFolder("tool_preview_damaged");
  std::filesystem::create_directories(folder);
  const std::filesystem::path sequence = folder / "seq";
  const auto [rendered, render_log] = RunCaught(kPrograms.simulate.string() +
                                                    " --preset sim-0 --frames 6 --width 160 --height 120 --quiet --out " +
                                                    sequence.string(),
                                                folder / "render.txt");
  ASSERT_EQ(rendered, 0) << render_log;
  std::filesystem::resize_file(sequence / "rgb" / "000002.png", 200);    // header intact, data cut
  std::filesystem::resize_file(sequence / "depth" / "000004.png", 200);
  const std::string preview = NRSLAM_TOOLS_DIR "/nrslam_preview " + sequence.string();
  const std::filesystem::path video = folder / "view.avi";
  const auto [drawn, draw_log] = RunCaught(preview + " --all --out " + video.string(), folder / "video.txt");
  ASSERT_EQ(drawn, 0) << draw_log;
  EXPECT_NE(draw_log.find("frame 2: cannot decode"), std::string::npos) << draw_log;
  EXPECT_NE(draw_log.find("frame 4: cannot decode"), std::string::npos) << draw_log;
  EXPECT_NE(draw_log.find("drawn without ground truth"), std::string::npos) << draw_log;
  EXPECT_NE(draw_log.find("wrote 6 frames to " + video.string() + " (1 unreadable: black)"), std::string::npos)
      << draw_log;
  cv::VideoCapture capture(video.string());
  ASSERT_TRUE(capture.isOpened());
  std::vector<double> brightness;
  for (cv::Mat image; capture.read(image);) {
    EXPECT_EQ(image.size(), cv::Size(320, 120));  // colour | depth, every frame
    brightness.push_back(cv::mean(image)[0]);
  }
  ASSERT_EQ(brightness.size(), 6u);
  EXPECT_LT(brightness[2], 2.0);  // the unreadable colour image: black (up to JPEG's ringing)
  for (size_t frame : {0u, 1u, 3u, 4u, 5u}) EXPECT_GT(brightness[frame], 10.0) << frame;
  const auto [folder_drawn, folder_log] =
      RunCaught(preview + " --all --out " + (folder / "frames").string(), folder / "frames.txt");
  ASSERT_EQ(folder_drawn, 0) << folder_log;
  for (int frame = 0; frame < 6; ++frame) {
    EXPECT_EQ(std::filesystem::exists(folder / "frames" / FrameFileName(frame)), frame != 2) << frame;
  }
  const auto [single, single_log] =
      RunCaught(preview + " --frame 2 --out " + (folder / "one.png").string(), folder / "one.txt");
  EXPECT_NE(single, 0);
  EXPECT_NE(single_log.find("cannot decode"), std::string::npos) << single_log;
  // A folder that --out names but that does not exist yet is made; a name OpenCV cannot write
  // an image to is refused before anything is drawn, naming it.
  const auto [nested, nested_log] =
      RunCaught(preview + " --frame 1 --out " + (folder / "new" / "one.png").string(), folder / "nested.txt");
  EXPECT_EQ(nested, 0) << nested_log;
  EXPECT_TRUE(std::filesystem::exists(folder / "new" / "one.png"));
  const auto [bare, bare_log] =
      RunCaught(preview + " --frame 1 --out " + (folder / "one").string(), folder / "bare.txt");
  EXPECT_NE(bare, 0);
  EXPECT_NE(bare_log.find("--out " + (folder / "one").string() + ": not an image file name OpenCV writes"),
            std::string::npos) << bare_log;
  // A scale that would draw nothing, or ask OpenCV for gigabytes, is named, not left to cv::resize.
  const auto [tiny, tiny_log] =
      RunCaught(preview + " --frame 1 --scale 0.01 --out " + (folder / "one.png").string(), folder / "tiny.txt");
  EXPECT_NE(tiny, 0);
  EXPECT_NE(tiny_log.find("--scale draws the 160x120 frames under 8 px a side"), std::string::npos) << tiny_log;
  const auto [huge, huge_log] =
      RunCaught(preview + " --frame 1 --scale 1000 --out " + (folder / "one.png").string(), folder / "huge.txt");
  EXPECT_NE(huge, 0);
  EXPECT_NE(huge_log.find("--scale must be in (0, 4]"), std::string::npos) << huge_log;
  std::filesystem::remove_all(folder);
}

TEST(BatchEvaluation, ACrashingOrMissingRunnerIsARecordedFailure) {
  const auto folder = UniqueTempFolder("batch_crash");
  EvaluationPlan plan;
  const std::filesystem::path crasher = StandInRunner(folder, "echo about to crash\nkill -SEGV $$\n", 2, &plan);
  ExecutePlan(plan, Programs{kPrograms.simulate, crasher, kPrograms.import, kPrograms.eval}, 2, [](const std::string&) {});
  for (const RunResult& result : CollectResults(plan)) {
    EXPECT_EQ(result.status, "failed");
    EXPECT_NE(result.error.find("killed by signal 11"), std::string::npos) << result.error;
    EXPECT_NE(result.error.find("about to crash"), std::string::npos) << result.error;  // its last words
  }
  ExecutePlan(plan, Programs{kPrograms.simulate, folder / "no-such-program", kPrograms.import, kPrograms.eval}, 2,
              [](const std::string&) {});
  for (const RunResult& result : CollectResults(plan)) {
    EXPECT_EQ(result.status, "failed");
    EXPECT_NE(result.error.find("cannot start"), std::string::npos) << result.error;
  }
  std::filesystem::remove_all(folder);
}

// A program that fails names the fault in a heading and lists what it found under it; the
// failure gives the heading with the list's first items, not the list's last line alone.
TEST(BatchEvaluation, AFailureGivesTheProgramsClosingMessageWithTheFirstOfItsList) {
  const auto folder = UniqueTempFolder("batch_list");
  EvaluationPlan plan;
  const std::filesystem::path runner = StandInRunner(folder,
                                                     "echo 'frame 1/5 tracking'\n"
                                                     "echo 'nrslam_run: invalid sequence seq:' >&2\n"
                                                     "for i in 0 1 2 3 4; do echo \"  - rgb/00000$i.png must be 8-bit\" >&2; done\n"
                                                     "echo '  - 25 more bad files in rgb/' >&2\n"
                                                     "exit 1\n",
                                                     1, &plan);
  ExecutePlan(plan, Programs{kPrograms.simulate, runner, kPrograms.import, kPrograms.eval}, 1, [](const std::string&) {});
  const std::vector<RunResult> results = CollectResults(plan);
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].error, "exit code 1: nrslam_run: invalid sequence seq: rgb/000000.png must be 8-bit; "
                              "rgb/000001.png must be 8-bit; rgb/000002.png must be 8-bit; 3 more line(s) in " +
                                  plan.runs[0].run_folder.string() + ".log");
  std::filesystem::remove_all(folder);
}

TEST(Progress, DurationsReadAsAPersonWouldSayThem) {
  EXPECT_EQ(FormatDuration(0), "0 s");
  EXPECT_EQ(FormatDuration(-3), "0 s");
  EXPECT_EQ(FormatDuration(42.4), "42 s");
  EXPECT_EQ(FormatDuration(150), "3 min");
  EXPECT_EQ(FormatDuration(89 * 60), "89 min");
  EXPECT_EQ(FormatDuration(2 * 3600 + 5 * 60 + 10), "2 h 5 min");
}

// Runs record the code of the nrslam_run that made them, and count as finished only when it
// is the evaluator's: an nrslam_run built from other code (one tool rebuilt, not the others)
// is refused before anything runs, not left to fail every run it finishes.
TEST(BatchEvaluation, ARunnerBuiltFromOtherCodeIsRefusedBeforeAnythingRuns) {
  const auto folder = UniqueTempFolder("batch_other_code");
  const auto runner_answering = [&](const std::string& code, EvaluationPlan* plan) {
    return StandInRunner(folder,
                         "if [ \"$1\" = --version ]; then echo 'nrslam 0.1.0 (revision 0123abcd, code " + code +
                             ")'; exit 0; fi\ntouch '" + (folder / "ran").string() + "'\n",
                         2, plan);
  };
  EvaluationPlan plan;
  const std::filesystem::path stale = runner_answering("0000deadbeef", &plan);
  try {
    ExecutePlan(plan, Programs{kPrograms.simulate, stale, kPrograms.import, kPrograms.eval}, 2, [](const std::string&) {});
    ADD_FAILURE() << "a runner of other code was used";
  } catch (const Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("built from other code (0000deadbeef)"), std::string::npos) << message;
    EXPECT_NE(message.find(CodeFingerprint()), std::string::npos) << message;
    EXPECT_NE(message.find("Rebuild every tool"), std::string::npos) << message;
  }
  EXPECT_FALSE(std::filesystem::exists(folder / "ran"));
  EXPECT_FALSE(std::filesystem::exists(plan.runs[0].run_folder / "failure.json"));

  // The same code passes the check; a run that then exits with 0 and writes nothing is a
  // failure that says so, not "exit code 0".
  const std::filesystem::path current = runner_answering(CodeFingerprint(), &plan);
  ExecutePlan(plan, Programs{kPrograms.simulate, current, kPrograms.import, kPrograms.eval}, 2, [](const std::string&) {});
  EXPECT_TRUE(std::filesystem::exists(folder / "ran"));
  for (const RunResult& result : CollectResults(plan)) {
    EXPECT_EQ(result.status, "failed");
    EXPECT_NE(result.error.find("exited with 0 but left no finished run"), std::string::npos) << result.error;
  }
  std::filesystem::remove_all(folder);
}

// A run the system kills (as the out-of-memory killer would) is recorded with the memory it
// had reached, which tells a run that ran out of memory from one that crashed.
TEST(BatchEvaluation, AKilledRunIsRecordedWithItsPeakMemory) {
  const auto folder = UniqueTempFolder("batch_killed");
  EvaluationPlan plan;
  // The shell holds the 32 MiB it reads into its variable, then kills itself.
  const std::filesystem::path grower =
      StandInRunner(folder, "x=$(head -c 33554432 /dev/zero | tr '\\0' a)\nkill -KILL $$\n", 1, &plan);
  ExecutePlan(plan, Programs{kPrograms.simulate, grower, kPrograms.import, kPrograms.eval}, 1, [](const std::string&) {});
  const std::vector<RunResult> results = CollectResults(plan);
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].status, "failed");
  const std::string& error = results[0].error;
  const size_t at = error.find("killed by signal 9 (Killed) at a peak of ");
  ASSERT_NE(at, std::string::npos) << error;
  const double peak_mb = std::stod(error.substr(at + std::string("killed by signal 9 (Killed) at a peak of ").size()));
  EXPECT_GE(peak_mb, 32.0) << error;
  EXPECT_LT(peak_mb, 1024.0) << error;
  std::filesystem::remove_all(folder);
}

TEST(BatchEvaluation, ARunThatHangsIsKilledAtItsTimeoutAndRecorded) {
  const auto folder = UniqueTempFolder("batch_timeout");
  EvaluationPlan plan;
  const std::filesystem::path hanger = StandInRunner(folder, "exec sleep 600\n", 3, &plan);
  const auto start = std::chrono::steady_clock::now();
  ExecutePlan(plan, Programs{kPrograms.simulate, hanger, kPrograms.import, kPrograms.eval}, 2, [](const std::string&) {}, 1.0);
  // Three runs of 1 s, two at a time: about two seconds, not the 600 s each would take.
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 60.0);
  for (const RunResult& result : CollectResults(plan)) {
    EXPECT_EQ(result.status, "failed");
    EXPECT_NE(result.error.find("timed out after 1 s (killed)"), std::string::npos) << result.error;
  }
  std::filesystem::remove_all(folder);
}

// Stopped (nrslam_eval on SIGINT or SIGTERM): the runs going are ended, none more starts, and
// none is recorded as failed, so the next evaluation runs them.
TEST(BatchEvaluation, AStoppedBatchEndsItsRunsAndLeavesThemUnfinished) {
  const auto folder = UniqueTempFolder("batch_stopped");
  EvaluationPlan plan;
  // Two runs going and one waiting when the stop comes (--version answers at once).
  const std::filesystem::path sleeper =
      StandInRunner(folder, "[ \"$1\" = --version ] && exit 1\nexec sleep 600\n", 3, &plan);
  std::atomic<bool> stop{false};
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(1000));
    stop = true;
  });
  std::vector<std::string> lines;
  const auto start = std::chrono::steady_clock::now();
  ExecutePlan(plan, Programs{kPrograms.simulate, sleeper, kPrograms.import, kPrograms.eval}, 2,
              [&](const std::string& line) { lines.push_back(line); }, 0, &stop);
  stopper.join();
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 30.0);
  EXPECT_EQ(lines, std::vector<std::string>{
                       "3 run(s) interrupted and left unfinished: the next evaluation into this folder runs them"});
  for (const RunJob& run : plan.runs) {
    EXPECT_FALSE(std::filesystem::exists(run.run_folder / "failure.json")) << run.run_folder;
    EXPECT_FALSE(RunIsFinished(run));
  }
  std::filesystem::remove_all(folder);
}

TEST(BatchEvaluation, ASweepResumesWhereItStopped) {
  const auto folder = UniqueTempFolder("batch_resume");
  const Manifest manifest = LoadManifest(WriteFile(folder / "m.json", std::string(R"({
    "sequences": [{"name": "s", "preset": "sim-1", "simulate": )") + kTinySimulate + "}]}"));
  const EvaluationPlan plan = PlanEvaluation(manifest, {}, {ParseSweep("max_degree_D=4,8")}, folder / "out", folder / "cache");
  ASSERT_EQ(plan.runs.size(), 2u);
  // A dry run lists what the evaluation would do.
  const std::string before = DescribePlan(plan);
  EXPECT_EQ(before.rfind("1 sequence(s) to render or import, 0 already in the cache; 2 run(s) to run, 0 finished", 0), 0u)
      << before;
  EXPECT_NE(before.find("to render     sim-1 "), std::string::npos) << before;
  EXPECT_NE(before.find("to run        s [max_degree_D=8]\n"), std::string::npos) << before;
  std::vector<std::string> first_lines;
  ExecutePlan(plan, kPrograms, 2, [&](const std::string& line) { first_lines.push_back(line); });
  // Each run says how long it took; the first also how long the rest should take. (The
  // render of the sequence comes first.)
  ASSERT_EQ(first_lines.size(), 3u);
  first_lines.erase(first_lines.begin());
  EXPECT_TRUE(std::regex_search(first_lines[0], std::regex(R"(\[1/2\] s \[max_degree_D=\d\] done in \d+ s; about \d+ s left$)")))
      << first_lines[0];
  EXPECT_TRUE(std::regex_search(first_lines[1], std::regex(R"(\[2/2\] s \[max_degree_D=\d\] done in \d+ s$)"))) << first_lines[1];
  const std::vector<RunResult> first = CollectResults(plan);
  ASSERT_EQ(first[0].status, "ok") << first[0].error;
  ASSERT_EQ(first[1].status, "ok") << first[1].error;
  // The cached render records the code that made it, which is part of its key.
  EXPECT_EQ(ReadJsonFile(plan.prepares[0].folder / "sequence.json").at("provenance").at("code"),
            SequenceCodeFingerprint());
  // As if the second run had been interrupted: only it runs again.
  std::filesystem::remove(plan.runs[1].run_folder / "summary.json");
  const auto untouched = std::filesystem::last_write_time(plan.runs[0].run_folder / "summary.json");
  const std::string after = DescribePlan(plan);
  EXPECT_EQ(after.rfind("0 sequence(s) to render or import, 1 already in the cache; 1 run(s) to run, 1 finished", 0), 0u)
      << after;
  EXPECT_NE(after.find("finished      s [max_degree_D=4]\n"), std::string::npos) << after;
  EXPECT_NE(after.find("to run        s [max_degree_D=8]\n"), std::string::npos) << after;
  std::vector<std::string> lines;
  ExecutePlan(plan, kPrograms, 2, [&](const std::string& line) { lines.push_back(line); });
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0], "1 run(s) already finished, not run again");
  EXPECT_NE(lines[1].find("[1/1] s [max_degree_D=8] done in "), std::string::npos) << lines[1];
  EXPECT_EQ(lines[1].find("left"), std::string::npos) << lines[1];  // the last run: nothing left
  EXPECT_EQ(std::filesystem::last_write_time(plan.runs[0].run_folder / "summary.json"), untouched);
  const std::vector<RunResult> second = CollectResults(plan);
  EXPECT_DOUBLE_EQ(second[1].rmse_mm, first[1].rmse_mm);  // the same run, the same answer
  std::filesystem::remove_all(folder);
}

// The same --out reused with other options must not report the old runs as the new ones.
TEST(BatchEvaluation, AnOutputFolderReusedWithOtherOptionsIsRunAgain) {
  const auto folder = UniqueTempFolder("batch_superseded");
  const Manifest manifest = LoadManifest(WriteFile(folder / "m.json", std::string(R"({
    "defaults": {"init": "depth"},
    "sequences": [{"name": "s", "preset": "sim-1", "simulate": )") + kTinySimulate + "}]}"));
  const EvaluationPlan stiff = PlanEvaluation(manifest, {"deformation.k=3"}, {}, folder / "out", folder / "cache");
  const EvaluationPlan plain = PlanEvaluation(manifest, {}, {}, folder / "out", folder / "cache");
  ExecutePlan(stiff, kPrograms, 2, [](const std::string&) {});
  ASSERT_EQ(CollectResults(stiff)[0].status, "ok") << CollectResults(stiff)[0].error;
  EXPECT_TRUE(RunIsFinished(stiff.runs[0]));
  EXPECT_FALSE(RunIsFinished(plain.runs[0]));
  std::vector<std::string> lines;
  ExecutePlan(plain, kPrograms, 2, [&](const std::string& line) { lines.push_back(line); });
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0], "1 run(s) in the output folder had other options, another or changed sequence, changed estimates or other code: run again");
  EXPECT_NE(lines[1].find("[1/1] s done"), std::string::npos) << lines[1];
  const Json config = ReadJsonFile(plain.runs[0].run_folder / "config.json");
  EXPECT_EQ(config.at("options").at("deformation").at("k"), Json(DeformationModelOptions{}.k));
  EXPECT_TRUE(RunIsFinished(plain.runs[0]));
  lines.clear();
  ExecutePlan(plain, kPrograms, 2, [&](const std::string& line) { lines.push_back(line); });
  EXPECT_EQ(lines, std::vector<std::string>{"1 run(s) already finished, not run again"});
  // The sequence's description edited in place (here its frame rate; a corrected calibration
  // alike): its runs are run again.
  const std::filesystem::path description = plain.runs[0].sequence_folder / "sequence.json";
  const Json original = ReadJsonFile(description);
  Json edited = original;
  edited["fps"] = 25.0;
  std::ofstream(description) << edited.dump();
  EXPECT_FALSE(RunIsFinished(plain.runs[0]));
  std::ofstream(description) << original.dump(2);  // the same description, written otherwise
  EXPECT_TRUE(RunIsFinished(plain.runs[0]));
  // A run from another commit whose code is the same (a commit of the README alone) is reused...
  const Json as_written = ReadJsonFile(plain.runs[0].run_folder / "config.json");
  EXPECT_EQ(as_written.at("nrslam_revision"), SourceRevision());
  EXPECT_EQ(as_written.at("nrslam_code"), CodeFingerprint());
  Json other_commit = as_written;
  other_commit["nrslam_revision"] = std::string(SourceRevision()) + "-elsewhere";
  std::ofstream(plain.runs[0].run_folder / "config.json") << other_commit.dump();
  EXPECT_TRUE(RunIsFinished(plain.runs[0]));
  // ... one made by other code is not, nor one whose config does not say which code made it.
  Json other_code = as_written;
  other_code["nrslam_code"] = "0123456789ab";
  std::ofstream(plain.runs[0].run_folder / "config.json") << other_code.dump();
  EXPECT_FALSE(RunIsFinished(plain.runs[0]));
  Json unrecorded_code = as_written;
  unrecorded_code.erase("nrslam_code");
  std::ofstream(plain.runs[0].run_folder / "config.json") << unrecorded_code.dump();
  EXPECT_FALSE(RunIsFinished(plain.runs[0]));
  std::filesystem::remove_all(folder);
}

TEST(BatchEvaluation, EmittedJobsRunByGnuParallelThenMerged) {
  if (std::system("parallel --version > /dev/null 2>&1") != 0) GTEST_SKIP() << "GNU parallel is not installed";
  const auto folder = UniqueTempFolder("batch_parallel");
  const std::filesystem::path manifest = WriteFile(folder / "m.json", std::string(R"({
    "defaults": {"simulate": )") + kTinySimulate + R"(},
    "sequences": [{"name": "a", "preset": "sim-1"}, {"name": "b", "preset": "sim-1", "rigid": true}]})");
  const std::string eval = std::string(NRSLAM_TOOLS_DIR) + "/nrslam_eval";
  const std::string common = " --out " + (folder / "out").string() + " --cache " + (folder / "cache").string() +
                             " --sweep max_degree_D=4,8";
  ASSERT_EQ(std::system((eval + " " + manifest.string() + common + " --emit-jobs " + (folder / "jobs.txt").string() +
                         " > /dev/null").c_str()),
            0);
  const std::string text = FileText(folder / "jobs.txt");
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 4);
  // Four jobs, two at a time; both renders of the one preset race for the same cache folder.
  ASSERT_EQ(std::system(("parallel --will-cite -j2 < " + (folder / "jobs.txt").string() + " > /dev/null 2>&1").c_str()), 0);
  ASSERT_EQ(std::system((eval + " merge " + manifest.string() + common + " > " + (folder / "merge.txt").string()).c_str()), 0);
  const std::vector<RunResult> merged = ReadResults(folder / "out");
  ASSERT_EQ(merged.size(), 4u);
  for (const RunResult& r : merged) EXPECT_NE(r.status, "failed") << r.sequence << " " << r.label << ": " << r.error;
  // Nothing half-written is left in the cache.
  int cache_entries = 0;
  for (const auto& entry : std::filesystem::directory_iterator(folder / "cache")) {
    ++cache_entries;
    EXPECT_EQ(entry.path().filename().string().find(".partial"), std::string::npos) << entry.path();
  }
  EXPECT_EQ(cache_entries, 1);
  std::filesystem::remove_all(folder);
}

// Two evaluations that share a cache (as the cache is meant to be shared) and start at once both
// render the sequences they lack: each into a folder of its own, the first to finish moving its
// render into place. Here in two threads of one process, which must not take each other's
// children either. What an interrupted evaluation left behind is removed; a live one's is not.
TEST(BatchEvaluation, EvaluationsSharingACacheRenderTheSameSequencesAtOnce) {
  const auto folder = UniqueTempFolder("batch_shared_cache");
  const Manifest manifest = LoadManifest(WriteFile(folder / "m.json", std::string(R"({
    "defaults": {"init": "depth", "simulate": )") + kTinySimulate + R"(},
    "sequences": [{"name": "a", "preset": "sim-1"}, {"name": "b", "preset": "sim-2"}]})"));
  const EvaluationPlan first = PlanEvaluation(manifest, {}, {}, folder / "first", folder / "cache");
  const EvaluationPlan second = PlanEvaluation(manifest, {}, {}, folder / "second", folder / "cache");
  ASSERT_EQ(first.prepares.size(), 2u);
  char host[256] = {};
  ::gethostname(host, sizeof(host) - 1);
  const std::string sequence = first.prepares[0].folder.string();
  const std::filesystem::path abandoned = sequence + ".partial." + host + "-999999999-0";  // beyond any pid
  const std::filesystem::path live = sequence + ".partial." + host + "-1-0";               // init's
  WriteFile(abandoned / "rgb" / "000000.png", "half");
  WriteFile(abandoned.string() + ".log", "interrupted");
  WriteFile(live / "sequence.json", "{}");

  // The renderer, slowed down so that both evaluations start each render before either ends.
  const std::filesystem::path slow =
      WriteScript(folder / "slow_simulate.sh", "sleep 2\nexec " + kPrograms.simulate.string() + " \"$@\"\n");
  const Programs programs{slow, kPrograms.run, kPrograms.import, kPrograms.eval};
  std::vector<std::string> first_lines, second_lines;
  std::thread other([&] { ExecutePlan(second, programs, 2, [&](const std::string& l) { second_lines.push_back(l); }); });
  ExecutePlan(first, programs, 2, [&](const std::string& l) { first_lines.push_back(l); });
  other.join();
  // Both rendered both sequences: neither waited for the other.
  const auto renders = [](const std::vector<std::string>& lines) {
    return std::count_if(lines.begin(), lines.end(), [](const std::string& l) { return l.rfind("rendered ", 0) == 0; });
  };
  EXPECT_EQ(renders(first_lines), 2) << ::testing::PrintToString(first_lines);
  EXPECT_EQ(renders(second_lines), 2) << ::testing::PrintToString(second_lines);
  const std::vector<RunResult> a = CollectResults(first), b = CollectResults(second);
  ASSERT_EQ(a.size(), 2u);
  ASSERT_EQ(b.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    ASSERT_EQ(a[i].status, "ok") << a[i].error << "\n" << ::testing::PrintToString(first_lines);
    ASSERT_EQ(b[i].status, "ok") << b[i].error << "\n" << ::testing::PrintToString(second_lines);
    EXPECT_EQ(a[i].frames_tracked, 8);
    EXPECT_DOUBLE_EQ(a[i].rmse_mm, b[i].rmse_mm);  // the same complete sequence, whoever rendered it
  }
  std::set<std::string> cache;
  for (const auto& entry : std::filesystem::directory_iterator(folder / "cache")) {
    cache.insert(entry.path().filename().string());
  }
  const std::string live_name = live.filename().string();
  const std::set<std::string> expected = {first.prepares[0].folder.filename().string(),
                                          first.prepares[0].folder.filename().string() + ".log",
                                          first.prepares[1].folder.filename().string(),
                                          first.prepares[1].folder.filename().string() + ".log", live_name};
  EXPECT_EQ(cache, expected);
  // What was abandoned beside a sequence already there goes too, with nothing to run.
  const std::filesystem::path late = first.prepares[1].folder.string() + ".partial." + host + "-999999999-3.log";
  WriteFile(late, "interrupted");
  ExecutePlan(first, programs, 2, [](const std::string&) {});
  EXPECT_FALSE(std::filesystem::exists(late));
  // The cache's survey knows both renders for this build's: nothing for --prune to remove.
  const CacheContents contents = ReadCacheContents(folder / "cache");
  ASSERT_EQ(contents.sequences.size(), 2u);
  for (const CachedSequence& made : contents.sequences) EXPECT_TRUE(made.MadeByThisCode()) << made.code;
  EXPECT_EQ(contents.others, std::vector<std::filesystem::path>{live});
  std::filesystem::remove_all(folder);
}

// `nrslam_eval cache` lists what an evaluation left in its cache, by the code that made each
// sequence, and --prune removes the sequences this build would never read again (each with its
// log), and nothing that is not an evaluation's sequence.
TEST(SequenceCache, ListsEachSequenceByItsCodeAndPrunesOnlyThoseOfOtherCode) {
  const auto folder = UniqueTempFolder("sequence_cache");
  const std::filesystem::path cache = folder / "cache";
  const auto sequence = [&](const std::string& name, const std::string& description) {
    WriteFile(cache / name / "sequence.json", description);
    WriteFile(cache / name / "rgb" / "000000.png", std::string(1000, 'x'));
    WriteFile(cache / (name + ".log"), "rendered");
  };
  const std::filesystem::path current = CachedSequenceFolder(cache, "sim-1", {"--preset", "sim-1"});
  const std::string this_code = std::string(R"({"provenance": {"code": ")") + SequenceCodeFingerprint() + "\"}}";
  sequence(current.filename().string(), this_code);
  sequence("sim-2-0123456789ab", R"({"provenance": {"code": "0123456789ab"}})");
  // Made before sequences recorded their code, and damaged.
  sequence("sim-3-00000000000b", R"({"provenance": {"generator": "nrslam_simulate 0.1.0"}})");
  sequence("sim-4-00000000000c", "{");
  // Not an evaluation's sequence: someone's own folder, a folder without its description, the log
  // of a render that failed, a partial render of a live evaluation and a file.
  sequence("my-data", this_code);
  WriteFile(cache / "sim-5-00000000000d" / "rgb" / "000000.png", "x");
  WriteFile(cache / "sim-6-00000000000e.log", "rendering sim-6 failed");
  char host[256] = {};
  ::gethostname(host, sizeof(host) - 1);
  const std::filesystem::path live = current.string() + ".partial." + host + "-" + std::to_string(::getpid()) + "-0";
  WriteFile(live / "sequence.json", "{}");
  WriteFile(cache / "notes.txt", "mine");
  // An interrupted evaluation's partial render, which any evaluation into the cache removes.
  WriteFile(std::filesystem::path(current.string() + ".partial." + host + "-999999999-0") / "sequence.json", "{}");

  const CacheContents contents = ReadCacheContents(cache);
  std::vector<std::string> names, codes;
  for (const CachedSequence& s : contents.sequences) {
    names.push_back(s.folder.filename().string());
    codes.push_back(s.code);
    EXPECT_EQ(s.bytes, FileText(s.folder / "sequence.json").size() + 1000 + 8) << s.folder;
  }
  EXPECT_EQ(names, (std::vector<std::string>{current.filename().string(), "sim-2-0123456789ab", "sim-3-00000000000b",
                                             "sim-4-00000000000c"}));
  EXPECT_EQ(codes, (std::vector<std::string>{SequenceCodeFingerprint(), "0123456789ab", "", ""}));
  std::set<std::string> others;
  for (const std::filesystem::path& other : contents.others) others.insert(other.filename().string());
  const std::set<std::string> left_alone = {"my-data", "my-data.log", "sim-5-00000000000d", "sim-6-00000000000e.log",
                                            live.filename().string(), "notes.txt"};
  std::set<std::string> expected_others = left_alone;
  expected_others.insert(current.filename().string() + ".partial." + host + "-999999999-0");
  EXPECT_EQ(others, expected_others);

  const std::string listing = DescribeCache(cache, contents);
  EXPECT_NE(listing.find(": 4 sequence(s)"), std::string::npos) << listing;
  EXPECT_NE(listing.find("1 made by this build's code (" + std::string(SequenceCodeFingerprint()) + ")"),
            std::string::npos) << listing;
  EXPECT_NE(listing.find("3 by other code"), std::string::npos) << listing;
  EXPECT_NE(listing.find("sim-2-0123456789ab  0123456789ab"), std::string::npos) << listing;
  EXPECT_NE(listing.find("sim-3-00000000000b  not recorded"), std::string::npos) << listing;
  EXPECT_NE(listing.find("my-data, "), std::string::npos) << listing;
  // The program prints the same listing, and changes nothing without --prune.
  const auto [status, printed] =
      RunCaught(std::string(NRSLAM_TOOLS_DIR) + "/nrslam_eval cache --cache " + cache.string(), folder / "log.txt");
  EXPECT_EQ(status, 0) << printed;
  EXPECT_EQ(printed, listing);

  const auto [pruned, pruning] = RunCaught(
      std::string(NRSLAM_TOOLS_DIR) + "/nrslam_eval cache --prune --cache " + cache.string(), folder / "log.txt");
  EXPECT_EQ(pruned, 0) << pruning;
  std::uintmax_t freed = 0;
  for (const CachedSequence& s : contents.sequences) freed += s.MadeByThisCode() ? 0 : s.bytes;
  EXPECT_NE(pruning.find("removed 3 sequence(s), " + FormatFixed(freed / 1e6, 1) + " MB"), std::string::npos)
      << pruning;
  std::set<std::string> kept;
  for (const auto& entry : std::filesystem::directory_iterator(cache)) kept.insert(entry.path().filename().string());
  std::set<std::string> expected_kept = left_alone;
  expected_kept.insert({current.filename().string(), current.filename().string() + ".log"});
  EXPECT_EQ(kept, expected_kept);
  ExpectRefused([&] { ReadCacheContents(folder / "none"); },
                "the cache " + (folder / "none").string() + " does not exist");
  ExpectRefused([&] { ReadCacheContents(folder / "log.txt"); },
                "the cache " + (folder / "log.txt").string() + " is not a folder");
  std::filesystem::remove_all(folder);
}

// An evaluation killed before its parent reaped it is a zombie: ended, though kill(pid, 0)
// still finds it. Its partial renders are abandoned all the same.
TEST(Processes, AZombieIsNotRunning) {
  EXPECT_TRUE(ProcessIsRunning(::getpid()));
  EXPECT_FALSE(ProcessIsRunning(999999999));
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ASSERT_GT(child, 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // it has exited, not been reaped
  EXPECT_EQ(::kill(child, 0), 0);
  EXPECT_FALSE(ProcessIsRunning(child));
  ::waitpid(child, nullptr, 0);
  EXPECT_FALSE(ProcessIsRunning(child));
}

TEST(BatchEvaluation, TwoEvaluationsIntoOneFolderAreRefused) {
  const auto folder = UniqueTempFolder("batch_locked");
  const std::filesystem::path manifest = WriteFile(folder / "m.json", std::string(R"({
    "defaults": {"init": "depth", "simulate": )") + kTinySimulate + R"(},
    "sequences": [{"name": "a", "preset": "sim-1"}]})");
  const std::string evaluation = std::string(NRSLAM_TOOLS_DIR) + "/nrslam_eval " + manifest.string() + " --out " +
                                 (folder / "out").string() + " --cache " + (folder / "cache").string() + " > " +
                                 (folder / "log.txt").string() + " 2>&1";
  {
    const FolderLock running(folder / "out", "an evaluation still running");
    EXPECT_THROW(FolderLock(folder / "out", "a second one"), Error);
    EXPECT_NE(std::system(evaluation.c_str()), 0);
    const std::string text = FileText(folder / "log.txt");
    EXPECT_NE(text.find("is in use by another process (an evaluation still running, pid " + std::to_string(::getpid()) +
                        ", or a process it started)"),
              std::string::npos)
        << text;
    EXPECT_FALSE(std::filesystem::exists(folder / "out" / "runs"));  // nothing ran
    EXPECT_FALSE(std::filesystem::exists(folder / "cache"));         // nothing rendered
  }
  // A child of the holder keeps it (a run goes on writing after its evaluation was killed).
  {
    const FolderLock parent(folder / "out", "an evaluation killed later");
    ASSERT_EQ(std::system("sleep 3 &"), 0);
  }
  EXPECT_THROW(FolderLock(folder / "out", "too soon"), Error);
  std::this_thread::sleep_for(std::chrono::milliseconds(3500));
  // The lock ends with its holder and its children.
  EXPECT_EQ(std::system(evaluation.c_str()), 0);
  EXPECT_EQ(ReadResults(folder / "out").at(0).status, "ok");
  std::filesystem::remove_all(folder);
}

}  // namespace
}  // namespace nrslam
