#include "nrslam/system/run_sequence.h"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <fstream>
#include <future>
#include <iomanip>
#include <optional>
#include <sstream>
#include <utility>

#include "nrslam/eval/depth_evaluation.h"
#include "nrslam/io/camera_file.h"
#include "nrslam/io/sequence_reader.h"
#include "nrslam/io/tum.h"
#include "nrslam/mapping/mapper.h"
#include "nrslam/mapping/monocular_initialiser.h"
#include "nrslam/system/static_regions.h"
#include "nrslam/tracking/tracker.h"
#include "nrslam/util/error.h"
#include "nrslam/util/memory_usage.h"
#include "nrslam/util/stopwatch.h"
#include "nrslam/util/text_file.h"
#include "nrslam/util/text_table.h"

namespace nrslam {
namespace fs = std::filesystem;
namespace {

// A calibration given for the run instead of the sequence's own: it must fit the images.
Camera CameraOverride(const fs::path& file, const SequenceReader& reader) {
  const Camera camera = ReadCameraFile(file);
  const Camera& own = reader.info().camera;
  if (camera.width() != own.width() || camera.height() != own.height()) {
    throw Error("run.camera " + file.string() + " is for " + std::to_string(camera.width()) + "x" +
                std::to_string(camera.height()) + " images, the sequence's are " + std::to_string(own.width()) + "x" +
                std::to_string(own.height()));
  }
  return camera;
}

void WritePly(const fs::path& path, const Map& map) {
  std::ofstream file = OpenForWriting(path);
  file << "ply\nformat ascii 1.0\nelement vertex " << map.size()
       << "\nproperty float x\nproperty float y\nproperty float z\n"
          "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  for (const MapPoint& point : map.points()) {
    file << point.position.x() << ' ' << point.position.y() << ' ' << point.position.z() << ' '
         << int(point.colour[2]) << ' ' << int(point.colour[1]) << ' ' << int(point.colour[0]) << '\n';
  }
  CloseWritten(file, path);
}

struct FrameImages {
  cv::Mat bgr, mask, depth_mm;
  std::string depth_problem;  // why depth_mm is empty although the sequence has depth
};

// An unreadable colour image or mask makes the frame unusable (thrown); an unreadable depth map
// only matters where depth is used, so it is reported beside the frame instead. The sequence's
// static regions on this frame are left out of its mask.
FrameImages ReadFrame(const SequenceReader& reader, int frame, const StaticRegions& static_regions) {
  FrameImages images;
  images.bgr = reader.ReadRgb(frame);
  images.mask = reader.ReadMask(frame);
  static_regions.LeaveOut(frame, &images.mask);
  if (reader.has_depth()) images.depth_mm = reader.TryReadDepthMm(frame, &images.depth_problem);
  return images;
}

// Decoding a frame's PNGs and encoding its depth map are a fifth of a tracking run's time and
// depend on nothing the tracker computes, so they run beside it, on the other core: the two
// frames after this one are read while it is processed (the tracker looks one ahead), and each
// depth map is written while the next frame is. Results are the same as when done in line;
// only the wall-clock time changes.
class FrameIo {
 public:
  FrameIo(const SequenceReader& reader, int first, int last, StaticRegions static_regions)
      : reader_(reader), static_regions_(std::move(static_regions)), next_(first), last_(last) {
    Prefetch();
    Prefetch();
  }

  // The frame's images (frames are taken in order); errors of reading it (a missing or corrupt
  // file) are thrown here.
  FrameImages Take() {
    std::shared_future<FrameImages> current = std::move(ahead_.front());
    ahead_.pop_front();
    Prefetch();
    return current.get();
  }
  // The colour image of the frame after the last one taken, for the tracker to look ahead;
  // empty when there is none or it cannot be read (Take reports that in its turn).
  cv::Mat PeekNextBgr() const {
    if (ahead_.empty()) return {};
    try {
      return ahead_.front().get().bgr;
    } catch (const Error&) {
      return {};
    }
  }

  // Writes the image after the previous write has finished; throws if that one failed.
  void Write(const fs::path& path, cv::Mat image) {
    Finish();
    write_ = std::async(std::launch::async, [path, image = std::move(image)] {
      if (!cv::imwrite(path.string(), image)) throw Error("cannot write " + path.string());
    });
  }
  void Finish() {
    if (write_.valid()) write_.get();
  }

