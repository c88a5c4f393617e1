#include <gtest/gtest.h>

#include <fstream>

#include "error_message.h"
#include "nrslam/mapping/mapping_options.h"
#include "nrslam/sim/sim_options.h"
#include "nrslam/system/system_options.h"
#include "nrslam/tracking/tracking_options.h"
#include "nrslam/util/json_options.h"
#include "nrslam/util/text_table.h"
#include "temp_folder.h"

namespace nrslam {
namespace {

TEST(JsonOptions, AssignmentsParseWithTheFieldsType) {
  const SimOptions options = WithAssignments(SimOptions{}, {"deformation.amplitude_mm=7.5", "frames=33",
                                                           "camera.fov_deg=75", "camera.model=fisheye"});
  EXPECT_DOUBLE_EQ(options.deformation.amplitude_mm, 7.5);
  EXPECT_EQ(options.frames, 33);
  EXPECT_EQ(options.camera.model, "fisheye");
  EXPECT_DOUBLE_EQ(options.camera.fov_deg, 75.0);
}

TEST(JsonOptions, UnknownOptionIsAnErrorThatListsTheKnownOnes) {
  try {
    WithAssignments(SimOptions{}, {"deformation.amplitud_mm=5"});
    FAIL() << "a misspelt option was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("unknown option 'deformation.amplitud_mm'"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("deformation.amplitude_mm"), std::string::npos);
  }
}

// A mistyped or partial name gets the options it most likely meant, not a list of all of them;
// a name close to none gets the whole list.
TEST(JsonOptions, UnknownNamesSuggestTheCloseOptions) {
  const std::vector<std::string> paths = {"deformation.k", "deformation.sigma_factor", "deformation.max_degree_D",
                                          "deformation.stretch_threshold", "mapping.dba_window", "tracking.pose_sigma_px"};
  EXPECT_EQ(UnknownOptionHint("sigma", paths), "did you mean deformation.sigma_factor or tracking.pose_sigma_px?");
  EXPECT_EQ(UnknownOptionHint("stretch_treshold", paths), "did you mean deformation.stretch_threshold?");
  EXPECT_EQ(UnknownOptionHint("mapping.dba_windw", paths), "did you mean mapping.dba_window?");
  EXPECT_EQ(UnknownOptionHint("D", paths), "did you mean deformation.max_degree_D?");
  // Short names allow no edit: "kk" is not taken for "k".
  EXPECT_EQ(UnknownOptionHint("kk", paths), "known options: " + Join(paths, ", "));
  EXPECT_EQ(UnknownOptionHint("viscosity", paths), "known options: " + Join(paths, ", "));
  // Each unknown key of an options file gets its own hint.
  try {
    OptionsFromJson<SimOptions>(Json::parse(R"({"frame": 3, "deformation": {"amplitud_mm": 5}})"), "file.json");
    FAIL() << "unknown keys were accepted";
  } catch (const Error& e) {
    const std::string message = e.what();
    // "frame" is in colon.speed_mm_per_frame too; both are offered.
    EXPECT_NE(message.find("unknown option 'frame' (did you mean colon.speed_mm_per_frame or frames?)"),
              std::string::npos) << message;
    EXPECT_NE(message.find("unknown option 'deformation.amplitud_mm' (did you mean deformation.amplitude_mm?)"),
              std::string::npos) << message;
  }
}

// An options file may name a group's field as --set does; one option given two ways is refused.
TEST(JsonOptions, AnOptionsFileMayNestGroupsOrDotTheirFields) {
  const SimOptions nested =
      OptionsFromJson<SimOptions>(Json::parse(R"({"camera": {"width": 320}, "deformation": {"omega_rad_s": 4}})"), "f");
  const SimOptions dotted =
      OptionsFromJson<SimOptions>(Json::parse(R"({"camera.width": 320, "deformation": {"omega_rad_s": 4}})"), "f");
  EXPECT_EQ(nested.camera.width, 320);
  EXPECT_EQ(nested.deformation.omega_rad_s, 4.0);
  EXPECT_EQ(Json(dotted), Json(nested));
  EXPECT_EQ(DottedOptions(Json::parse(R"({"camera": {"width": 320}, "frames": 9})")),
            Json::parse(R"({"camera.width": 320, "frames": 9})"));
  EXPECT_EQ(NestedOptions(Json::parse(R"({"camera.width": 320, "frames": 9})")),
            Json::parse(R"({"camera": {"width": 320}, "frames": 9})"));
  const auto error = [](const std::string& text) {
    return ErrorMessage([&] { OptionsFromJson<SimOptions>(Json::parse(text), "f.json"); });
  };
  EXPECT_NE(error(R"({"camera.width": 320, "camera": {"width": 64}})")
                .find("f.json: option 'camera.width' is given twice, as a dotted name and as a group's field"),
            std::string::npos);
  EXPECT_NE(error(R"({"camera": 5, "camera.width": 64})").find("f.json: option 'camera' is given as a value and as a group"),
            std::string::npos);
  EXPECT_NE(error(R"({"camera.heigt": 240})").find("unknown option 'camera.heigt' (did you mean camera.height?)"),
            std::string::npos);
}

TEST(JsonOptions, BadValuesAndInvalidResultsAreRejected) {
  EXPECT_THROW(WithAssignments(SimOptions{}, {"frames=many"}), Error);
  EXPECT_THROW(WithAssignments(SimOptions{}, {"frames"}), Error);
  try {
    WithAssignments(SimOptions{}, {"frames=2.5"});  // would be truncated
    ADD_FAILURE() << "frames=2.5 accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot use '2.5' (expected a whole number, like"), std::string::npos)
        << e.what();
  }
  // No Check() involved: JSON cannot hold these, so config.json would record null.
  for (const char* not_finite : {"inf", "-inf", "nan", "infinity"}) {
    Json config = {{"k", 1.1}};
    EXPECT_THROW(ApplyAssignment(config, std::string("k=") + not_finite), Error) << not_finite;
    EXPECT_EQ(config["k"], 1.1);
  }
  EXPECT_THROW(WithAssignments(SimOptions{}, {"deformation=3"}), Error);          // a group
  EXPECT_THROW(WithAssignments(SimOptions{}, {"camera.model=orthographic"}), Error);  // fails Check()
  EXPECT_THROW(OptionsFromJson<SimOptions>(Json{{"sceen", "colon"}}, "test"), Error);
}

