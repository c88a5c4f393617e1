// system: the files of a run folder that every producer of one writes the same way (the
// runner, and the scorer of another system's output): points.csv's and metrics.csv's headers
// and rows, the estimated depth images, and summary.json with the run's aggregates and how it
// ended.
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "nrslam/eval/birth_errors.h"
#include "nrslam/eval/depth_evaluation.h"
#include "nrslam/eval/trajectory_error.h"
#include "nrslam/tracking/tracker.h"

namespace nrslam {

inline constexpr const char* kPointsCsvHeader = "frame,point_id,u,v,z_est,x,y,z,status";

// One row of points.csv: a point's pixel and camera depth (z_est) on a frame, its world
// position when the frame has a pose (else the three fields are empty), and its status
// ("tracked", "reassociated").
void WritePointsRow(std::ostream& out, int frame, int64_t id, const cv::Point2d& pixel, double depth,
                    const std::optional<Eigen::Vector3d>& world, const char* status);

// One frame's row of metrics.csv. The runner fills every field. The scorer of another system's
// output knows only the state, the map, the points and what the evaluator made of them; it
// leaves the tracker's and mapper's counts and timings at zero.
struct MetricsRow {
  int frame = 0;
  TrackingState state = TrackingState::kNotInitialised;
  int map = 0;
  size_t points = 0;
  int klt_tracked = 0;
  size_t candidates = 0;
  int outliers = 0, propagated = 0, reassociated = 0;
  int rigid_candidates = 0, deformable_candidates = 0, new_points = 0;
  double new_point_depth_bias = 0;  // MappingReport's
  bool batch_rejected = false;
  int points_without_groundtruth = 0;
  bool evaluated = false;  // false: scale 0 and the two RMSEs left empty
  double scale = 0, rmse_mm = 0, flat_rmse_mm = 0;
  double ms_klt = 0, ms_pose = 0, ms_deformation = 0, ms_dba = 0, ms_triangulation = 0;
  double ms_total = 0;  // tracking and mapping together
  double ms_joint_solve = 0, ms_linear_solve = 0;
  double median_depth = 0;  // map units; 0 (no points) is written empty
  std::string note;

  // The evaluator's figures for the frame.
  void Score(const FrameEvaluation& evaluation);
};

// metrics.csv's header line and one row in its columns, numbers at the stream's precision.
// Both come from one list of columns, so a column added to one is added to the other.
std::string MetricsCsvHeader();
void WriteMetricsRow(std::ostream& out, const MetricsRow& row);

// What the input did to a run, as the runner counts it in summary.json and the batch reads it
// back into results.json: files that could not be read, frames skipped or noted, ground truth
// too sparse to score, and the part of the image left out as never changing.
struct InputEffects {
  // Frames lost because their colour image or mask could not be read (the run goes on), and
  // tracked frames left unscored because their ground-truth depth file could not be read.
  int frames_unreadable = 0, frames_groundtruth_unreadable = 0;
  // Of frames_unreadable, those after the first map started: the batch's status tells them
  // apart from frames the system failed to track (batch/results.h, RunStatus).
  int frames_unreadable_after_init = 0;
  // Tracked frames whose ground truth was read but valid under fewer than the evaluator's
  // min_points of their points (depth missing over most of the view): not scored.
  int frames_sparse_groundtruth = 0;
  // Frames lost as image dropouts: skipped with the map kept (TrackingOptions::max_dropout_frames).
  int frames_dropout = 0;
  // Frames tracked although most of the view was hidden at once (FrameResult::sudden_occlusion):
  // one per occlusion, not per frame it lasts.
  int sudden_occlusions = 0;
  // Frames tracked although the view jumped (FrameResult::view_jump): frames missing from the
  // recording, or a jerk of the scope.
  int view_jumps = 0;
  // The share of the image left out on some frame because it never changed over the sequence
  // or a window of it (an on-screen display, an unmasked black border; system/static_regions.h,
  // margin included).
  double static_fraction = 0;
  // Another system's estimates (nrslam_eval score) whose pixel lies outside the image: left out.
  int estimates_outside_image = 0;
  // Of another system's scored frames, those whose estimates fall as the true depth rises
  // (DepthCorrelation below kInverseDepthCorrelation), recorded only when they are most of
  // them: inverse depth or disparity taken for depth.
  int frames_depth_inverted = 0;
  // Frames of the range asked for (run.last_frame) that lie past the sequence's end: the run
  // stops at its last frame, and a sweep or batch that meant a longer sequence can tell.
  int frames_past_end = 0;
  // One note each, those that apply, in the order the runner and nrslam_eval print them: a
  // range past the end, unreadable files, sparse ground truth, image dropouts, sudden
  // occlusions, jumps of the view, static regions, estimates outside the image, inverted depth.
  std::vector<std::string> Notes() const;
};
// Under the same flat keys in summary.json and in a results.json row; a key missing (results
// written before it existed) reads as none.
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(InputEffects, frames_unreadable, frames_groundtruth_unreadable,
                                                frames_unreadable_after_init, frames_sparse_groundtruth,
                                                frames_dropout, sudden_occlusions, view_jumps, static_fraction,
                                                estimates_outside_image, frames_depth_inverted, frames_past_end)

// A change of a map's median depth beyond this factor, either way, gets a note: more than the
// depth of an endoscopic scene changes over a sequence, less than a collapsing scale gives.
inline constexpr double kDepthChangeNoteFactor = 10;

// How far a map's depth moved in its own units, which needs no ground truth: the median depth
// of the points a frame reports (metrics.csv median_depth) at the map's last tracked frame over
// its first. A monocular map whose scale collapses (docs/mapping.md, "Long runs") shows it as a
// depth that falls by orders of magnitude, where the depth of a scene seen down a lumen or
// across a cavity stays within a few times.
struct DepthChange {
  double ratio = 0;      // 0: nothing tracked (or, read back, not recorded)
  int beyond_from = -1;  // the frame from which it stayed beyond kDepthChangeNoteFactor; -1: it did not
  // Whether the depth moved more than `factor` either way (never before a first depth).
  bool Beyond(double factor) const { return ratio > 0 && std::abs(std::log(ratio)) > std::log(factor); }
  // "the map's median depth went ×1.9e-06 from its first tracked frame to its last, beyond 10×
  // from frame 265 on (…)" when it ends beyond the factor; "" otherwise.
  std::string Note() const;
};

// Under flat keys in summary.json and a results.json row, null when not recorded:
// map_depth_change (ratio) and map_depth_change_beyond_from.
void to_json(nlohmann::json& json, const DepthChange& change);
void from_json(const nlohmann::json& json, DepthChange& change);

// The DepthChange of a run's maps, frame by frame.
class MapDepthDrift {
 public:
  // `median_depth` of tracked `frame` of `map`, frames in order; 0 (no point reported) or NaN is
  // passed over. Returns `map`'s change so far (ratio 0 before its first depth).
  DepthChange AddFrame(int map, int frame, double median_depth);
  // `map` was given up for its depth change (RunOptions::restart_on_depth_change); the run says
  // so in its own note (GivenUpText), so Change() passes it over.
  void GiveUp(int map);
  // Of the map not given up whose depth changed most (largest |log ratio|); ratio 0 when none.
  DepthChange Change() const;

