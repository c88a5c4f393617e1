// nrslam_preview: writes one frame of a sequence as a PNG: the colour image beside its
// ground-truth depth in false colour (near = red, far = blue, black = none). With --run, the
// run's points on that frame are drawn over both panels, coloured by their depth error, with
// the frame's state and RMSE above; with several, one such view per run, one under the other.
#include <CLI/CLI.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "documentation_footer.h"
#include "nrslam/batch/run_folder.h"
#include "nrslam/eval/error_view.h"
#include "nrslam/io/sequence_reader.h"
#include "nrslam/util/error.h"
#include "nrslam/util/folder.h"
#include "nrslam/util/json_options.h"
#include "nrslam/util/source_revision.h"
#include "nrslam/util/text_table.h"

namespace {

namespace fs = std::filesystem;

// The state the run recorded for each frame (metrics.csv); none when it has no such file.
std::map<int, std::string> RecordedStates(const fs::path& run) {
  std::map<int, std::string> states;
  if (!fs::exists(run / "metrics.csv")) return states;
  for (const auto& row : nrslam::ReadCsv(run / "metrics.csv")) {
    const double frame = nrslam::Number(row, "frame");
    if (std::isfinite(frame) && row.count("state")) states[static_cast<int>(frame)] = row.at("state");
  }
  return states;
}

std::vector<std::string> Caption(const std::string& run_name, int frame, const std::string& state,
                                 const nrslam::FramePoints& points, const nrslam::ErrorView& view) {
  using nrslam::FormatFixed;
  std::string first = run_name + "  frame " + std::to_string(frame);
  if (!state.empty()) first += "  " + state;
  first += "  " + std::to_string(points.size()) + " points";
  const nrslam::FrameEvaluation& evaluation = view.evaluation;
  if (evaluation.evaluated) {
    first += "  RMSE " + FormatFixed(evaluation.rmse_mm, 2) + " mm (flat map " + FormatFixed(evaluation.flat_rmse_mm, 2) +
             ")  scale " + FormatFixed(evaluation.scale, 3);
  }
  const std::string percent = FormatFixed(100 * view.full_scale_error, view.full_scale_error < 0.1 ? 1 : 0);
  return {first, "depth error: blue " + percent + " % too shallow, white right, red " + percent +
                     " % too deep; grey ring: not scored"};
}

cv::Mat WithCaption(const cv::Mat& image, const std::vector<std::string>& lines) {
  constexpr int kLineHeight = 20;
  cv::Mat out(image.rows + kLineHeight * static_cast<int>(lines.size()) + 6, image.cols, CV_8UC3, cv::Scalar::all(0));
  image.copyTo(out(cv::Rect(0, out.rows - image.rows, image.cols, image.rows)));
  for (size_t i = 0; i < lines.size(); ++i) {
    // Small enough to fit a narrow (scaled-down) image.
    int baseline = 0;
    const double width = cv::getTextSize(lines[i], cv::FONT_HERSHEY_SIMPLEX, 1.0, 1, &baseline).width;
    const double font_scale = std::min(0.45, (image.cols - 12) / width);
    cv::putText(out, lines[i], cv::Point(6, kLineHeight * static_cast<int>(i + 1)), cv::FONT_HERSHEY_SIMPLEX,
                font_scale, cv::Scalar::all(255), 1, cv::LINE_AA);
  }
  return out;
}

// One run folder, read once.
struct RunRecord {
  explicit RunRecord(const fs::path& folder)
      : name(folder.lexically_normal().filename().string()),
        sequence(nrslam::ReadJsonFile(folder / "config.json").at("sequence").get<std::string>()),
        points(nrslam::ReadRunPoints(folder)),
        states(RecordedStates(folder)),
        evaluation(nrslam::RunEvaluationOptions(folder)) {}
  std::string name;
  std::string sequence;  // the sequence it ran on
  nrslam::RunPoints points;
  std::map<int, std::string> states;
  nrslam::EvaluationOptions evaluation;
};

// A sequence, and any runs of it, drawn frame by frame: one view per run, one under the other.
class Preview {
 public:
  Preview(const std::string& sequence, const std::vector<std::string>& runs, const nrslam::ErrorViewOptions& options,
          double scale)
      : runs_(runs.begin(), runs.end()), reader_(sequence.empty() ? SequenceOfRuns() : sequence), options_(options),
        scale_(scale) {
    // cv::resize's own message for a frame scaled to nothing names neither the option nor a fix.
    const int width = reader_.info().camera.width(), height = reader_.info().camera.height();
    if (std::min(width, height) * scale < kMinScaledSide) {
      throw nrslam::Error("--scale draws the " + std::to_string(width) + "x" +
                          std::to_string(height) + " frames under " + std::to_string(kMinScaledSide) + " px a side");
    }
  }

