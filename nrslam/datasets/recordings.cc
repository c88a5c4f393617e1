// The importers of recordings without a dataset's layout: a video or an image folder, and a
// raw stereo pair, which they rectify.
#include "nrslam/datasets/frame_source.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <opencv2/videoio/registry.hpp>

#include <functional>
#include <memory>
#include <utility>

#include "nrslam/datasets/stereo_rectification.h"
#include "nrslam/io/camera_file.h"
#include "nrslam/util/error.h"

namespace nrslam::importer {
namespace fs = std::filesystem;

namespace {

// FFmpeg, where OpenCV has it, rather than every backend in turn: the others print their own
// failures (GStreamer an assertion and a stack of warnings) above ours for a file none can open.
cv::VideoCapture OpenVideo(const fs::path& file) {
  const int backend = cv::videoio_registry::hasBackend(cv::CAP_FFMPEG) ? cv::CAP_FFMPEG : cv::CAP_ANY;
  return cv::VideoCapture(file.string(), backend);
}

// The frames of an image folder (sorted by name) or a video file: their count and a reader,
// which for a video only goes forward (frames skipped over are grabbed, not decoded).
struct FrameStream {
  int count = 0;
  std::function<cv::Mat(int)> read;  // BGR
};

FrameStream OpenFrames(const ImportOptions& options, const fs::path& input) {
  FrameStream stream;
  if (fs::is_directory(input)) {
    const std::vector<fs::path> files = ImageFiles(input);
    if (files.empty()) Fail(options, "no image files in " + input.string());
    stream.count = static_cast<int>(files.size());
    stream.read = [&options, files](int i) { return ReadImage(options, files[i], cv::IMREAD_COLOR); };
    return stream;
  }
  // A video: count the frames first (grab without decoding), then decode them in order.
  if (!fs::exists(input)) Fail(options, input.string() + " does not exist");
  cv::VideoCapture counter = OpenVideo(input);
  if (!counter.isOpened()) Fail(options, "cannot open " + input.string() + " as an image folder or a video");
  while (counter.grab()) ++stream.count;
  if (stream.count == 0) Fail(options, "the video " + input.string() + " has no frames");
  auto video = std::make_shared<cv::VideoCapture>(OpenVideo(input));
  auto next = std::make_shared<int>(0);  // the frame the video decodes next
  stream.read = [&options, video, next, input](int i) {
    if (i < *next) {
      Fail(options,
           "frame " + std::to_string(i) + " of " + input.string() + " asked for after frame " + std::to_string(*next));
    }
    cv::Mat frame;
    while (*next < i && video->grab()) ++*next;  // frames skipped (--frame-step) are not decoded
    if (*next != i || !video->read(frame)) {
      Fail(options, "cannot decode frame " + std::to_string(i) + " of " + input.string());
    }
    ++*next;
    return frame;
  };
  return stream;
}

}  // namespace

FrameSource Images(const ImportOptions& options) {
  if (options.calibration.empty()) Fail(options, "needs --calibration (a camera JSON)");
  FrameSource source;
  source.camera = LoadCalibration(options);
  const FrameStream frames = OpenFrames(options, options.input);
  source.count = frames.count;
  source.rgb = frames.read;
  return source;
}

// A raw stereo recording: the left and right images as two streams, or one stream whose images
// hold both (side by side, or the left above the right), rectified with the pair's calibration.
FrameSource Stereo(const ImportOptions& options) {
  if (options.calibration.empty()) {
    Fail(options,
         "needs --calibration: the pair's stereo calibration (OpenCV's M1 D1 M2 D2 R T, Kalibr's camchain, or "
         "the left camera's ROS camera_info with the right one's as --second-calibration)");
  }
  const bool packed = !options.stereo_layout.empty();
  if (packed == !options.right.empty()) {
    Fail(options, "needs either --right (the right camera's images) or --stereo-layout (both in one image)");
  }
  const FrameStream left = OpenFrames(options, options.input);
  const FrameStream right = packed ? left : OpenFrames(options, options.right);
  if (right.count != left.count) {
    Fail(options,
         "the right camera has " + std::to_string(right.count) + " frames, the left " + std::to_string(left.count));
  }
  // One image holding both views splits in halves; the calibration is of one view.
  const bool side_by_side = options.stereo_layout == "side-by-side";
  const auto half = [&options, side_by_side](const cv::Mat& both, int index, int i) {
    const int width = side_by_side ? both.cols / 2 : both.cols, height = side_by_side ? both.rows : both.rows / 2;
    if ((side_by_side ? both.cols : both.rows) % 2 != 0) {
      Fail(options, "frame " + std::to_string(i) + " is " + std::to_string(both.cols) + "x" +
                        std::to_string(both.rows) + ", which does not split into two equal views");
    }
    const cv::Rect view =
        side_by_side ? cv::Rect(index * width, 0, width, height) : cv::Rect(0, index * height, width, height);
    return both(view);  // a view into the decoded frame, which stays alive while it is used
  };
  // The left stream's last decoded frame: a video decodes in order, and a packed frame holds
  // the right view too.
  auto decoded = std::make_shared<std::pair<int, cv::Mat>>(0, left.read(0));
  const auto left_frame = [left, decoded](int i) -> const cv::Mat& {
    if (decoded->first != i) *decoded = {i, left.read(i)};
    return decoded->second;
  };
  const cv::Mat first = packed ? half(decoded->second, 0, 0) : decoded->second;
  std::vector<fs::path> calibration_files = {options.calibration};
  if (!options.second_calibration.empty()) calibration_files.push_back(options.second_calibration);
  StereoCalibration calibration;
  try {
    calibration =
        ReadStereoCalibration(calibration_files, std::make_pair(first.cols, first.rows), options.stereo_unit_mm);
  } catch (const Error& e) {
    Fail(options, e.what());
  }
  if (first.cols != calibration.left.width() || first.rows != calibration.left.height()) {
    Fail(options, "left frame 0 is " + std::to_string(first.cols) + "x" + std::to_string(first.rows) +
                      " but the calibration is " + std::to_string(calibration.left.width()) + "x" +
                      std::to_string(calibration.left.height()));
  }
  StereoRectificationOptions rectification;
  rectification.width = options.rectified_width;
  rectification.height = options.rectified_height;
  rectification.alpha = options.rectify_alpha;
  std::shared_ptr<const StereoRectifier> rectifier;
  try {
    rectifier = std::make_shared<const StereoRectifier>(calibration, rectification);
  } catch (const Error& e) {
    Fail(options, e.what());
  }
  FrameSource source;
  source.count = left.count;
  source.camera = rectifier->camera();
  source.baseline_mm = rectifier->baseline_mm();
  std::vector<std::string> files;
  for (const fs::path& file : calibration_files) files.push_back(fs::absolute(file).string());
  const Eigen::Matrix3d& r1 = rectifier->rectified_from_left();
  source.provenance["rectification"] = {
      {"calibration", files},
      {"alpha", options.rectify_alpha},
      {"raw_left_camera", calibration.left},
      {"raw_right_camera", calibration.right},
      {"rectified_from_raw_left",
       {{r1(0, 0), r1(0, 1), r1(0, 2)}, {r1(1, 0), r1(1, 1), r1(1, 2)}, {r1(2, 0), r1(2, 1), r1(2, 2)}}}};
  const auto raw = [=, &options](bool right_view, int i) {
    const cv::Mat image = packed       ? half(left_frame(i), right_view ? 1 : 0, i)
                          : right_view ? right.read(i)
                                       : left_frame(i);
    if (image.cols != calibration.left.width() || image.rows != calibration.left.height()) {
      Fail(options, std::string(right_view ? "right" : "left") + " frame " + std::to_string(i) + " is " +
                        std::to_string(image.cols) + "x" + std::to_string(image.rows) + " but the " +
                        (right_view ? "left frames and the " : "") + "calibration " + (right_view ? "are " : "is ") +
                        std::to_string(calibration.left.width()) + "x" + std::to_string(calibration.left.height()));
    }
    return image;
  };
  source.rgb = [raw, rectifier](int i) { return rectifier->Left(raw(false, i)); };
  source.right = [raw, rectifier](int i) { return rectifier->Right(raw(true, i)); };
  return source;
}

}  // namespace nrslam::importer
