// io: reads a PNG's size and pixel format from its header, without decoding it, so that a
// sequence of thousands of frames is validated in milliseconds.
#pragma once

#include <filesystem>
#include <optional>

namespace nrslam {

struct PngHeader {
  int width = 0;
  int height = 0;
  int bit_depth = 0;  // bits per channel
  int channels = 0;
};

// nullopt if the file is missing, unreadable or not a PNG.
std::optional<PngHeader> ReadPngHeader(const std::filesystem::path& path);

}  // namespace nrslam
