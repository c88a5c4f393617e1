#include "nrslam/io/tum.h"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "nrslam/util/error.h"
#include "nrslam/util/text_file.h"

namespace nrslam {

void WriteTum(const std::filesystem::path& path, const std::vector<StampedPose>& poses) {
  std::ofstream file(path);
  if (!file) throw Error("cannot write " + path.string());
  file << "# timestamp tx ty tz qx qy qz qw (world_from_camera)\n" << std::setprecision(12);
  for (const StampedPose& pose : poses) {
    const Eigen::Vector3d& t = pose.world_from_camera.translation;
    const Eigen::Quaterniond& q = pose.world_from_camera.rotation;
    file << pose.timestamp << ' ' << t.x() << ' ' << t.y() << ' ' << t.z() << ' ' << q.x() << ' ' << q.y()
         << ' ' << q.z() << ' ' << q.w() << '\n';
  }
  CloseWritten(file, path);
}

std::vector<StampedPose> ReadTum(const std::filesystem::path& path) {
  std::ifstream file = OpenToRead(path, "TUM trajectory file");
  std::vector<StampedPose> poses;
  std::string line;
  for (int line_number = 1; std::getline(file, line); ++line_number) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double v[8];
    for (double& value : v) {
      // strtod, unlike a stream, reads "nan" and "inf": such a pose is then named as non-finite below.
      std::string token;
      char* end = nullptr;
      if (fields >> token) value = std::strtod(token.c_str(), &end);
      if (end == nullptr || end == token.c_str() || *end != '\0') {
        throw Error(path.string() + ":" + std::to_string(line_number) + ": expected 8 numbers (t tx ty tz qx qy qz qw)");
      }
    }
    for (double value : v) {
      if (!std::isfinite(value)) throw Error(path.string() + ":" + std::to_string(line_number) + ": non-finite value");
    }
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (!IsUnitQuaternion(q)) {
      throw Error(path.string() + ":" + std::to_string(line_number) + ": quaternion is not unit length");
    }
    poses.push_back({v[0], Rigid3(q, Eigen::Vector3d(v[1], v[2], v[3]))});
  }
  return poses;
}

}  // namespace nrslam