// A value of the wrong kind in an options file is named with what it got, rather than
// nlohmann's bare type error, and a fraction is not truncated into a whole-number option.
TEST(JsonOptions, ValuesOfTheWrongKindAreNamed) {
  const Json given = {{"frames", 2.5}, {"camera", {{"model", 3}, {"fov_deg", 80}}}, {"deformation", "strong"}};
  try {
    OptionsFromJson<SimOptions>(given, "options.json");
    FAIL() << "wrongly typed values were accepted";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("options.json: "), std::string::npos) << what;
    EXPECT_NE(what.find("frames must be a whole number, got 2.5"), std::string::npos) << what;
    EXPECT_NE(what.find("camera.model must be a string, got 3"), std::string::npos) << what;
    EXPECT_NE(what.find("deformation is a group of options, got \"strong\""), std::string::npos) << what;
    EXPECT_EQ(what.find("fov_deg"), std::string::npos) << what;  // a whole number is a number
  }
  EXPECT_DOUBLE_EQ(OptionsFromJson<SimOptions>(Json{{"camera", {{"fov_deg", 80}}}}, "test").camera.fov_deg, 80.0);
}

// Fields of files a person writes (sequence.json, a camera) are read by kind, never truncated.
TEST(JsonFields, ValuesOfAnotherKindAreNamedNotConverted) {
  const Json given = {{"width", 320},    {"fps", 30},           {"half", 320.5},
                      {"text", "abc"},   {"huge", 10000000000}, {"mixed", {1.5, "a"}},
                      {"list", {1, 2.5}}};
  EXPECT_EQ(Field<int>(given, "width", "camera"), 320);
  EXPECT_DOUBLE_EQ(Field<double>(given, "fps", "camera"), 30.0);  // a whole number is a number
  EXPECT_EQ(Field<std::vector<double>>(given, "list", "camera"), (std::vector<double>{1.0, 2.5}));
  EXPECT_EQ(Field(given, "absent", "camera", 7), 7);
  EXPECT_EQ(ErrorMessage([&] { Field<int>(given, "half", "camera"); }), "camera: half must be a whole number, got 320.5");
  EXPECT_EQ(ErrorMessage([&] { Field<int>(given, "huge", "camera"); }),
            "camera: huge must be a whole number, got 10000000000");
  EXPECT_EQ(ErrorMessage([&] { Field<double>(given, "text", "camera"); }), "camera: text must be a number, got \"abc\"");
  EXPECT_EQ(ErrorMessage([&] { Field<std::string>(given, "fps", "camera"); }), "camera: fps must be a string, got 30");
  EXPECT_EQ(ErrorMessage([&] { Field<std::vector<double>>(given, "mixed", "camera"); }),
            "camera: mixed must be a list of numbers, got [1.5,\"a\"]");
  EXPECT_EQ(ErrorMessage([&] { Field<double>(given, "absent", "camera"); }), "camera: missing field 'absent'");
  EXPECT_EQ(ErrorMessage([&] { Field(given, "text", "camera", 1.0); }), "camera: text must be a number, got \"abc\"");
}