  int frame_count() const { return reader_.frame_count(); }
  double fps() const { return reader_.info().fps; }

  cv::Mat Draw(int frame) const {
    const cv::Mat colour = reader_.ReadRgb(frame);
    cv::Mat depth;
    if (reader_.has_depth()) {
      std::string problem;
      depth = reader_.TryReadDepthMm(frame, &problem);
      if (!problem.empty()) {
        // Drawn as no ground truth (black), so the frame keeps the size of the others.
        std::cerr << "nrslam_preview: frame " << frame << ": " << problem << "; drawn without ground truth\n";
        depth = cv::Mat::zeros(colour.size(), CV_32F);
      }
    }
    if (runs_.empty()) {
      cv::Mat panel = colour;
      if (!depth.empty()) cv::hconcat(colour, nrslam::ColourDepth(depth, options_.near_mm, options_.far_mm), panel);
      return Scaled(panel);
    }
    std::vector<cv::Mat> views;
    for (const RunRecord& run : runs_) {
      const auto found = run.points.find(frame);
      const nrslam::FramePoints points = found == run.points.end() ? nrslam::FramePoints() : found->second;
      const nrslam::ErrorView view = nrslam::DrawErrorView(colour, depth, points, run.evaluation, options_);
      const auto state = run.states.find(frame);
      views.push_back(WithCaption(Scaled(view.image), Caption(run.name, frame, state == run.states.end() ? "" : state->second,
                                                              points, view)));
    }
    cv::Mat stacked;
    cv::vconcat(views, stacked);
    return stacked;
  }

 private:
  // The runs' own sequence: they must all have run on the same one.
  std::string SequenceOfRuns() const {
    if (runs_.empty()) throw nrslam::Error("give a sequence folder, or --run with a run folder");
    for (const RunRecord& run : runs_) {
      if (run.sequence != runs_.front().sequence) {
        throw nrslam::Error("the runs are of different sequences: " + runs_.front().sequence + " (" +
                            runs_.front().name + ") and " + run.sequence + " (" + run.name + ")");
      }
    }
    return runs_.front().sequence;
  }