 private:
  void Prefetch() {
    if (next_ < last_) {
      ahead_.push_back(
          std::async(std::launch::async, ReadFrame, std::cref(reader_), next_++, std::cref(static_regions_)).share());
    }
  }
  const SequenceReader& reader_;
  const StaticRegions static_regions_;
  int next_;  // the next frame to prefetch
  int last_;
  // Futures of std::async wait for their thread when the last one sharing it goes, so a run
  // that unwinds early leaves no thread behind.
  std::deque<std::shared_future<FrameImages>> ahead_;
  std::future<void> write_;
};

// Why a tracked frame whose ground truth was read has no score: "not scored: 3 of its 40 points
// on valid ground truth (evaluation.min_points = 5)".
std::string SparseGroundTruthNote(const FrameEvaluation& evaluation, const EvaluationOptions& options) {
  const int points = evaluation.points_used + evaluation.points_without_groundtruth;
  return "not scored: " + std::to_string(evaluation.points_used) + " of its " + std::to_string(points) +
         " points on valid ground truth (evaluation.min_points = " + std::to_string(options.min_points) + ")";
}

}  // namespace

RunSummary RunSequence(const fs::path& sequence, const SystemOptions& options, const fs::path& out,
                       const RunProgress& progress) {
  options.Check();
  const SequenceReader reader(sequence);
  if (options.run.init == "depth" && !reader.has_depth()) {
    throw Error("sequence " + sequence.string() + " has no depth/ folder: --init depth needs one");
  }
  const Camera camera = options.run.camera.empty() ? reader.info().camera : CameraOverride(options.run.camera, reader);
  const int first = std::min(options.run.first_frame, reader.frame_count());
  const int last = options.run.last_frame < 0 ? reader.frame_count() : std::min(options.run.last_frame, reader.frame_count());
  if (first >= last) {
    throw Error("run.first_frame " + std::to_string(options.run.first_frame) + " is past the last frame of " +
                sequence.string() + " (" + std::to_string(reader.frame_count()) + " frames, 0 to " +
                std::to_string(reader.frame_count() - 1) + ")");
  }

  RunFolderStreams streams =
      BeginRunFolder(out, sequence, {{"sequence_info", reader.info()}, {"camera", camera}, {"options", options}});
  std::ofstream& points_csv = streams.points;
  std::ofstream& metrics_csv = streams.metrics;
  std::ofstream log = OpenForWriting(out / "run.log");

  Tracker tracker(camera, options.frontend, options.deformation, options.tracking);
  tracker.EnableCandidates(options.run.mapping);
  Mapper mapper(camera, options.frontend, options.deformation, options.mapping, options.tracking.rigid);
  MonocularInitialiser initialiser(camera, options.frontend, options.tracking, options.initialisation);
  const bool monocular = options.run.init == "monocular";
  int maps = 0;  // maps started so far: a monocular run starts a new one after each loss
  // Each map numbers its points from 0; points.csv offsets them by the points of the run's
  // earlier maps, so that an id names one point of the whole run.
  int64_t id_base = 0;
  int64_t map_points = 0;  // points of the current map, as of the last frame tracked
  int map_start_frame = -1;  // the frame the current map started on: its points are not births
  // The current map's depth moved beyond run.restart_on_depth_change: the initialiser is
  // starting a new map from the images while the current one goes on tracking.
  bool replacing = false;
  BirthErrors births;
  MapDepthDrift depth_drift;
  double ms_initialisation = 0, ms_tracking = 0, ms_tracking_linear_solve = 0, ms_dba = 0, ms_triangulation = 0;
  RunSummary summary;
  summary.frames_total = last - first;
  summary.input.frames_past_end = std::max(0, options.run.last_frame - reader.frame_count());
  if (summary.input.frames_past_end > 0) log << PastEndText(summary.input.frames_past_end) << '\n';
  const auto start_map = [&](const FrameResult& started, const std::optional<Keyframe>& reference) {
    if (options.run.mapping) mapper.StartMap(started, tracker, reference);
    ++maps;
    id_base += map_points;
    map_points = 0;
    map_start_frame = started.frame;
    if (summary.init_frame < 0) summary.init_frame = started.frame;
  };
  // Initialises the frame by `attempt` when it succeeded (a monocular start, after a loss or
  // beside a map being replaced); otherwise leaves `result` alone.
  const auto start_from_images = [&](int frame, const cv::Mat& bgr, const cv::Mat& mask,
                                     const InitialisationAttempt& attempt, FrameResult* result) {
    if (!attempt.success) return;
    const int replaced = replacing ? maps : 0;
    *result = tracker.InitialiseFromSeed(frame, bgr, mask, attempt.map.seed);
    replacing = false;
    if (result->state != TrackingState::kTracking) return;
    start_map(*result, ReferenceKeyframe(attempt.map));
    log << "frame " << frame << ": map " << maps << " initialised from frames " << attempt.map.reference_frame << " and "
        << frame << (replaced > 0 ? ", replacing map " + std::to_string(replaced) : "") << ": " << attempt.note << "\n";
  };
  std::vector<FrameEvaluation> evaluations;
  std::vector<StampedPose> trajectory;
  std::vector<TrajectorySegment> aligned_maps;  // tracked camera centres per map, with their truth
  const auto start = Clock::now();
  StaticRegions static_regions = StaticRegions::OfSequence(reader, options.frontend.masks, first, last, log);
  summary.input.static_fraction = static_regions.Fraction();
  if (summary.input.static_fraction > 0) {
    const fs::path file = out / "static_mask.png";
    if (!cv::imwrite(file.string(), static_regions.Union())) throw Error("cannot write " + file.string());
    log << StaticRegionText(summary.input.static_fraction) << '\n';
  }
  FrameIo io(reader, first, last, std::move(static_regions));
  for (int frame = first; frame < last; ++frame) {
    FrameResult result;
    result.frame = frame;
    MappingReport mapping;
    cv::Mat depth_mm;
    std::string depth_problem;
    try {
      const FrameImages images = io.Take();
      const cv::Mat& bgr = images.bgr;
      const cv::Mat& mask = images.mask;
      depth_mm = images.depth_mm;
      depth_problem = images.depth_problem;
      InitialisationAttempt replacement;
      if (replacing && tracker.state() == TrackingState::kTracking) {
        const auto init_start = Clock::now();
        replacement = initialiser.Add(frame, bgr, mask);
        ms_initialisation += MillisecondsSince(init_start);
      }
      if (replacement.success) {
        start_from_images(frame, bgr, mask, replacement, &result);
      } else if (tracker.state() == TrackingState::kTracking) {
        result = tracker.Track(frame, bgr, mask, io.PeekNextBgr());
        if (result.state == TrackingState::kLost) {
          summary.input.frames_dropout += result.dropout;
          log << "frame " << frame << ": lost (" << result.note << ")\n";
        } else if (!result.note.empty()) {
          log << "frame " << frame << ": " << result.note << '\n';
        }
        summary.input.sudden_occlusions += result.sudden_occlusion;
        summary.input.view_jumps += result.view_jump;
        if (result.state == TrackingState::kTracking && options.run.mapping) {
          mapping = mapper.Process(result, bgr, mask, &tracker);
          result.cam_from_world = tracker.pose();  // the DBA may have refined it
          if (mapping.new_points > 0) log << "frame " << frame << ": " << mapping.new_points << " new points\n";
          // Windows whose model was chosen: by model selection, or a gated warm-up (no baseline test).
          const DbaReport& dba = mapping.dba_report;
          if (mapping.dba && (dba.baseline_ratio >= 0 || dba.rigid_inlier_fraction >= 0)) {
            std::ostringstream line;  // its precision stays with this line, not the whole log
            line << "frame " << frame << ": DBA " << (dba.rigid ? "rigid" : "deformable") << std::setprecision(3);
            if (dba.baseline_ratio >= 0) {
              line << " (baseline ratio " << dba.baseline_ratio << ", rigid inliers " << dba.rigid_inlier_fraction;
              if (dba.tracked_deformation >= 0) line << ", tracked deformation " << dba.tracked_deformation;
              line << ")\n";
            } else {
              line << " (warm-up, rigid inliers " << dba.rigid_inlier_fraction << ")\n";
            }
            log << line.str();
          }
        }
        // Once per keyframe: what neither tracking nor the DBA window holds is gone for good.
        if (result.keyframe) tracker.RetireDroppedPoints(mapper.WindowPoints());
      } else if (tracker.state() == TrackingState::kLost && !monocular && !options.run.reinitialise_after_loss) {
        result.state = TrackingState::kLost;
        result.note = "lost earlier; not re-initialised (run.reinitialise_after_loss=false)";
      } else if (monocular) {
        const auto init_start = Clock::now();
        const InitialisationAttempt attempt = initialiser.Add(frame, bgr, mask);
        ms_initialisation += MillisecondsSince(init_start);
        result.state = tracker.state();
        result.note = "initialising: " + attempt.note;
        start_from_images(frame, bgr, mask, attempt, &result);
      } else {
        if (!depth_problem.empty()) throw Error(depth_problem);
        result = tracker.InitialiseFromDepth(frame, bgr, depth_mm, mask);
        if (result.state == TrackingState::kTracking) {
          start_map(result, std::nullopt);
          log << "frame " << frame << ": map initialised from depth with " << result.points.size() << " points\n";
        }
      }
    } catch (const Error& e) {
      result.state = TrackingState::kLost;  // an unreadable frame: recorded, and the run goes on
      result.note = e.what();
      ++summary.input.frames_unreadable;
      if (summary.init_frame >= 0) ++summary.input.frames_unreadable_after_init;
      log << "frame " << frame << ": " << e.what() << '\n';
    }

    ms_tracking += result.ms_total;
    ms_tracking_linear_solve += result.ms_linear_solve;
    ms_dba += mapping.ms_dba;
    ms_triangulation += mapping.ms_triangulation;
    FrameEvaluation evaluation;
    std::vector<DepthPoint> depth_points;
    double median_depth = 0;
    const bool tracked = result.state == TrackingState::kTracking;
    if (tracked && !depth_problem.empty()) {
      // Tracked as if it were whole: only its score is missing, and the run says so.
      ++summary.input.frames_groundtruth_unreadable;
      const std::string not_scored = "not scored: " + depth_problem;
      log << "frame " << frame << ": " << not_scored << '\n';
      result.note = result.note.empty() ? not_scored : not_scored + "; " + result.note;
    }
    if (tracked) {
      trajectory.push_back({frame / reader.info().fps, result.cam_from_world.Inverse()});
      if (reader.has_groundtruth()) {
        aligned_maps.resize(static_cast<size_t>(maps));
        aligned_maps.back().estimated.push_back(trajectory.back().world_from_camera.translation);
        aligned_maps.back().groundtruth.push_back(
            reader.groundtruth()[static_cast<size_t>(frame)].world_from_camera.translation);
      }
      map_points = static_cast<int64_t>(tracker.map().size());
      std::vector<int64_t> ids;
      for (const TrackedPoint& point : result.points) {
        const Eigen::Vector3d world = tracker.map().point(point.id).position;
        const double z = (result.cam_from_world * world).z();
        depth_points.push_back({cv::Point2d(point.pixel.x, point.pixel.y), z});
        ids.push_back(id_base + point.id);
        WritePointsRow(points_csv, frame, ids.back(), point.pixel, z, world,
                       point.reassociated ? "reassociated" : "tracked");
      }
      median_depth = MedianDepth(depth_points);
      const DepthChange map_depth = depth_drift.AddFrame(maps, frame, median_depth);
      const double restart = options.run.restart_on_depth_change;
      if (monocular && restart > 0 && !replacing && map_depth.Beyond(restart)) {
        replacing = true;  // the initialiser's last attempt succeeded, so its next Add starts a reference
        ++summary.maps_given_up;
        depth_drift.GiveUp(maps);
        std::ostringstream given_up;
        given_up << std::setprecision(3) << "map " << maps << " given up: its median depth went ×" << map_depth.ratio
                 << " from its first frame (run.restart_on_depth_change = " << restart
                 << "); it tracks until a new one starts";
        log << "frame " << frame << ": " << given_up.str() << '\n';
        result.note = result.note.empty() ? given_up.str() : given_up.str() + "; " + result.note;
      }
      if (!depth_mm.empty()) {
        evaluation = EvaluateFrame(depth_points, depth_mm, options.evaluation);
        evaluation.map = maps;
        if (evaluation.points_used < options.evaluation.min_points) {
          ++summary.input.frames_sparse_groundtruth;
          const std::string not_scored = SparseGroundTruthNote(evaluation, options.evaluation);
          log << "frame " << frame << ": " << not_scored << '\n';
          result.note = result.note.empty() ? not_scored : not_scored + "; " + result.note;
        }
      }
      // Every tracked frame, with ground truth or not: a point is born once, where it first appears.
      births.AddFrame(ids, depth_points, depth_mm, evaluation, frame == map_start_frame);
      const cv::Size size(reader.info().camera.width(), reader.info().camera.height());
      io.Write(out / "depth" / FrameFileName(frame),
               SplatDepth(depth_points, evaluation.evaluated ? evaluation.scale : 1.0, size, reader.info().depth_unit_mm));
    }
    summary.CountFrame(frame, tracked, result.note);
    MetricsRow row;
    row.frame = frame;
    row.state = result.state;
    row.map = maps;
    row.points = result.points.size();
    row.klt_tracked = result.klt_tracked;
    row.candidates = result.candidates.size();
    row.outliers = result.outliers;
    row.propagated = result.propagated;
    row.reassociated = result.reassociated;
    row.rigid_candidates = mapping.rigid_candidates;
    row.deformable_candidates = mapping.deformable_candidates;
    row.new_points = mapping.new_points;
    row.new_point_depth_bias = mapping.new_point_depth_bias;
    row.batch_rejected = mapping.batch_rejected;
    row.Score(evaluation);
    row.ms_klt = result.ms_klt;
    row.ms_pose = result.ms_pose;
    row.ms_deformation = result.ms_deformation;
    row.ms_dba = mapping.ms_dba;
    row.ms_triangulation = mapping.ms_triangulation;
    row.ms_total = result.ms_total + mapping.ms_dba + mapping.ms_triangulation;
    row.ms_joint_solve = result.ms_joint_solve;
    row.ms_linear_solve = result.ms_linear_solve;
    row.median_depth = median_depth;
    row.note = result.note;
    WriteMetricsRow(metrics_csv, row);
    // A full disk shows here within a few frames, not after the whole run.
    if (points_csv.fail() || metrics_csv.fail()) {
      throw Error("cannot write the run's files in " + out.string() + " (is the disk full?)");
    }
    if (progress) {
      std::ostringstream line;
      line << "frame " << frame + 1 - first << "/" << summary.frames_total << "  " << ToString(result.state) << "  "
           << result.points.size() << " points";
      if (evaluation.evaluated) line << "  RMSE " << std::fixed << std::setprecision(2) << evaluation.rmse_mm << " mm";
      line << "  " << std::fixed << std::setprecision(1) << result.ms_total << " ms";
      progress(frame + 1 - first, summary.frames_total, line.str());
    }
    // Last used here, so its pairs move into the list kept for the alignments at the end.
    if (evaluation.evaluated) evaluations.push_back(std::move(evaluation));
  }
  io.Finish();
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  summary.fps = summary.frames_total / std::max(seconds, 1e-9);
  summary.peak_memory_mb = PeakResidentMemoryMb();
  summary.ms_initialisation = ms_initialisation / summary.frames_total;
  summary.ms_tracking = ms_tracking / summary.frames_total;
  summary.ms_tracking_linear_solve = ms_tracking_linear_solve / summary.frames_total;
  summary.ms_dba = ms_dba / summary.frames_total;
  summary.ms_triangulation = ms_triangulation / summary.frames_total;
  summary.maps = maps;
  summary.map_points = tracker.map().size();
  summary.map_depth = depth_drift.Change();
  AggregateInto(&summary, evaluations, aligned_maps, options.evaluation);
  summary.births = births.Summarise();

  CloseWritten(points_csv, out / "points.csv");
  CloseWritten(metrics_csv, out / "metrics.csv");
  CloseWritten(log, out / "run.log");
  WriteTum(out / "trajectory.tum", trajectory);
  WritePly(out / "map.ply", tracker.map());
  WriteSummaryJson(out / "summary.json", summary,
                   {{"init", options.run.init},
                    {"mapping", options.run.mapping},
                    {"mode", options.tracking.rigid ? "rigid" : "deformable"}});
  return summary;
}

}  // namespace nrslam
