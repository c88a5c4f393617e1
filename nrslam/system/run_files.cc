#include "nrslam/system/run_files.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "nrslam/io/depth_encoding.h"
#include "nrslam/util/csv.h"
#include "nrslam/util/error.h"
#include "nrslam/util/folder.h"
#include "nrslam/util/median.h"
#include "nrslam/util/source_revision.h"
#include "nrslam/util/text_file.h"
#include "nrslam/util/text_table.h"

namespace nrslam {

std::string DescribeStop(int init_frame, int stop_frame, const std::string& reason) {
  if (reason.empty()) return "";
  if (init_frame < 0) return "never initialised: " + reason;
  return "lost from frame " + std::to_string(stop_frame) + ": " + reason;
}

std::string UnreadableInputText(int frames_unreadable, int frames_groundtruth_unreadable) {
  const auto plural = [](int count) { return count == 1 ? "" : "s"; };
  std::string text;
  if (frames_unreadable > 0) {
    text = std::to_string(frames_unreadable) + " frame" + plural(frames_unreadable) + " unreadable (lost)";
  }
  if (frames_groundtruth_unreadable > 0) {
    text += (text.empty() ? "" : "; ") + std::string("ground-truth depth unreadable on ") +
            std::to_string(frames_groundtruth_unreadable) + " tracked frame" + plural(frames_groundtruth_unreadable) +
            " (not scored)";
  }
  return text.empty() ? text : text + "; metrics.csv names the files";
}

std::string SparseGroundTruthText(int frames_sparse_groundtruth) {
  if (frames_sparse_groundtruth == 0) return "";
  return std::to_string(frames_sparse_groundtruth) +
         (frames_sparse_groundtruth == 1 ? " tracked frame" : " tracked frames") +
         " not scored: too few of their points on valid ground truth (under evaluation.min_points)";
}

std::string DropoutText(int frames_dropout) {
  if (frames_dropout == 0) return "";
  return std::to_string(frames_dropout) +
         (frames_dropout == 1 ? " frame skipped as an image dropout" : " frames skipped as image dropouts") +
         " (lost; the map kept)";
}

std::string OcclusionText(int sudden_occlusions) {
  if (sudden_occlusions == 0) return "";
  return std::to_string(sudden_occlusions) + (sudden_occlusions == 1 ? " sudden occlusion" : " sudden occlusions") +
         ": most of the view hidden at once, the tracks left matching well (the frames used; metrics.csv notes them)";
}

std::string PastEndText(int frames_past_end) {
  if (frames_past_end == 0) return "";
  return std::to_string(frames_past_end) + (frames_past_end == 1 ? " frame" : " frames") +
         " of the range asked for (run.last_frame) " + (frames_past_end == 1 ? "lies" : "lie") +
         " past the sequence's end: the run stopped at its last frame";
}

std::string ViewJumpText(int view_jumps) {
  if (view_jumps == 0) return "";
  return std::to_string(view_jumps) + (view_jumps == 1 ? " jump of the view" : " jumps of the view") +
         ": its tracks moved far more than over the frames before (frames missing from the recording, or a jerk "
         "of the scope; metrics.csv notes them)";
}

std::string OutsideImageText(int estimates_outside_image) {
  if (estimates_outside_image == 0) return "";
  return std::to_string(estimates_outside_image) +
         (estimates_outside_image == 1 ? " estimate lay outside the image and was"
                                       : " estimates lay outside the image and were") +
         " left out (u and v are the image's pixels, u across and v down)";
}

std::string InvertedDepthText(int frames_depth_inverted) {
  if (frames_depth_inverted == 0) return "";
  return std::to_string(frames_depth_inverted) +
         (frames_depth_inverted == 1 ? " scored frame has" : " scored frames have") +
         " estimates that fall as the true depth rises (correlation below " +
         FormatFixed(kInverseDepthCorrelation, 1) +
         "): inverse depth or disparity (as depth networks write) must be turned into depth first";
}

std::string StaticRegionText(double static_fraction) {
  if (static_fraction <= 0) return "";
  std::ostringstream text;
  text << std::fixed << std::setprecision(1) << 100 * static_fraction
       << " % of the image never changed (an on-screen display, a black border or background) and was left out"
          " (static_mask.png)";
  return text.str();
}

std::string DepthChange::Note() const {
  if (beyond_from < 0) return "";
  std::ostringstream text;
  text << std::setprecision(2) << "the map's median depth went ×" << ratio
       << " from its first tracked frame to its last, beyond " << kDepthChangeNoteFactor << "× from frame "
       << beyond_from
       << " on (map units; metrics.csv median_depth): its scale has drifted that far unless the scene's depth "
          "changed as much";
  return text.str();
}

std::string GivenUpText(int maps_given_up) {
  if (maps_given_up == 0) return "";
  const bool one = maps_given_up == 1;
  return std::to_string(maps_given_up) + (one ? " map given up as its" : " maps given up as their") +
         " median depth moved beyond run.restart_on_depth_change, " + (one ? "" : "each ") +
         "replaced by a new one started from the images while it tracked on (run.log names the frames)";
}

std::vector<std::string> MapNotes(int maps_given_up, const DepthChange& map_depth) {
  std::vector<std::string> notes;
  for (std::string note : {GivenUpText(maps_given_up), map_depth.Note()}) {
    if (!note.empty()) notes.push_back(std::move(note));
  }
  return notes;
}

void to_json(nlohmann::json& json, const DepthChange& change) {
  const nlohmann::json none;
  json = {{"map_depth_change", change.ratio > 0 ? nlohmann::json(change.ratio) : none},
          {"map_depth_change_beyond_from", change.beyond_from >= 0 ? nlohmann::json(change.beyond_from) : none}};
}

void from_json(const nlohmann::json& json, DepthChange& change) {
  const auto number = [&json](const char* key, double none) {
    const auto found = json.find(key);
    return found != json.end() && found->is_number() ? found->get<double>() : none;
  };
  change.ratio = number("map_depth_change", 0);
  change.beyond_from = static_cast<int>(number("map_depth_change_beyond_from", -1));
}

DepthChange MapDepthDrift::AddFrame(int map, int frame, double median_depth) {
  if (!(median_depth > 0)) {  // NaN too: another system's output may hold anything
    const auto found = maps_.find(map);
    return found == maps_.end() ? DepthChange{} : found->second.change;
  }
  MapDepths& depths = maps_.try_emplace(map, MapDepths{median_depth, {}}).first->second;
  depths.change.ratio = median_depth / depths.first;
  if (!depths.change.Beyond(kDepthChangeNoteFactor)) {
    depths.change.beyond_from = -1;
  } else if (depths.change.beyond_from < 0) {
    depths.change.beyond_from = frame;
  }
  return depths.change;
}

void MapDepthDrift::GiveUp(int map) {
  const auto found = maps_.find(map);  // a map is given up only for a depth it has recorded
  if (found != maps_.end()) found->second.given_up = true;
}

DepthChange MapDepthDrift::Change() const {
  DepthChange most;
  for (const auto& [map, depths] : maps_) {
    if (depths.given_up) continue;
    if (most.ratio == 0 || std::abs(std::log(depths.change.ratio)) > std::abs(std::log(most.ratio))) {
      most = depths.change;
    }
  }
  return most;
}

double MedianDepth(const std::vector<DepthPoint>& points) {
  if (points.empty()) return 0;
  std::vector<double> depths;
  depths.reserve(points.size());
  for (const DepthPoint& point : points) depths.push_back(point.depth);
  return MedianInPlace(&depths);
}

std::vector<std::string> InputEffects::Notes() const {
  std::vector<std::string> notes;
  for (std::string note : {PastEndText(frames_past_end), UnreadableInputText(frames_unreadable, frames_groundtruth_unreadable),
                           SparseGroundTruthText(frames_sparse_groundtruth), DropoutText(frames_dropout),
                           OcclusionText(sudden_occlusions), ViewJumpText(view_jumps),
                           StaticRegionText(static_fraction), OutsideImageText(estimates_outside_image),
                           InvertedDepthText(frames_depth_inverted)}) {
    if (!note.empty()) notes.push_back(std::move(note));
  }
  return notes;
}

std::string RunSummary::Status() const {
  if (init_frame < 0) return "not_initialised";
  return stop_frame >= 0 ? "lost" : "ok";
}

void RunSummary::CountFrame(int frame, bool tracked, const std::string& note) {
  if (tracked) {
    ++frames_tracked;
    stop_frame = -1;
    stop_reason.clear();
    return;
  }
  if (init_frame >= 0) ++frames_lost;
  if (stop_frame < 0 || init_frame < 0) {
    // Where the final untracked stretch began; before any map, the latest reason is the one that matters.
    if (stop_frame < 0) stop_frame = frame;
    stop_reason = note;
  }
}

std::string DescribeSummary(const RunSummary& summary) {
  std::ostringstream text;
  text << "frames tracked " << summary.frames_tracked << "/" << summary.frames_total << " (init at " << summary.init_frame
       << ", lost " << summary.frames_lost << ")  ";
  if (summary.frames_evaluated > 0) {
    // Rounded as the results table rounds them; summary.json keeps every digit.
    text << "RMSE mean " << FormatFixed(summary.rmse_mm, 3) << " mm, median " << FormatFixed(summary.rmse_median_mm, 3)
         << " mm (flat map " << FormatFixed(summary.rmse_flat_mm, 3) << " mm; one scale per map "
         << FormatFixed(summary.rmse_map_scale_mm, 3) << " mm)  ";
  } else if (summary.frames_tracked == 0) {
    text << "no frame tracked, no RMSE  ";
  } else if (summary.input.frames_sparse_groundtruth > 0) {
    text << "no RMSE: the ground truth is too sparse to score any frame  ";
  } else {
    text << "no ground truth, no RMSE  ";
  }
  if (summary.trajectory_error.evaluated) {
    text << "trajectory error " << FormatFixed(summary.trajectory_error.rmse_mm, 3) << " mm  ";
  }
  if (summary.births.mean) {
    text << "new points born at log depth error " << FormatFixed(*summary.births.mean, 3) << " (median "
         << FormatFixed(*summary.births.median, 3) << ", " << summary.births.births_evaluated << " points)  ";
  }
  if (summary.fps > 0) text << FormatFixed(summary.fps, 1) << " fps";
  if (summary.peak_memory_mb > 0) text << "  peak memory " << std::lround(summary.peak_memory_mb) << " MB";
  const std::string stop = DescribeStop(summary.init_frame, summary.stop_frame, summary.stop_reason);
  if (!stop.empty()) text << '\n' << stop;
  for (const std::string& note : MapNotes(summary.maps_given_up, summary.map_depth)) text << '\n' << note;
  for (const std::string& note : summary.input.Notes()) {
    text << '\n' << note;
  }
  return text.str();
}

void AggregateInto(RunSummary* summary, const std::vector<FrameEvaluation>& frames,
                   const std::vector<TrajectorySegment>& maps, const EvaluationOptions& options) {
  const SequenceMetrics metrics = AggregateFrames(frames);
  summary->rmse_mm = metrics.rmse_mm;
  summary->rmse_median_mm = metrics.rmse_median_mm;
  summary->rmse_pooled_mm = metrics.rmse_pooled_mm;
  summary->rmse_flat_mm = metrics.rmse_flat_mm;
  summary->frames_evaluated = metrics.frames_evaluated;
  const OtherAlignments other = EvaluateOtherAlignments(frames, options);
  summary->rmse_map_scale_mm = other.rmse_map_scale_mm;
  summary->rmse_median_scale_mm = other.rmse_median_scale_mm;
  summary->trajectory_error = AlignedTrajectoryError(maps);
}

void WritePointsRow(std::ostream& out, int frame, int64_t id, const cv::Point2d& pixel, double depth,
                    const std::optional<Eigen::Vector3d>& world, const char* status) {
  out << frame << ',' << id << ',' << pixel.x << ',' << pixel.y << ',' << depth << ',';
  if (world) {
    out << world->x() << ',' << world->y() << ',' << world->z();
  } else {
    out << ",,";
  }
  out << ',' << status << '\n';
}

namespace {

struct MetricsColumn {
  const char* name;
  void (*write)(std::ostream& out, const MetricsRow& row);
};

// metrics.csv's columns in their order. The RMSEs are at 6 decimals (std::to_string), as the
// file has always held them, whatever the stream's precision.
const MetricsColumn kMetricsColumns[] = {
    {"frame", [](std::ostream& out, const MetricsRow& row) { out << row.frame; }},
    {"state", [](std::ostream& out, const MetricsRow& row) { out << ToString(row.state); }},
    {"map", [](std::ostream& out, const MetricsRow& row) { out << row.map; }},
    {"points", [](std::ostream& out, const MetricsRow& row) { out << row.points; }},
    {"klt_tracked", [](std::ostream& out, const MetricsRow& row) { out << row.klt_tracked; }},
    {"candidates", [](std::ostream& out, const MetricsRow& row) { out << row.candidates; }},
    {"outliers", [](std::ostream& out, const MetricsRow& row) { out << row.outliers; }},
    {"propagated", [](std::ostream& out, const MetricsRow& row) { out << row.propagated; }},
    {"reassociated", [](std::ostream& out, const MetricsRow& row) { out << row.reassociated; }},
    {"rigid_candidates", [](std::ostream& out, const MetricsRow& row) { out << row.rigid_candidates; }},
    {"deformable_candidates", [](std::ostream& out, const MetricsRow& row) { out << row.deformable_candidates; }},
    {"new_points", [](std::ostream& out, const MetricsRow& row) { out << row.new_points; }},
    {"new_point_depth_bias", [](std::ostream& out, const MetricsRow& row) { out << row.new_point_depth_bias; }},
    {"batch_rejected", [](std::ostream& out, const MetricsRow& row) { out << (row.batch_rejected ? 1 : 0); }},
    {"points_without_gt", [](std::ostream& out, const MetricsRow& row) { out << row.points_without_groundtruth; }},
    {"scale", [](std::ostream& out, const MetricsRow& row) { out << (row.evaluated ? row.scale : 0.0); }},
    {"rmse_mm",
     [](std::ostream& out, const MetricsRow& row) {
       if (row.evaluated) out << std::to_string(row.rmse_mm);
     }},
    {"rmse_flat_mm",
     [](std::ostream& out, const MetricsRow& row) {
       if (row.evaluated) out << std::to_string(row.flat_rmse_mm);
     }},
    {"ms_klt", [](std::ostream& out, const MetricsRow& row) { out << row.ms_klt; }},
    {"ms_pose", [](std::ostream& out, const MetricsRow& row) { out << row.ms_pose; }},
    {"ms_deformation", [](std::ostream& out, const MetricsRow& row) { out << row.ms_deformation; }},
    {"ms_dba", [](std::ostream& out, const MetricsRow& row) { out << row.ms_dba; }},
    {"ms_triangulation", [](std::ostream& out, const MetricsRow& row) { out << row.ms_triangulation; }},
    {"ms_total", [](std::ostream& out, const MetricsRow& row) { out << row.ms_total; }},
    {"ms_joint_solve", [](std::ostream& out, const MetricsRow& row) { out << row.ms_joint_solve; }},
    {"ms_linear_solve", [](std::ostream& out, const MetricsRow& row) { out << row.ms_linear_solve; }},
    // At the stream's 9 digits: a collapsed map's depths are tiny.
    {"median_depth",
     [](std::ostream& out, const MetricsRow& row) {
       if (row.median_depth > 0) out << row.median_depth;
     }},
    {"note", [](std::ostream& out, const MetricsRow& row) { out << CsvField(row.note); }},
};

}  // namespace

void MetricsRow::Score(const FrameEvaluation& evaluation) {
  points_without_groundtruth = evaluation.points_without_groundtruth;
  evaluated = evaluation.evaluated;
  scale = evaluation.scale;
  rmse_mm = evaluation.rmse_mm;
  flat_rmse_mm = evaluation.flat_rmse_mm;
}

std::string MetricsCsvHeader() {
  std::string header;
  for (const MetricsColumn& column : kMetricsColumns) {
    if (!header.empty()) header += ',';
    header += column.name;
  }
  return header;
}

void WriteMetricsRow(std::ostream& out, const MetricsRow& row) {
  bool first = true;
  for (const MetricsColumn& column : kMetricsColumns) {
    if (!first) out << ',';
    first = false;
    column.write(out, row);
  }
  out << '\n';
}

RunFolderStreams BeginRunFolder(const std::filesystem::path& out, const std::filesystem::path& sequence,
                                const nlohmann::json& config) {
  // A sequence's own folder (`--out` given the sequence's path, say) would have its ground-truth
  // depth/ replaced by the run's estimates.
  if (std::filesystem::exists(out / "sequence.json")) {
    throw Error(out.string() + " holds a sequence (sequence.json): a run written there would replace its depth/ "
                "with the run's estimates; write the run to another folder");
  }
  CreateFolder(out);
  std::error_code error;
  // An earlier run's output in the same folder goes first, its summary before anything else: a
  // run that stops early must not leave the last run's result beside its own configuration,
  // nor a shorter run the longer run's depth maps.
  for (const char* file : {"summary.json", "trajectory.tum", "map.ply", "run.log", "static_mask.png", "depth"}) {
    std::filesystem::remove_all(out / file, error);
    if (error) throw Error("cannot remove the earlier run's " + (out / file).string() + ": " + error.message());
  }
  CreateFolder(out / "depth");
  {
    nlohmann::json written{{"nrslam_version", NRSLAM_VERSION},
                           {"nrslam_revision", SourceRevision()},
                           {"nrslam_code", CodeFingerprint()},
                           {"sequence", std::filesystem::absolute(sequence).string()}};
    written.update(config);
    WriteTextFile(out / "config.json", written.dump(2) + '\n');
  }
  RunFolderStreams streams{OpenForWriting(out / "points.csv"), OpenForWriting(out / "metrics.csv")};
  streams.points << kPointsCsvHeader << '\n';
  streams.metrics << MetricsCsvHeader() << '\n';
  return streams;
}

std::ofstream OpenForWriting(const std::filesystem::path& path) {
  std::ofstream file(path);
  if (!file) throw Error("cannot write " + path.string());
  file << std::setprecision(9);
  return file;
}

cv::Mat SplatDepth(const std::vector<DepthPoint>& points, double to_mm, const cv::Size& size, double unit_mm) {
  cv::Mat depth = cv::Mat::zeros(size, CV_16UC1);
  for (const DepthPoint& point : points) {
    const uint16_t value = DepthUnitsOrNone(to_mm * point.depth / unit_mm);
    if (value == 0) continue;
    const int cx = cvRound(point.pixel.x), cy = cvRound(point.pixel.y);
    for (int y = std::max(0, cy - 1); y <= std::min(size.height - 1, cy + 1); ++y) {
      for (int x = std::max(0, cx - 1); x <= std::min(size.width - 1, cx + 1); ++x) {
        depth.at<uint16_t>(y, x) = value;
      }
    }
  }
  return depth;
}

void WriteSummaryJson(const std::filesystem::path& path, const RunSummary& summary, const nlohmann::json& provenance) {
  const TrajectoryError& trajectory_error = summary.trajectory_error;
  nlohmann::json json{{"rmse_mm", summary.rmse_mm},
                      {"rmse_median_mm", summary.rmse_median_mm},
                      {"rmse_pooled_mm", summary.rmse_pooled_mm},
                      {"rmse_flat_mm", summary.rmse_flat_mm},
                      {"rmse_map_scale_mm", summary.rmse_map_scale_mm},
                      {"rmse_median_scale_mm", summary.rmse_median_scale_mm},
                      {"frames_tracked", summary.frames_tracked},
                      {"frames_total", summary.frames_total},
                      {"frames_lost", summary.frames_lost},
                      {"frames_evaluated", summary.frames_evaluated},
                      {"init_frame", summary.init_frame},
                      {"fps", summary.fps},
                      {"peak_memory_mb", summary.peak_memory_mb > 0 ? nlohmann::json(summary.peak_memory_mb) : nlohmann::json()},
                      {"ms_per_frame", {{"initialisation", summary.ms_initialisation},
                                        {"tracking", summary.ms_tracking},
                                        {"tracking_linear_solve", summary.ms_tracking_linear_solve},
                                        {"dba", summary.ms_dba},
                                        {"triangulation", summary.ms_triangulation}}},
                      {"maps", summary.maps},
                      // null without ground-truth poses or a moving camera
                      {"ate_rmse_mm", trajectory_error.evaluated ? nlohmann::json(trajectory_error.rmse_mm) : nlohmann::json()},
                      {"ate_scale", trajectory_error.evaluated ? nlohmann::json(trajectory_error.scale) : nlohmann::json()},
                      {"ate_frames", trajectory_error.poses},
                      // null without new points scored (eval/birth_errors.h)
                      {"births_evaluated", summary.births.births_evaluated},
                      {"birth_log_error_mean", summary.births.mean ? nlohmann::json(*summary.births.mean) : nlohmann::json()},
                      {"birth_log_error_median", summary.births.median ? nlohmann::json(*summary.births.median) : nlohmann::json()},
                      {"map_points", summary.map_points},
                      {"maps_given_up", summary.maps_given_up}};
  json.update(nlohmann::json(summary.map_depth));
  json.update(nlohmann::json(summary.input));
  json.update(provenance);
  json["status"] = summary.Status();
  json["stop_frame"] = summary.stop_frame >= 0 ? nlohmann::json(summary.stop_frame) : nlohmann::json();
  json["stop_reason"] = summary.stop_frame >= 0 ? nlohmann::json(summary.stop_reason) : nlohmann::json();
  // Whole or not at all: a folder with summary.json holds a finished run (nrslam_eval reuses it).
  WriteTextFile(path, json.dump(2) + '\n');
}

}  // namespace nrslam
