#include "nrslam/system/external_result.h"

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <utility>
#include <vector>

#include "nrslam/camera/camera.h"
#include "nrslam/io/sequence_info.h"
#include "nrslam/io/sequence_reader.h"
#include "nrslam/io/tum.h"
#include "nrslam/tracking/tracker.h"
#include "nrslam/util/csv.h"
#include "nrslam/util/error.h"
#include "nrslam/util/text_file.h"

namespace nrslam {
namespace fs = std::filesystem;
namespace {

struct EstimatedPoint {
  int64_t id;
  cv::Point2d pixel;
  double depth;
};
using FrameEstimates = std::map<int, std::vector<EstimatedPoint>>;

// The whole field as a number, or nullopt ("nan" and "inf" parse: they are estimates a system
// failed to make, not a malformed file).
std::optional<double> ParseNumber(const std::string& field) {
  const char* begin = field.c_str();
  char* end = nullptr;
  const double value = std::strtod(begin, &end);
  if (end == begin) return std::nullopt;
  while (*end != '\0' && std::isspace(static_cast<unsigned char>(*end))) ++end;
  if (*end != '\0') return std::nullopt;
  return value;
}

void CheckFrame(double frame, int frame_count, const std::string& where) {
  if (!(frame >= 0 && frame < frame_count && frame == std::floor(frame))) {
    std::ostringstream message;
    message << where << ": frame " << frame << " is not a frame of the sequence (0 … " << frame_count - 1 << ")";
    throw Error(message.str());
  }
}

// Refuses estimates whose pixels cannot be the image's: more than a tenth outside it (u and v
// swapped put a quarter of a 4:3 view's outside, another image size more), or all within two
// pixels (normalised coordinates). Scored, they would give the error against the wrong pixels'
// ground truth, or none, without a word. A few outside (a system that reports points leaving
// the view) are left out and counted.
void CheckPixelsAreTheImages(const fs::path& file, const std::vector<cv::Point2d>& pixels, int outside,
                             const Camera& camera) {
  if (pixels.empty()) return;
  cv::Point2d low = pixels.front(), high = pixels.front();
  for (const cv::Point2d& pixel : pixels) {
    low = {std::min(low.x, pixel.x), std::min(low.y, pixel.y)};
    high = {std::max(high.x, pixel.x), std::max(high.y, pixel.y)};
  }
  std::ostringstream where;
  where << std::fixed << std::setprecision(1) << "u " << low.x << " … " << high.x << ", v " << low.y << " … "
        << high.y;
  const std::string expected = "u and v are expected in the image's pixels, u across and v down, (0,0) the centre "
                               "of the top-left pixel";
  const std::string count = std::to_string(pixels.size());
  if (10 * static_cast<size_t>(outside) > pixels.size()) {
    throw Error(file.string() + ": " + std::to_string(outside) + " of its " + count + " estimates lie outside the " +
                std::to_string(camera.width()) + "x" + std::to_string(camera.height()) + " image (" + where.str() +
                "): " + expected);
  }
  constexpr size_t kFewestToJudgeSpread = 10;
  if (pixels.size() >= kFewestToJudgeSpread && high.x - low.x < 2 && high.y - low.y < 2) {
    throw Error(file.string() + ": all " + count + " estimates lie within two pixels of each other (" + where.str() +
                "): " + expected + ", not normalised coordinates");
  }
}

// `has_point_ids`: whether the file has its own point_id column (else ids number rows).
// `outside`: the estimates left out because their pixel lies outside the image.
FrameEstimates ReadPointsCsv(const fs::path& file, int frame_count, const Camera& camera, bool* has_point_ids,
                             int* outside) {
  std::ifstream in = OpenToRead(file, "CSV file");
  int line = 0;
  std::vector<std::string> header, fields;
  if (!ReadCsvRecord(in, file.string(), &line, &header)) {
    throw Error(file.string() + " is empty: a header line is expected");
  }
  std::map<std::string, size_t> column;
  // "frame, u, v, z" (numpy's savetxt with ", ") names frame, u, v and z.
  for (std::string& name : header) {
    const size_t first = name.find_first_not_of(' '), last = name.find_last_not_of(' ');
    name = first == std::string::npos ? std::string() : name.substr(first, last - first + 1);
  }
  for (size_t i = 0; i < header.size(); ++i) column.emplace(header[i], i);
  const auto require = [&](const std::string& name) {
    if (!column.count(name)) throw Error(file.string() + ": no column '" + name + "' in its header (frame, u, v and z are needed)");
    return column.at(name);
  };
  // A run's own points.csv has both: z_est is the camera depth, z the world coordinate.
  const size_t frame_column = require("frame"), u_column = require("u"), v_column = require("v"),
               z_column = column.count("z_est") ? column.at("z_est") : require("z");
  const bool has_ids = column.count("point_id") > 0;
  *has_point_ids = has_ids;
  const size_t id_column = has_ids ? column.at("point_id") : 0;
  const size_t needed = std::max({frame_column, u_column, v_column, z_column, id_column}) + 1;
  FrameEstimates estimates;
  std::vector<cv::Point2d> pixels;
  std::set<std::pair<int, int64_t>> ids_seen;  // frame, point_id
  *outside = 0;
  while (ReadCsvRecord(in, file.string(), &line, &fields)) {
    const std::string where = file.string() + ":" + std::to_string(line);
    if (fields.size() < needed) {
      throw Error(where + ": " + std::to_string(fields.size()) + " fields, the header needs " + std::to_string(needed));
    }
    const auto number = [&](size_t index) {
      const std::optional<double> value = ParseNumber(fields[index]);
      if (!value) throw Error(where + ": '" + fields[index] + "' (" + header[index] + ") is not a number");
      return *value;
    };
    const double frame = number(frame_column);
    CheckFrame(frame, frame_count, where);
    std::vector<EstimatedPoint>& points = estimates[static_cast<int>(frame)];
    const double u = number(u_column), v = number(v_column), z = number(z_column);
    int64_t id = static_cast<int64_t>(points.size());
    if (has_ids) {
      // Whole and within the integers a double holds exactly: a fraction or NaN cast to an id
      // would merge points that are not one, or give every NaN row the same id.
      const double value = number(id_column);
      if (!(std::abs(value) <= 9007199254740992.0 && value == std::floor(value))) {
        throw Error(where + ": '" + fields[id_column] + "' (point_id) is not a whole number");
      }
      id = static_cast<int64_t>(value);
      // One point is at one place in a frame; two rows of it would be paired with another
      // run's point twice, or its birth scored twice.
      if (!ids_seen.emplace(static_cast<int>(frame), id).second) {
        throw Error(where + ": point_id " + std::to_string(id) + " a second time in frame " +
                    std::to_string(static_cast<int>(frame)));
      }
    }
    if (!(std::isfinite(u) && std::isfinite(v) && std::isfinite(z) && z > 0)) continue;
    pixels.emplace_back(u, v);
    if (!camera.InImage(Eigen::Vector2d(u, v), /*margin=*/-0.5)) {  // pixels' outer edges, not centres
      ++*outside;
    } else {
      points.push_back({id, {u, v}, z});
    }
  }
  CheckPixelsAreTheImages(file, pixels, *outside, camera);
  return estimates;
}

FrameEstimates ReadDepthImages(const fs::path& folder, const cv::Size& size, int stride, int frame_count) {
  // OpenCV 4.6 reads EXR only when asked to (CVE hardening), and depth networks write EXR.
  setenv("OPENCV_IO_ENABLE_OPENEXR", "1", 0);
  std::vector<fs::path> files;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
    // Files OpenCV has no reader for (notes, calibration, hidden files) are not estimates.
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file() && name.front() != '.' && cv::haveImageReader(entry.path().string())) {
      files.push_back(entry.path());
    }
  }
  // An empty folder is a wrong path far more often than a system that failed on every frame.
  if (files.empty()) throw Error(folder.string() + " holds no depth image");
  std::sort(files.begin(), files.end());
  FrameEstimates estimates;
  for (const fs::path& file : files) {
    const std::optional<int> frame = FrameNumberOf(file.stem().string());
    if (!frame) throw Error(file.string() + ": no frame number in the file name");
    CheckFrame(*frame, frame_count, file.string());
    if (estimates.count(*frame)) throw Error(file.string() + ": a second depth image of frame " + std::to_string(*frame));
    const cv::Mat image = cv::imread(file.string(), cv::IMREAD_UNCHANGED);
    if (image.empty()) throw Error("cannot read " + file.string() + " as an image");
    if (image.channels() != 1) throw Error(file.string() + ": a depth image has one channel, this one " + std::to_string(image.channels()));
    if (image.size() != size) {
      throw Error(file.string() + " is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                  ", the sequence's images are " + std::to_string(size.width) + "x" + std::to_string(size.height));
    }
    cv::Mat depth;
    image.convertTo(depth, CV_64F);
    std::vector<EstimatedPoint>& points = estimates[*frame];
    for (int y = stride / 2; y < depth.rows; y += stride) {
      for (int x = stride / 2; x < depth.cols; x += stride) {
        const double z = depth.at<double>(y, x);
        if (std::isfinite(z) && z > 0) points.push_back({static_cast<int64_t>(y) * depth.cols + x, {double(x), double(y)}, z});
      }
    }
  }
  return estimates;
}

std::map<int, Rigid3> ReadTrajectory(const fs::path& file, double fps, int frame_count) {
  std::map<int, Rigid3> poses;
  for (const StampedPose& pose : ReadTum(file)) {
    const double frame = std::round(pose.timestamp * fps);
    const std::string where = file.string() + " (t = " + std::to_string(pose.timestamp) + " s)";
    if (!(frame >= 0 && frame < frame_count)) {
      // Most often a clock of its own (a recording's, the epoch's) instead of the frame's time.
      std::ostringstream message;
      message << where << ": no frame of the sequence is at that time; times are frame / fps, " << std::fixed
              << std::setprecision(3) << "0 … " << (frame_count - 1) / fps << " s at " << std::defaultfloat << fps
              << " fps (a trajectory on another clock needs its first frame's time subtracted)";
      throw Error(message.str());
    }
    if (!poses.emplace(static_cast<int>(frame), pose.world_from_camera).second) {
      throw Error(where + ": a second pose of frame " + std::to_string(static_cast<int>(frame)));
    }
  }
  return poses;
}

// Sizes and modification times of the files given (a folder's: all of its files), so that an
// output exported again to the same path is not taken for the one scored before.
std::string Fingerprint(const std::vector<fs::path>& paths) {
  uintmax_t files = 0, bytes = 0;
  fs::file_time_type newest{};
  std::error_code error;
  const auto add = [&](const fs::path& file) {
    ++files;
    bytes += fs::file_size(file, error);
    newest = std::max(newest, fs::last_write_time(file, error));
  };
  for (const fs::path& path : paths) {
    if (path.empty()) continue;
    if (!fs::is_directory(path, error)) {
      add(path);
      continue;
    }
    for (const fs::directory_entry& entry : fs::directory_iterator(path, error)) {
      if (entry.is_regular_file(error)) add(entry.path());
    }
  }
  return std::to_string(files) + " files, " + std::to_string(bytes) + " bytes, newest at " +
         std::to_string(newest.time_since_epoch().count());
}

}  // namespace