 private:
  struct MapDepths {
    double first = 0;
    DepthChange change;
    bool given_up = false;
  };
  std::map<int, MapDepths> maps_;
};

// "2 maps given up as their median depth moved beyond run.restart_on_depth_change (…)"; "" when none.
std::string GivenUpText(int maps_given_up);
// What a run's maps did, one line each, as nrslam_run and nrslam_eval print it: its GivenUpText
// and its depth change's Note. Empty when neither has anything to say.
std::vector<std::string> MapNotes(int maps_given_up, const DepthChange& map_depth);

// The median depth of a frame's reported points (map units); 0 when there are none.
double MedianDepth(const std::vector<DepthPoint>& points);

struct RunSummary {
  double rmse_mm = 0, rmse_median_mm = 0, rmse_pooled_mm = 0;
  double rmse_flat_mm = 0;  // the same points all at one depth (eval/depth_evaluation.h)
  // The same frames at one scale per map, and at each frame's median ratio (OtherAlignments).
  double rmse_map_scale_mm = 0, rmse_median_scale_mm = 0;
  int frames_tracked = 0;  // frames with a pose after initialisation (the paper's "# Fr.")
  int frames_total = 0;
  int frames_lost = 0;
  int init_frame = -1;
  int frames_evaluated = 0;
  InputEffects input;  // what damaged or unusual input did to the run
  double fps = 0;          // frames processed per second of wall time (reading included)
  // The process's peak resident memory when the run ended (MB; util/memory_usage.h): the run's
  // own under nrslam_run and nrslam_eval, which give each sequence its own process. 0: not measured.
  double peak_memory_mb = 0;
  // Mean milliseconds per processed frame in each stage (the mapping stages run on some frames only).
  double ms_initialisation = 0, ms_tracking = 0, ms_dba = 0, ms_triangulation = 0;
  double ms_tracking_linear_solve = 0;  // of ms_tracking: the joint solves' linear solver
  TrajectoryError trajectory_error;  // camera centres aligned to the ground-truth poses per map
  BirthErrorSummary births;          // how far from the map's scale new points were born
  int maps = 0;            // maps started (a monocular run starts a new one after a loss or a give-up)
  size_t map_points = 0;   // points in the last map
  DepthChange map_depth;  // how far the map not given up that moved most drifted in depth (MapDepthDrift)
  int maps_given_up = 0;  // maps ended for their depth change (RunOptions::restart_on_depth_change)
  // A run that ends without tracking: the first frame of that final stretch and its note (why
  // it was lost); for a run that never initialised, the last frame's note. -1 and "" otherwise.
  int stop_frame = -1;
  std::string stop_reason;
  // "ok", "lost" (the run ends without tracking) or "not_initialised".
  std::string Status() const;
  // Counts one processed frame, tracked or not (`note`: why not): frames_tracked, frames_lost
  // and where the final untracked stretch began. Set init_frame first on the frame a map starts.
  void CountFrame(int frame, bool tracked, const std::string& note);
};

// How a run that ends without tracking stopped: "lost from frame 12: only 7 points left after
// outlier rejection" or "never initialised: …"; "" when `reason` is empty (it ends tracking).
std::string DescribeStop(int init_frame, int stop_frame, const std::string& reason);

// "80 frames of the range asked for (run.last_frame) lie past the sequence's end: the run
// stopped at its last frame"; "" when none.
std::string PastEndText(int frames_past_end);

// What damaged input cost a run, e.g. "1 frame unreadable (lost); ground-truth depth unreadable
// on 2 tracked frames (not scored); metrics.csv names the files"; "" when nothing.
std::string UnreadableInputText(int frames_unreadable, int frames_groundtruth_unreadable);

// "3 tracked frames not scored: too few of their points on valid ground truth (under
// evaluation.min_points)"; "" when none.
std::string SparseGroundTruthText(int frames_sparse_groundtruth);

// "2 frames skipped as image dropouts (lost; the map kept)"; "" when none.
std::string DropoutText(int frames_dropout);

// "2 sudden occlusions: most of the view hidden at once, the tracks left matching well (the
// frames used; metrics.csv notes them)"; "" when none.
std::string OcclusionText(int sudden_occlusions);

// "1 jump of the view: its tracks moved far more than over the frames before (frames missing
// from the recording, or a jerk of the scope; metrics.csv notes them)"; "" when none.
std::string ViewJumpText(int view_jumps);

// "9.9 % of the image never changed (an on-screen display, a black border or background) and
// was left out (static_mask.png)"; "" when none.
std::string StaticRegionText(double static_fraction);

// "3 estimates lay outside the image and were left out (u and v are the image's pixels, u
// across and v down)", of another system's output; "" when none.
std::string OutsideImageText(int estimates_outside_image);

// A frame's estimates whose correlation with the true depth is below this fall as it rises;
// depth at any scale correlates near +1, a poor estimate near 0.
inline constexpr double kInverseDepthCorrelation = -0.5;

// "57 scored frames have estimates that fall as the true depth rises: inverse depth or
// disparity (as depth networks write) must be turned into depth first"; "" when none.
std::string InvertedDepthText(int frames_depth_inverted);

// The summary's figures: the depth aggregates of the evaluated frames (each with its pairs and
// map, as EvaluateFrame and the caller left them) and the trajectory error of the tracked
// camera centres (one segment per map).
void AggregateInto(RunSummary* summary, const std::vector<FrameEvaluation>& frames,
                   const std::vector<TrajectorySegment>& maps, const EvaluationOptions& options);

// A run folder begun: an earlier run's files in `out` removed (summary.json first; other
// files are left alone), `out` and `out`/depth created, config.json written (the version, the
// sequence's absolute path, then `config`'s keys), points.csv and metrics.csv opened with
// their headers. Throws Error if any of it cannot be written, or if `out` holds a sequence.
struct RunFolderStreams {
  std::ofstream points, metrics;
};
RunFolderStreams BeginRunFolder(const std::filesystem::path& out, const std::filesystem::path& sequence,
                                const nlohmann::json& config);

// What a run did, in one or two lines (as nrslam_run prints it): frames tracked, RMSE,
// trajectory error, fps (when measured), and how it stopped.
std::string DescribeSummary(const RunSummary& summary);

// A text file for the run folder, numbers at 9 significant digits; throws Error if it cannot be opened.
std::ofstream OpenForWriting(const std::filesystem::path& path);

// Estimated depth image: each point a 3x3 splat of its depth times `to_mm` (the frame's scale
// when it was evaluated), 16-bit in `unit_mm`.
cv::Mat SplatDepth(const std::vector<DepthPoint>& points, double to_mm, const cv::Size& size, double unit_mm);

// summary.json: the summary's figures under the key names of design §5, plus `provenance`'s
// keys (how the run was made: init, mapping, mode).
void WriteSummaryJson(const std::filesystem::path& path, const RunSummary& summary, const nlohmann::json& provenance);

}  // namespace nrslam