  cv::Mat Scaled(const cv::Mat& image) const {
    if (scale_ == 1.0) return image;
    cv::Mat resized;
    cv::resize(image, resized, cv::Size(), scale_, scale_, scale_ < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
    return resized;
  }

  std::vector<RunRecord> runs_;
  nrslam::SequenceReader reader_;
  nrslam::ErrorViewOptions options_;
  double scale_;
  static constexpr int kMinScaledSide = 8;
};

// A frame of --all, or nothing (said on stderr) when its colour image cannot be read: one
// damaged frame should not cost the rest of a video.
std::optional<cv::Mat> DrawOrSkip(const Preview& preview, int frame) {
  try {
    return preview.Draw(frame);
  } catch (const nrslam::Error& e) {
    std::cerr << "nrslam_preview: frame " << frame << ": " << e.what() << "; skipped\n";
    return std::nullopt;
  }
}

void WritePng(const fs::path& file, const cv::Mat& image) {
  if (!cv::imwrite(file.string(), image)) throw nrslam::Error("cannot write " + file.string());
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Write a frame of a sequence (colour | depth) as a PNG; with --run, each run's points coloured by "
               "their depth error"};
  app.set_version_flag("--version", nrslam::VersionString());
  app.footer(DocumentationFooter("docs/tracking.md, \"Looking at a run\""));
  std::string sequence, out;
  std::vector<std::string> runs;
  int frame = 0;
  bool all_frames = false;
  nrslam::ErrorViewOptions view_options;
  double scale = 1.0;
  app.add_option("sequence", sequence, "sequence folder (with --run: the run's own, from its config.json, if not given)");
  app.add_option("--run", runs,
                 "run folders of nrslam_run or nrslam_eval: draw their points of the frame, one view under the other "
                 "(e.g. deformable and rigid)");
  app.add_option("--frame", frame, "frame index")->capture_default_str();
  app.add_flag("--all", all_frames,
               "every frame: --out is then a folder of NNNNNN.png, or a Motion-JPEG video if it ends in .avi");
  app.add_option("--out", out, "output PNG (with --all: a folder, or a .avi video)")->required();
  app.add_option("--scale", scale, "resize factor")->capture_default_str();
  app.add_option("--near", view_options.near_mm, "depth shown red, mm")->capture_default_str();
  app.add_option("--far", view_options.far_mm, "depth shown blue, mm")->capture_default_str();
  app.add_option("--full-scale-error", view_options.full_scale_error,
                 "relative depth error drawn at full colour (0.25 = 25 %); 0: three times each frame's rms relative "
                 "error")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    view_options.Check();
    // Up to 4, as nrslam_import's: a larger factor is a typo (a percentage) that would ask for gigabytes.
    if (!(scale > 0 && scale <= 4)) throw nrslam::Error("--scale must be in (0, 4]");
    const bool to_video = fs::path(out).extension() == ".avi";
    // Checked before anything is drawn: OpenCV's own message names neither the file nor a fix.
    if (!all_frames && !cv::haveImageWriter(out)) {
      throw nrslam::Error("--out " + out + ": not an image file name OpenCV writes (e.g. view.png; with --all, a "
                          "folder or a .avi video)");
    }
    if (!all_frames || to_video) nrslam::CreateFolder(fs::absolute(out).parent_path());
    const Preview preview(sequence, runs, view_options, scale);
    if (!all_frames) {
      WritePng(out, preview.Draw(frame));
      return 0;
    }
    int skipped = 0;  // frames whose colour image could not be read
    if (to_video) {
      // Motion JPEG: OpenCV writes it without any external codec.
      // A skipped frame is a black one, so the video keeps the sequence's timing; those before
      // the first drawn frame wait for its size.
      cv::VideoWriter video;
      cv::Mat black;  // the size of the drawn frames, once the first is drawn
      int waiting = 0;
      for (int index = 0; index < preview.frame_count(); ++index) {
        const std::optional<cv::Mat> image = DrawOrSkip(preview, index);
        if (!image) {
          ++skipped;
          if (black.empty()) {
            ++waiting;
          } else {
            video.write(black);
          }
          continue;
        }
        if (black.empty()) {
          if (!video.open(out, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), preview.fps(), image->size())) {
            throw nrslam::Error("cannot write the video " + out);
          }
          black = cv::Mat::zeros(image->size(), CV_8UC3);
          for (; waiting > 0; --waiting) video.write(black);
        }
        video.write(*image);
      }
      if (black.empty()) throw nrslam::Error("no frame of the sequence could be drawn");
    } else {
      nrslam::CreateFolder(out);
      for (int index = 0; index < preview.frame_count(); ++index) {
        char name[16];
        std::snprintf(name, sizeof(name), "%06d.png", index);
        const std::optional<cv::Mat> image = DrawOrSkip(preview, index);
        skipped += !image;
        if (image) WritePng(fs::path(out) / name, *image);
      }
    }
    std::cout << "wrote " << preview.frame_count() - (to_video ? 0 : skipped) << " frames to " << out;
    if (skipped > 0) std::cout << " (" << skipped << " unreadable: " << (to_video ? "black" : "left out") << ")";
    std::cout << '\n';
  } catch (const std::exception& e) {
    std::cerr << "nrslam_preview: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