void ExternalResult::Check() const {
  if (estimates.empty()) throw Error("external result: no estimates given (a CSV file or a folder of depth images)");
  if (!fs::exists(estimates)) throw Error("external result: " + estimates.string() + " does not exist");
  if (!trajectory.empty() && !fs::is_regular_file(trajectory)) {
    throw Error("external result: trajectory " + trajectory.string() + " is not a file");
  }
  if (depth_stride_px < 1) throw Error("external result: depth_stride_px must be >= 1");
}

nlohmann::json ToJson(const ExternalResult& result) {
  return {{"name", result.name},
          {"estimates", fs::absolute(result.estimates).string()},
          {"trajectory", result.trajectory.empty() ? "" : fs::absolute(result.trajectory).string()},
          {"depth_stride_px", result.depth_stride_px},
          {"fingerprint", Fingerprint({result.estimates, result.trajectory})}};
}

RunSummary ScoreExternalResult(const fs::path& sequence, const ExternalResult& result,
                               const EvaluationOptions& evaluation, const fs::path& out) {
  result.Check();
  evaluation.Check();
  const SequenceReader reader(sequence);
  const SequenceInfo& info = reader.info();
  const cv::Size size(info.camera.width(), info.camera.height());
  // Only a CSV with its own point_id column names points: depth images number pixels, and a
  // CSV without ids numbers rows. Recorded, so that nothing pairs such ids across runs.
  bool ids_name_points = false;
  int outside_image = 0;
  const FrameEstimates estimates =
      fs::is_directory(result.estimates)
          ? ReadDepthImages(result.estimates, size, result.depth_stride_px, reader.frame_count())
          : ReadPointsCsv(result.estimates, reader.frame_count(), info.camera, &ids_name_points, &outside_image);
  const std::map<int, Rigid3> poses =
      result.trajectory.empty() ? std::map<int, Rigid3>{} : ReadTrajectory(result.trajectory, info.fps, reader.frame_count());

  RunFolderStreams streams =
      BeginRunFolder(out, sequence,
                     {{"sequence_info", info},
                      {"external", ToJson(result)},
                      {"evaluation", evaluation},
                      {"ids_name_points", ids_name_points}});
  std::ofstream& points_csv = streams.points;
  std::ofstream& metrics_csv = streams.metrics;

  RunSummary summary;
  summary.frames_total = reader.frame_count();
  summary.input.estimates_outside_image = outside_image;
  std::vector<FrameEvaluation> evaluations;
  std::vector<StampedPose> trajectory;
  std::vector<TrajectorySegment> aligned(1);
  // Births only where ids name points from frame to frame (not rows of a frame or pixels); the
  // first frame with points is the one map's first.
  BirthErrors births;
  MapDepthDrift depth_drift;
  bool had_points = false;
  const std::vector<EstimatedPoint> none;
  const std::string no_estimate = "no estimate of this frame in " + result.estimates.string();
  for (int frame = 0; frame < reader.frame_count(); ++frame) {
    const auto found = estimates.find(frame);
    const std::vector<EstimatedPoint>& points = found == estimates.end() ? none : found->second;
    const auto pose = poses.find(frame);
    const bool tracked = !points.empty() || pose != poses.end();
    FrameEvaluation frame_evaluation;
    std::string depth_problem;  // why a tracked frame with points is not scored
    double median_depth = 0;
    if (tracked && summary.init_frame < 0) {
      summary.init_frame = frame;
      summary.maps = 1;  // one map: another system's figures are not split by its re-initialisations
    }
    summary.CountFrame(frame, tracked, no_estimate);
    if (tracked) {
      std::vector<DepthPoint> depth_points;
      for (const EstimatedPoint& point : points) depth_points.push_back({point.pixel, point.depth});
      median_depth = MedianDepth(depth_points);
      depth_drift.AddFrame(summary.maps, frame, median_depth);
      cv::Mat depth_mm;
      if (reader.has_depth() && !points.empty()) {
        depth_mm = reader.TryReadDepthMm(frame, &depth_problem);
        if (depth_problem.empty()) {
          frame_evaluation = EvaluateFrame(depth_points, depth_mm, evaluation);
          if (frame_evaluation.points_used < evaluation.min_points) ++summary.input.frames_sparse_groundtruth;
        } else {
          ++summary.input.frames_groundtruth_unreadable;
        }
      }
      if (ids_name_points) {
        std::vector<int64_t> ids;
        for (const EstimatedPoint& point : points) ids.push_back(point.id);
        births.AddFrame(ids, depth_points, depth_mm, frame_evaluation, !had_points && !points.empty());
      }
      had_points = had_points || !points.empty();
      for (const EstimatedPoint& point : points) {
        const Eigen::Vector3d ray = info.camera.Unproject(Eigen::Vector2d(point.pixel.x, point.pixel.y));
        std::optional<Eigen::Vector3d> world;  // none without a pose
        if (pose != poses.end() && ray.z() > 1e-9) world = pose->second * (ray * (point.depth / ray.z()));
        WritePointsRow(points_csv, frame, point.id, point.pixel, point.depth, world, "tracked");
      }
      const fs::path depth_file = out / "depth" / FrameFileName(frame);
      const double to_mm = frame_evaluation.evaluated ? frame_evaluation.scale : 1.0;
      if (!cv::imwrite(depth_file.string(), SplatDepth(depth_points, to_mm, size, info.depth_unit_mm))) {
        throw Error("cannot write " + depth_file.string());
      }
      if (pose != poses.end()) {
        trajectory.push_back({frame / info.fps, pose->second});
        if (reader.has_groundtruth()) {
          aligned[0].estimated.push_back(pose->second.translation);
          aligned[0].groundtruth.push_back(reader.groundtruth()[static_cast<size_t>(frame)].world_from_camera.translation);
        }
      }
    }
    MetricsRow row;
    row.frame = frame;
    row.state = tracked ? TrackingState::kTracking
                : summary.init_frame < 0 ? TrackingState::kNotInitialised
                                         : TrackingState::kLost;
    row.map = summary.maps;
    row.points = points.size();
    row.Score(frame_evaluation);
    row.median_depth = median_depth;
    row.note = !tracked ? "no estimate" : depth_problem.empty() ? "" : "not scored: " + depth_problem;
    WriteMetricsRow(metrics_csv, row);
    // Last used here, so its pairs move into the list kept for the alignments at the end.
    if (frame_evaluation.evaluated) evaluations.push_back(std::move(frame_evaluation));
  }
  const auto inverted = std::count_if(evaluations.begin(), evaluations.end(), [](const FrameEvaluation& frame) {
    return DepthCorrelation(frame.estimated, frame.groundtruth) < kInverseDepthCorrelation;
  });
  if (2 * static_cast<size_t>(inverted) > evaluations.size()) {
    summary.input.frames_depth_inverted = static_cast<int>(inverted);
  }
  AggregateInto(&summary, evaluations, aligned, evaluation);
  summary.births = births.Summarise();
  summary.map_depth = depth_drift.Change();
  CloseWritten(points_csv, out / "points.csv");
  CloseWritten(metrics_csv, out / "metrics.csv");
  WriteTum(out / "trajectory.tum", trajectory);
  WriteSummaryJson(out / "summary.json", summary, {{"init", "external"}, {"mapping", nullptr}, {"mode", "external"}});
  return summary;
}

}  // namespace nrslam