TEST(JsonOptions, RoundTripKeepsEveryField) {
  SimOptions options = SimPreset("sim-5");
  options.colon.fold_width_mm = 1.7;
  options.appearance.noise_sigma = 3.5;
  const SimOptions back = OptionsFromJson<SimOptions>(Json(options), "test");
  EXPECT_EQ(Json(back), Json(options));
}

TEST(JsonOptions, TrackingLinearSolverIsAChoiceOfTwo) {
  const TrackingOptions cgnr = WithAssignments(TrackingOptions{}, {"joint_linear_solver=cgnr"});
  EXPECT_EQ(cgnr.joint_linear_solver, "cgnr");
  EXPECT_EQ(OptionsFromJson<TrackingOptions>(Json(cgnr), "test").joint_linear_solver, "cgnr");
  EXPECT_THROW(WithAssignments(TrackingOptions{}, {"joint_linear_solver=qr"}), Error);
  const TrackingOptions dogleg = WithAssignments(TrackingOptions{}, {"joint_trust_region=dogleg"});
  EXPECT_EQ(OptionsFromJson<TrackingOptions>(Json(dogleg), "test").joint_trust_region, "dogleg");
  EXPECT_THROW(WithAssignments(TrackingOptions{}, {"joint_trust_region=newton"}), Error);
}

TEST(JsonOptions, DisplacementPriorIsOffByDefaultAndNeverNegative) {
  EXPECT_EQ(TrackingOptions{}.displacement_prior_sigma, 0.0);
  EXPECT_EQ(WithAssignments(TrackingOptions{}, {"displacement_prior_sigma=0.2"}).displacement_prior_sigma, 0.2);
  EXPECT_THROW(WithAssignments(TrackingOptions{}, {"displacement_prior_sigma=-0.2"}), Error);
}

TEST(JsonOptions, ReassociationConsensusIsACount) {
  const TrackingOptions off = WithAssignments(TrackingOptions{}, {"reassociation_consensus_k=0"});
  EXPECT_EQ(OptionsFromJson<TrackingOptions>(Json(off), "test").reassociation_consensus_k, 0);
  EXPECT_EQ(TrackingOptions{}.reassociation_consensus_k, 4);
  EXPECT_THROW(WithAssignments(TrackingOptions{}, {"reassociation_consensus_k=-1"}), Error);
  EXPECT_EQ(WithAssignments(TrackingOptions{}, {"hidden_recent_frames=0"}).hidden_recent_frames, 0);
  EXPECT_THROW(WithAssignments(TrackingOptions{}, {"hidden_recent_frames=-1"}), Error);
  EXPECT_THROW(WithAssignments(TrackingOptions{}, {"hidden_min_edge_fraction=0.5"}), Error);
}

TEST(JsonOptions, StaticRegionOptionsAreValidatedAndRoundTrip) {
  const FrontendOptions off =
      WithAssignments(FrontendOptions{}, {"masks.static_frames=0", "masks.static_min_edge=8",
                                          "masks.static_min_seconds=1.5", "masks.static_window_seconds=12"});
  EXPECT_EQ(Json(OptionsFromJson<FrontendOptions>(Json(off), "test")), Json(off));
  EXPECT_EQ(off.masks.static_frames, 0);
  EXPECT_EQ(FrontendOptions{}.masks.static_frames, 24);
  EXPECT_THROW(WithAssignments(FrontendOptions{}, {"masks.static_frames=9"}), Error);  // too few to tell
  EXPECT_EQ(WithAssignments(FrontendOptions{}, {"masks.static_frames=10"}).masks.static_frames, 10);
  EXPECT_THROW(WithAssignments(FrontendOptions{}, {"masks.static_max_change=256"}), Error);
  EXPECT_THROW(WithAssignments(FrontendOptions{}, {"masks.static_min_edge=-1"}), Error);
  EXPECT_THROW(WithAssignments(FrontendOptions{}, {"masks.static_margin_px=-1"}), Error);
  EXPECT_THROW(WithAssignments(FrontendOptions{}, {"masks.static_max_fraction=1.5"}), Error);
  EXPECT_EQ(off.masks.static_min_seconds, 1.5);
  EXPECT_THROW(WithAssignments(FrontendOptions{}, {"masks.static_min_seconds=-1"}), Error);
  EXPECT_EQ(off.masks.static_window_seconds, 12);
  EXPECT_EQ(FrontendOptions{}.masks.static_window_seconds, 8);
  // Windows shorter than the shortest span the check trusts would find still tissue.
  EXPECT_THROW(WithAssignments(FrontendOptions{}, {"masks.static_window_seconds=2"}), Error);
  EXPECT_THROW(WithAssignments(FrontendOptions{}, {"masks.static_window_seconds=0", "masks.static_min_seconds=0"}),
               Error);
}

