#include "nrslam/batch/report.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <map>
#include <numeric>
#include <optional>
#include <set>
#include <sstream>
#include <utility>

#include "nrslam/batch/run_folder.h"
#include "nrslam/batch/svg_plot.h"
#include "nrslam/eval/depth_evaluation.h"
#include "nrslam/eval/error_view.h"
#include "nrslam/eval/trajectory_error.h"
#include "nrslam/io/sequence_reader.h"
#include "nrslam/util/error.h"
#include "nrslam/util/folder.h"
#include "nrslam/util/json_options.h"
#include "nrslam/util/text_file.h"
#include "nrslam/util/text_table.h"

namespace nrslam {
namespace {

// A file-name-safe version of a run's key.
std::string Slug(const RunResult& result) {
  std::string slug = result.sequence + (result.label.empty() ? "" : "__" + result.label);
  for (char& c : slug) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.') c = '_';
  }
  return slug;
}

// Camera positions of a TUM file beside the true ones, top view. A map's world has its own
// scale and gauge (a monocular map is in map units), so each map's estimated centres are
// carried onto the true ones by the similarity the ATE column uses; each map is its own
// polyline, since nothing joins the worlds of two maps.
std::vector<PlotSeries> TopView(const std::filesystem::path& estimate_file, const std::vector<StampedPose>& truth,
                                const std::map<int, int>& map_of_frame) {
  std::vector<PlotSeries> plot;
  const std::vector<StampedPose> estimate = ReadTum(estimate_file);
  if (estimate.empty() || truth.empty()) return plot;
  auto nearest = [&](double t) {
    size_t best = 0;
    for (size_t i = 1; i < truth.size(); ++i) {
      if (std::abs(truth[i].timestamp - t) < std::abs(truth[best].timestamp - t)) best = i;
    }
    return best;
  };
  PlotSeries true_path{"ground truth", "#222", {}, {}};
  std::map<int, TrajectorySegment> maps;
  for (const StampedPose& pose : estimate) {
    const size_t frame = nearest(pose.timestamp);
    const auto map = map_of_frame.find(static_cast<int>(frame));
    TrajectorySegment& segment = maps[map == map_of_frame.end() ? 1 : map->second];
    segment.estimated.push_back(pose.world_from_camera.translation);
    segment.groundtruth.push_back(truth[frame].world_from_camera.translation);
    true_path.x.push_back(segment.groundtruth.back().x());
    true_path.y.push_back(segment.groundtruth.back().z());
  }
  plot.push_back(std::move(true_path));
  for (const auto& [map, segment] : maps) {
    const auto centres = AlignedCentres(segment);
    if (!centres) continue;
    // One legend entry for all maps.
    PlotSeries aligned{plot.size() == 1 ? "estimate" : "", "#d62728", {}, {}};
    for (const Eigen::Vector3d& centre : *centres) {
      aligned.x.push_back(centre.x());
      aligned.y.push_back(centre.z());
    }
    plot.push_back(std::move(aligned));
  }
  return plot;
}

// A frame of the run with what it left out as never changing (its static_mask.png) tinted red.
std::string StaticRegionFigure(const SequenceReader& sequence, const std::filesystem::path& run, int frame,
                               const std::filesystem::path& folder, const std::string& name) {
  const cv::Mat left_out = cv::imread((run / "static_mask.png").string(), cv::IMREAD_GRAYSCALE);
  cv::Mat image = sequence.ReadRgb(frame);
  if (left_out.size() != image.size()) return "<p>static_mask.png is unreadable or not the images' size</p>\n";
  cv::Mat tinted = image.clone();
  tinted.setTo(cv::Scalar(0, 0, 255), left_out);
  cv::addWeighted(image, 0.5, tinted, 0.5, 0, image);
  if (!cv::imwrite((folder / name).string(), image)) throw Error("cannot write " + (folder / name).string());
  std::ostringstream html;
  html << "<div class=\"images\"><figure><img src=\"" << EscapeXml(name) << "\" width=\"640\"><figcaption>frame "
       << frame << ": in red, what the run left out as never changing</figcaption></figure></div>\n";
  return html.str();
}

// One run's section: plots and images, or why they are missing.
std::string RunSection(const RunResult& result, const std::filesystem::path& folder) {
  std::ostringstream html;
  const std::string key = RunKey(result);
  html << "<section><h2 id=\"" << EscapeXml(Slug(result)) << "\">" << EscapeXml(key) << "</h2>\n";
  if (result.status == "failed") {
    html << "<p class=\"failed\">Failed: " << EscapeXml(result.error) << "</p></section>\n";
    return html.str();
  }
  html << "<p>" << result.frames_tracked << "/" << result.frames_total << " frames tracked, RMSE "
       << RmseCell(result, result.rmse_mm) << " mm (median " << RmseCell(result, result.rmse_median_mm)
       << "; one scale per map: " << RecordedRmseCell(result, result.rmse_map_scale_mm) << "; a map at one depth: "
       << RecordedRmseCell(result, result.rmse_flat_mm) << "), trajectory error " << MillimetresCell(result.ate_mm) << " mm, run folder <code>" << EscapeXml(result.run_folder) << "</code></p>\n";
  for (const std::string& note : RunNotes(result)) html << "<p>" << EscapeXml(note) << "</p>\n";
  try {
    const std::filesystem::path run = result.run_folder;
    const Json config = ReadJsonFile(run / "config.json");
    const SequenceReader sequence(config.at("sequence").get<std::string>());
    const auto metrics = ReadCsv(run / "metrics.csv");
    PlotSeries rmse{"depth RMSE", "#1f77b4", {}, {}};
    PlotSeries flat{"a map at one depth", "#999999", {}, {}};  // runs before it was recorded have none
    // The evaluator's scale relative to its map's first (what one scale per map pays for), and
    // the map's median depth relative to its first, which needs no ground truth: a collapsing
    // scale shows in both, mirrored, and a change of the scene's depth in the second alone. As
    // log10, since a collapse spans orders of magnitude.
    PlotSeries scale_drift{"frame scale / map's first", "#2ca02c", {}, {}};
    PlotSeries depth_drift{"median depth / map's first", "#d62728", {}, {}};
    std::map<int, double> first_scale, first_depth;  // per map
    std::map<int, int> map_of_frame;
    std::vector<int> tracked;
    for (const auto& row : metrics) {
      if (row.at("state") != "tracking") continue;
      const int frame = static_cast<int>(Number(row, "frame"));
      const double map_number = Number(row, "map");  // NaN in runs before it was recorded
      const int map = std::isnan(map_number) ? 1 : static_cast<int>(map_number);
      if (!std::isnan(map_number)) map_of_frame[frame] = map;
      rmse.x.push_back(frame);
      rmse.y.push_back(Number(row, "rmse_mm"));
      if (row.count("rmse_flat_mm") != 0) {
        flat.x.push_back(frame);
        flat.y.push_back(Number(row, "rmse_flat_mm"));
      }
      const double scale = Number(row, "scale");
      if (scale > 0) {  // 0: the frame was not evaluated
        scale_drift.x.push_back(frame);
        scale_drift.y.push_back(std::log10(scale / first_scale.emplace(map, scale).first->second));
      }
      const double depth = Number(row, "median_depth");  // NaN in runs before it was recorded
      if (depth > 0) {
        depth_drift.x.push_back(frame);
        depth_drift.y.push_back(std::log10(depth / first_depth.emplace(map, depth).first->second));
      }
      tracked.push_back(frame);
    }
    html << "<div class=\"plots\">"
         << LinePlotSvg(flat.x.empty() ? std::vector<PlotSeries>{rmse} : std::vector<PlotSeries>{rmse, flat},
                        {"Depth RMSE per frame", "frame", "RMSE (mm)", 520, 300, false});
    std::vector<PlotSeries> drift;
    for (const PlotSeries& series : {scale_drift, depth_drift}) {
      if (!series.x.empty()) drift.push_back(series);
    }
    if (!drift.empty()) {
      html << LinePlotSvg(drift, {"Scale drift: each frame over its map's first", "frame", "log10 of the ratio", 520,
                                  300, false});
    }
    if (sequence.has_groundtruth() && std::filesystem::exists(run / "trajectory.tum")) {
      const std::vector<PlotSeries> top = TopView(run / "trajectory.tum", sequence.groundtruth(), map_of_frame);
      // Only the true path: no map had the 3 frames of a moving camera that an alignment needs.
      const std::string title = top.size() > 1 ? "Trajectory, top view (each map aligned as for the ATE)"
                                               : "Trajectory, top view (no map long enough to align)";
      html << LinePlotSvg(top, {title, "x (mm)", "z (mm)", 520, 300, true});
    }
    html << "</div>\n";
    if (std::filesystem::exists(run / "static_mask.png") && !metrics.empty()) {
      const int first_frame = static_cast<int>(Number(metrics.front(), "frame"));
      html << StaticRegionFigure(sequence, run, first_frame, folder, Slug(result) + "_static.png");
    }
    if (sequence.has_depth() && tracked.size() > 1) {
      // The first frame after initialisation, the middle one and the last tracked one.
      const std::set<int> shown = {tracked[1], tracked[tracked.size() / 2], tracked.back()};
      RunPoints points = ReadRunPoints(run);
      const EvaluationOptions evaluation = RunEvaluationOptions(run);
      ErrorViewOptions view_options;
      view_options.full_scale_error = 0;  // from each frame's errors: depth-initialised runs are off by a few per cent
      html << "<p>Depth error of each tracked point after the frame's scale: blue too shallow, white right, red too "
              "deep (full colour at the per cent given); beside it the ground-truth depth, each point filled with the "
              "colour of its own depth:</p><div class=\"images\">";
      for (int frame : shown) {
        std::string depth_problem;
        const cv::Mat depth_mm = sequence.TryReadDepthMm(frame, &depth_problem);
        if (!depth_problem.empty()) {
          html << "<p>frame " << frame << ": " << EscapeXml(depth_problem) << "</p>";
          continue;
        }
        const std::string name = Slug(result) + "_depth_error_" + std::to_string(frame) + ".png";
        const ErrorView view = DrawErrorView(sequence.ReadRgb(frame), depth_mm, points[frame], evaluation, view_options);
        if (!cv::imwrite((folder / name).string(), view.image)) throw Error("cannot write " + (folder / name).string());
        html << "<figure><img src=\"" << EscapeXml(name) << "\" width=\"640\"><figcaption>frame " << frame;
        if (view.evaluation.evaluated) {
          html << ", RMSE " << FormatFixed(view.evaluation.rmse_mm, 2) << " mm, full colour at ±"
               << FormatFixed(100 * view.full_scale_error, 1) << " %";
        }
        html << "</figcaption></figure>";
      }
      html << "</div>\n";
    }
  } catch (const std::exception& e) {
    html << "<p class=\"failed\">No plots: " << EscapeXml(e.what()) << "</p>\n";
  }
  html << "</section>\n";
  return html.str();
}

// A sweep point's value as a number, for a plot's axis; nothing for a value that is not one
// (a weighting's name, a flag).
std::optional<double> NumericValue(const std::string& assignment) {
  const std::string text = assignment.substr(assignment.find('=') + 1);
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0') return std::nullopt;
  return value;
}

// A table of text cells, each escaped.
std::string HtmlTable(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows) {
  std::ostringstream html;
  html << "<table><tr>";
  for (const std::string& column : header) html << "<th>" << EscapeXml(column) << "</th>";
  html << "</tr>\n";
  for (const std::vector<std::string>& row : rows) {
    html << "<tr>";
    for (const std::string& cell : row) html << "<td>" << EscapeXml(cell) << "</td>";
    html << "</tr>\n";
  }
  html << "</table>\n";
  return html.str();
}

// With sweeps: mean RMSE against each swept option's value, one line per sequence.
std::string SweepSection(const std::vector<RunResult>& results) {
  // option → sequence → value → (sum, n): each point averages over the other options' values.
  std::map<std::string, std::map<std::string, std::map<double, std::pair<double, int>>>> curves;
  for (const RunResult& r : results) {
    if (r.status != "ok" || !r.evaluated()) continue;
    for (const std::string& assignment : r.point) {
      const std::optional<double> value = NumericValue(assignment);
      if (!value) continue;  // no axis to plot it on
      auto& cell = curves[assignment.substr(0, assignment.find('='))][r.sequence][*value];
      cell.first += r.rmse_mm;
      cell.second += 1;
    }
  }
  const std::vector<SweepValueSummary> summaries = SummariseSweep(results);
  if (summaries.empty()) return "";
  static const char* kColours[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f"};
  std::ostringstream html;
  std::vector<std::vector<std::string>> rows;
  for (const SweepValueSummary& summary : summaries) rows.push_back(SweepSummaryCells(summary));
  html << "<section><h2>Sweeps</h2><p>Per swept value, over the sequences tracked to the end at every point; "
          "each run is also paired with the run of the same sequence at a run option's default (the values "
          "of a simulator option are different data, so they are not paired).</p>"
       << HtmlTable(SweepSummaryHeader(), rows);
  if (curves.empty()) return html.str() + "</section>\n";  // no numeric values to plot against
  html << "<p>RMSE of the runs that tracked every frame against each swept option, "
          "per sequence; with several options swept, each point is the mean over the others' values.</p>"
          "<div class=\"plots\">";
  for (const auto& [option, sequences] : curves) {
    std::vector<PlotSeries> series;
    for (const auto& [sequence, points] : sequences) {
      PlotSeries s{sequence, kColours[series.size() % 8], {}, {}, true};
      for (const auto& [x, cell] : points) {
        s.x.push_back(x);
        s.y.push_back(cell.first / cell.second);
      }
      series.push_back(s);
    }
    html << LinePlotSvg(series, {"RMSE against " + option, option, "mean RMSE (mm)", 520, 300, false});
  }
  html << "</div></section>\n";
  return html.str();
}

std::string RigidSection(const std::vector<RigidComparison>& comparisons) {
  if (comparisons.empty()) return "";
  std::ostringstream html;
  html << "<section><h2>Deformable against rigid</h2><p>Each deformable run beside the rigid run of the same "
          "sequence and options. Ratio = rigid / deformable: above 1, the deformable run is more accurate. "
          "\"Common\": both runs scored over the frames both evaluated (a rigid run that stops early is "
          "otherwise scored on the first frames only). \"Same points\": both runs scored on the points both "
          "report, the same tracks, over the frames where both have enough of them (a rigid run flags much "
          "of a deforming scene as outliers and is otherwise scored on the points that still fit).</p>";
  std::vector<std::vector<std::string>> rows;
  for (const RigidComparison& comparison : comparisons) rows.push_back(RigidComparisonCells(comparison));
  html << HtmlTable(RigidComparisonHeader(), rows) << "<p>"
       << EscapeXml(RigidComparisonTallyText(TallyRigidComparisons(comparisons))) << "</p>";
  // With sweeps (of the data above all: where does the deformable model pay?), the ratio of the
  // runs' own RMSEs against each swept value: option → value → log ratios of its pairs.
  std::map<std::string, std::map<double, std::vector<double>>> log_ratios;
  for (const RigidComparison& comparison : comparisons) {
    if (comparison.deformable.rmse_mm <= 0 || comparison.rigid.rmse_mm <= 0) continue;
    for (const std::string& assignment : comparison.deformable.point) {
      const std::optional<double> value = NumericValue(assignment);
      if (!value) continue;
      log_ratios[assignment.substr(0, assignment.find('='))][*value].push_back(
          std::log(comparison.rigid.rmse_mm / comparison.deformable.rmse_mm));
    }
  }
  std::ostringstream plots;
  for (const auto& [option, values] : log_ratios) {
    if (values.size() < 2) continue;
    PlotSeries ratio{"rigid / deformable", "#d62728", {}, {}, true};
    for (const auto& [x, logs] : values) {
      ratio.x.push_back(x);
      ratio.y.push_back(std::exp(std::accumulate(logs.begin(), logs.end(), 0.0) / static_cast<double>(logs.size())));
    }
    const PlotSeries even{"equally accurate", "#999999", {ratio.x.front(), ratio.x.back()}, {1.0, 1.0}};
    plots << LinePlotSvg({ratio, even},
                         {"Rigid / deformable RMSE against " + LastName(option), option, "ratio", 520, 300, false});
  }
  if (!plots.str().empty()) {
    html << "<p>The ratio of each pair's own RMSEs against each swept option: the geometric mean over the pairs "
            "at that value (with several options swept, over the others' values too). Above the grey line the "
            "deformable runs are the more accurate.</p><div class=\"plots\">"
         << plots.str() << "</div>";
  }
  html << "</section>\n";
  return html.str();
}

std::string SeedSection(const std::vector<SeedGroup>& groups) {
  if (groups.empty()) return "";
  std::vector<std::vector<std::string>> rows;
  for (const SeedGroup& group : groups) rows.push_back(SeedGroupCells(group));
  return "<section><h2>Over scene seeds</h2><p>Runs of one preset that differ only in the simulator's seed. "
         "Each is scored by its own RMSE (\"to end\": how many of those tracked every frame); sd is the sample "
         "standard deviation across seeds.</p>" +
         HtmlTable(SeedGroupHeader(), rows) + "</section>\n";
}

}  // namespace

void WriteReport(const std::vector<RunResult>& results, const std::vector<RigidComparison>& comparisons,
                 const std::vector<SeedGroup>& seed_groups, const std::filesystem::path& folder) {
  CreateFolder(folder);
  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>nrslam evaluation</title>\n"
          "<style>body{font-family:sans-serif;margin:24px;max-width:1200px}table{border-collapse:collapse}"
          "td,th{padding:3px 10px;border-bottom:1px solid #ddd;text-align:right}td:first-child,th:first-child"
          "{text-align:left}td:nth-child(-n+2){white-space:nowrap}.failed{color:#b00}.plots,.images{display:flex;flex-wrap:wrap;gap:12px}"
          "figure{margin:0}section{margin-top:28px}</style></head><body>\n<h1>nrslam evaluation</h1>\n";
  html << "<table><tr><th>run</th><th>status</th><th>init</th><th>tracked</th><th>RMSE mm</th><th>median mm</th>"
          "<th>flat mm</th><th>1 scale mm</th><th>ATE mm</th><th>fps</th><th>MB</th></tr>\n";
  for (const RunResult& r : results) {
    const std::string key = RunKey(r);
    html << "<tr><td><a href=\"#" << EscapeXml(Slug(r)) << "\">" << EscapeXml(key) << "</a></td>";
    if (r.status == "failed") {
      html << "<td class=\"failed\">FAILED</td><td colspan=\"9\" class=\"failed\">" << EscapeXml(r.error) << "</td></tr>\n";
      continue;
    }
    html << "<td>" << r.status << "</td><td>" << InitFrameCell(r) << "</td><td>" << r.frames_tracked << "/"
         << r.frames_total << "</td><td>" << RmseCell(r, r.rmse_mm) << "</td><td>"
         << RmseCell(r, r.rmse_median_mm) << "</td><td>" << RecordedRmseCell(r, r.rmse_flat_mm) << "</td><td>"
         << RecordedRmseCell(r, r.rmse_map_scale_mm) << "</td><td>" << MillimetresCell(r.ate_mm) << "</td><td>" << FormatFixed(r.fps, 1)
         << "</td><td>" << MegabytesCell(r.peak_memory_mb) << "</td></tr>\n";
  }
  html << "</table>\n<p>Code: " << EscapeXml(DescribeRevisions(results)) << "</p>\n" << SweepSection(results) << RigidSection(comparisons) << SeedSection(seed_groups);
  for (const RunResult& r : results) html << RunSection(r, folder);
  // Self-check for people and for the test that opens the page in a headless browser.
  html << "<script>window.addEventListener('load',()=>{const i=[...document.images];"
          "document.body.dataset.check='images='+i.length+' broken='+i.filter(x=>!(x.complete&&x.naturalWidth>0)).length"
          "+' plots='+document.querySelectorAll('svg.plot').length"
          "+' series='+document.querySelectorAll('svg.plot polyline.series').length;});</script>\n";
  html << "</body></html>\n";
  WriteTextFile(folder / "index.html", html.str());
}

}  // namespace nrslam
