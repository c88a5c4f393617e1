#include "nrslam/io/png_header.h"

#include <array>
#include <cstdint>
#include <fstream>

namespace nrslam {

std::optional<PngHeader> ReadPngHeader(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return std::nullopt;
  // 8-byte signature, then the IHDR chunk: length(4) "IHDR"(4) width(4) height(4) depth(1) colour(1).
  std::array<unsigned char, 26> bytes{};
  if (!file.read(reinterpret_cast<char*>(bytes.data()), bytes.size())) return std::nullopt;
  static constexpr unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  for (int i = 0; i < 8; ++i) {
    if (bytes[i] != kSignature[i]) return std::nullopt;
  }
  if (bytes[12] != 'I' || bytes[13] != 'H' || bytes[14] != 'D' || bytes[15] != 'R') return std::nullopt;
  auto read_u32 = [&](int offset) {
    return static_cast<uint32_t>(bytes[offset]) << 24 | static_cast<uint32_t>(bytes[offset + 1]) << 16 |
           static_cast<uint32_t>(bytes[offset + 2]) << 8 | static_cast<uint32_t>(bytes[offset + 3]);
  };
  PngHeader header;
  header.width = static_cast<int>(read_u32(16));
  header.height = static_cast<int>(read_u32(20));
  header.bit_depth = bytes[24];
  switch (bytes[25]) {  // PNG colour type
    case 0: header.channels = 1; break;  // grey
    case 2: header.channels = 3; break;  // RGB
    case 3: header.channels = 3; break;  // palette, decoded to RGB
    case 4: header.channels = 2; break;  // grey + alpha
    case 6: header.channels = 4; break;  // RGBA
    default: return std::nullopt;
  }
  return header;
}

}  // namespace nrslam
