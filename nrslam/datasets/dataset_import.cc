#include "nrslam/datasets/dataset_import.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "nrslam/datasets/frame_source.h"
#include "nrslam/datasets/stereo_depth.h"
#include "nrslam/datasets/stereo_rectification.h"
#include "nrslam/io/sequence_writer.h"
#include "nrslam/util/error.h"
#include "nrslam/util/source_revision.h"

namespace nrslam {
namespace fs = std::filesystem;

namespace {

using importer::FrameSource;
using importer::Fail;
using importer::ReadImage;


// An image as written: at `size` (area-averaged down, bilinear up; a depth map by nearest pixel).
cv::Mat Resized(const cv::Mat& image, const cv::Size& size, bool depth) {
  if (image.size() == size) return image;
  cv::Mat resized;
  const int interpolation = depth ? cv::INTER_NEAREST : size.width < image.cols ? cv::INTER_AREA : cv::INTER_LINEAR;
  cv::resize(image, resized, size, 0, 0, interpolation);
  return resized;
}

// Every frame of `source` up to `count`, and its poses, into `writer`, the images resized to
// `written` (the size of the written sequence's camera).
void WriteFrames(const ImportOptions& options, const FrameSource& source, int count, const cv::Size& written,
                 const SequenceWriter& writer) {
  const cv::Size size(source.camera.width(), source.camera.height());
  for (int i = 0; i < count; ++i) {
    const int from = i * options.frame_step;  // the dataset's frame that becomes frame i
    const cv::Mat rgb = source.rgb(from);
    if (rgb.size() != size) {
      Fail(options, "frame " + std::to_string(from) + " is " + std::to_string(rgb.cols) + "x" +
                        std::to_string(rgb.rows) + " but the camera is " + std::to_string(size.width) + "x" +
                        std::to_string(size.height));
    }
    writer.WriteRgb(i, Resized(rgb, written, false));
    const cv::Mat right = source.right ? source.right(from) : cv::Mat();
    if (!right.empty()) writer.WriteRight(i, Resized(right, written, false));
    if (source.depth_mm || options.stereo_depth) {
      // Stereo depth is matched at the source's size, before any --scale: ground truth as fine as
      // the recording gives (halved first, the test's plane came out 2.3× less accurate).
      const cv::Mat depth =
          source.depth_mm ? source.depth_mm(from)
                          : StereoDepthMm(rgb, right, source.camera.fx(), source.baseline_mm, options.stereo_depth_options);
      if (depth.size() != size) {
        Fail(options, "depth of frame " + std::to_string(from) + " has another size than the image");
      }
      writer.WriteDepthMm(i, Resized(depth, written, true));
    }
  }
  if (!source.world_from_camera.empty()) {
    std::vector<StampedPose> poses;
    for (int i = 0; i < count; ++i) {
      const int from = i * options.frame_step;
      poses.push_back({from / options.fps, source.world_from_camera[static_cast<size_t>(from)]});
    }
    writer.WriteGroundtruth(poses);
  }
}

}  // namespace

void ImportOptions::Check() const {
  const std::vector<std::string> formats = ImportFormats();
  if (std::find(formats.begin(), formats.end(), format) == formats.end()) {
    std::string known;
    for (const std::string& name : formats) known += (known.empty() ? "" : ", ") + name;
    throw Error("unknown dataset format '" + format + "' (known: " + known + ")");
  }
  if (!fs::exists(input)) throw Error(format + " dataset: " + input.string() + " does not exist");
  if (frame_step < 1) throw Error("import options: frame_step must be >= 1, got " + std::to_string(frame_step));
  if (!(fps > 0) || max_frames < 0 || !(depth_unit_mm > 0) || !(near > 0) || !(far > near) || !(scene_unit_mm > 0)) {
    throw Error("import options: need fps > 0, max_frames >= 0, depth_unit_mm > 0, 0 < near < far, scene_unit_mm > 0");
  }
  if (!(scale > 0 && scale <= 4)) throw Error("import options: scale must be in (0, 4], got " + std::to_string(scale));
  const bool stereo_option = !right.empty() || !second_calibration.empty() || !stereo_layout.empty() ||
                             rectified_width != 0 || rectified_height != 0 || rectify_alpha != 0.0 ||
                             stereo_unit_mm != 0.0;
  if (stereo_option && format != "stereo") {
    throw Error(
        "import options: the right images, stereo layout, second calibration and rectification apply to --format "
        "stereo only");
  }
  if (!stereo_layout.empty() && stereo_layout != "side-by-side" && stereo_layout != "top-bottom") {
    throw Error("import options: stereo layout must be side-by-side or top-bottom, got '" + stereo_layout + "'");
  }
  if (stereo_unit_mm < 0) {
    throw Error("import options: stereo_unit_mm must be > 0 (or 0: the calibration format's own)");
  }
  StereoRectificationOptions{rectified_width, rectified_height, rectify_alpha}.Check();
  stereo_depth_options.Check();
}

std::vector<std::string> ImportFormats() { return {"endomapper-sim", "hamlyn", "c3vd", "images", "stereo"}; }

SequenceInfo ImportDataset(const ImportOptions& options, const fs::path& out) {
  options.Check();
  // OpenCV 4.6 reads EXR only when asked to (CVE hardening); the Endomapper depth is EXR.
  setenv("OPENCV_IO_ENABLE_OPENEXR", "1", 0);
  FrameSource source = options.format == "endomapper-sim" ? importer::EndomapperSim(options)
                       : options.format == "hamlyn"       ? importer::Hamlyn(options)
                       : options.format == "c3vd"         ? importer::C3vd(options)
                       : options.format == "stereo"       ? importer::Stereo(options)
                                                          : importer::Images(options);
  const int kept = (source.count + options.frame_step - 1) / options.frame_step;
  const int count = options.max_frames > 0 ? std::min(options.max_frames, kept) : kept;
  SequenceInfo info;
  info.camera = options.scale == 1.0
                    ? source.camera
                    : source.camera.Resized(std::max(1, static_cast<int>(std::lround(source.camera.width() * options.scale))),
                                            std::max(1, static_cast<int>(std::lround(source.camera.height() * options.scale))));
  info.fps = options.fps / options.frame_step;
  info.frame_count = count;
  info.depth_unit_mm = options.depth_unit_mm;
  if (source.right) info.stereo = StereoInfo{source.baseline_mm, info.camera};
  info.provenance = {{"generator", std::string("nrslam_import ") + NRSLAM_VERSION},
                     {"code", SequenceCodeFingerprint()},
                     {"format", options.format},
                     {"source", fs::absolute(options.input).string()}};
  info.provenance.update(source.provenance);
  if (options.frame_step != 1) info.provenance["frame_step"] = options.frame_step;  // frame i was the dataset's i·step
  if (options.scale != 1.0) {
    info.provenance["scale"] = options.scale;
    info.provenance["source_camera"] = source.camera;
  }
  cv::Mat mask;
  if (!options.mask.empty()) {
    mask = ReadImage(options, options.mask, cv::IMREAD_GRAYSCALE);
    if (mask.cols != source.camera.width() || mask.rows != source.camera.height()) {
      Fail(options, "the mask " + options.mask.string() + " is " + std::to_string(mask.cols) + "x" +
                        std::to_string(mask.rows) + " but the images are " + std::to_string(source.camera.width()) +
                        "x" + std::to_string(source.camera.height()));
    }
    mask = Resized(mask, cv::Size(info.camera.width(), info.camera.height()), true) > 0;
    if (cv::countNonZero(mask) == 0) Fail(options, "the mask " + options.mask.string() + " leaves no pixel usable");
    info.mask = "mask.png";
  }
  if (options.stereo_depth) {
    if (!source.right) Fail(options, "--stereo-depth needs the right camera's images");
    if (source.depth_mm) Fail(options, "--stereo-depth: the dataset has depth of its own");
    info.provenance["depth"] = {{"generator", std::string("nrslam_import --stereo-depth ") + NRSLAM_VERSION},
                                {"options", nlohmann::json(options.stereo_depth_options)}};
  }
  const SequenceWriter writer(out, info, source.depth_mm || options.stereo_depth);
  try {
    if (!mask.empty()) writer.WriteFixedMask(mask);
    WriteFrames(options, source, count, cv::Size(info.camera.width(), info.camera.height()), writer);
  } catch (...) {
    // Half a sequence would pass for a whole one until its missing frames are read: a failed
    // import leaves none.
    try {
      RemoveSequence(out);
    } catch (const Error&) {
      // The import's own error says more than a failed clean-up.
    }
    throw;
  }
  return info;
}

}  // namespace nrslam