TEST(JsonOptions, DropoutShareIsAFraction) {
  const TrackingOptions off = WithAssignments(TrackingOptions{}, {"min_tracked_fraction=0"});
  EXPECT_EQ(OptionsFromJson<TrackingOptions>(Json(off), "test").min_tracked_fraction, 0.0);
  EXPECT_THROW(WithAssignments(TrackingOptions{}, {"min_tracked_fraction=1.5"}), Error);
  EXPECT_THROW(WithAssignments(TrackingOptions{}, {"min_tracked_fraction=-0.1"}), Error);
  const TrackingOptions strict = WithAssignments(TrackingOptions{}, {"dropout_min_match_ssim=1"});
  EXPECT_EQ(OptionsFromJson<TrackingOptions>(Json(strict), "test").dropout_min_match_ssim, 1.0);
  EXPECT_THROW(WithAssignments(TrackingOptions{}, {"dropout_min_match_ssim=1.1"}), Error);
  EXPECT_THROW(WithAssignments(TrackingOptions{}, {"dropout_min_match_ssim=-0.5"}), Error);
}

TEST(JsonOptions, DbaModelSelectionThresholdsAreValidatedAndRoundTrip) {
  const MappingOptions options = WithAssignments(
      MappingOptions{}, {"dba_model_selection=false", "rigid_dba_min_inliers=0.99", "rigid_dba_min_baseline=0.5"});
  EXPECT_FALSE(options.dba_model_selection);
  EXPECT_EQ(Json(OptionsFromJson<MappingOptions>(Json(options), "test")), Json(options));
  EXPECT_THROW(WithAssignments(MappingOptions{}, {"rigid_dba_min_inliers=1.5"}), Error);  // a fraction
  EXPECT_THROW(WithAssignments(MappingOptions{}, {"rigid_dba_min_baseline=-0.1"}), Error);
}

TEST(JsonOptions, DeformableGateSpanOptionsAreValidated) {
  const MappingOptions shortest = WithAssignments(MappingOptions{}, {"deformable_gate_span=shortest"});
  EXPECT_EQ(OptionsFromJson<MappingOptions>(Json(shortest), "test").deformable_gate_span, "shortest");
  EXPECT_THROW(WithAssignments(MappingOptions{}, {"deformable_gate_span=longest"}), Error);
  EXPECT_THROW(WithAssignments(MappingOptions{}, {"shortest_gate_below_fraction=1.5"}), Error);
  EXPECT_EQ(WithAssignments(MappingOptions{}, {"shortest_gate_below_fraction=0"}).shortest_gate_below_fraction, 0.0);
}

TEST(JsonOptions, DeformableFitToleranceIsCeresDefaultAndAFraction) {
  EXPECT_EQ(MappingOptions{}.deformable_function_tolerance, 1e-6);
  const MappingOptions tight = WithAssignments(MappingOptions{}, {"deformable_function_tolerance=1e-14"});
  EXPECT_EQ(OptionsFromJson<MappingOptions>(Json(tight), "test").deformable_function_tolerance, 1e-14);
  EXPECT_THROW(WithAssignments(MappingOptions{}, {"deformable_function_tolerance=0"}), Error);
  EXPECT_THROW(WithAssignments(MappingOptions{}, {"deformable_function_tolerance=1"}), Error);
}

TEST(JsonOptions, OnlyMinusOneMeansToTheEndOfTheSequence) {
  EXPECT_EQ(WithAssignments(RunOptions{}, {"last_frame=-1"}).last_frame, -1);
  EXPECT_EQ(WithAssignments(RunOptions{}, {"first_frame=10", "last_frame=11"}).last_frame, 11);
  try {
    WithAssignments(RunOptions{}, {"last_frame=-5"});  // not "all but the last five"
    ADD_FAILURE() << "last_frame=-5 was accepted";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("-1 (to the end)"), std::string::npos) << error.what();
  }
  EXPECT_THROW(WithAssignments(RunOptions{}, {"first_frame=10", "last_frame=10"}), Error);  // empty range
}

TEST(JsonOptions, AFileThatIsNotJsonIsNamedWithWhatIsWrong) {
  const auto folder = UniqueTempFolder("json_file");
  std::filesystem::create_directories(folder);
  std::ofstream(folder / "bad.json") << "{\"k\": ";
  const auto message = [](const std::filesystem::path& file) {
    try {
      ReadJsonFile(file);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message(folder), folder.string() + " is a folder, not a JSON file");
  EXPECT_EQ(message(folder / "none.json"), "cannot open " + (folder / "none.json").string());
  EXPECT_EQ(message(folder / "bad.json").rfind((folder / "bad.json").string() + " is not valid JSON (", 0), 0u);
  std::filesystem::remove_all(folder);
}

}  // namespace
}  // namespace nrslam
