#include "nrslam/batch/run_folder.h"

#include <cmath>
#include <fstream>

#include "nrslam/io/sequence_reader.h"
#include "nrslam/system/system_options.h"
#include "nrslam/util/csv.h"
#include "nrslam/util/error.h"
#include "nrslam/util/json_options.h"
#include "nrslam/util/text_file.h"

namespace nrslam {

std::vector<std::map<std::string, std::string>> ReadCsv(const std::filesystem::path& file) {
  std::ifstream stream = OpenToRead(file, "CSV file");
  std::vector<std::string> header, fields;
  std::vector<std::map<std::string, std::string>> rows;
  int line = 0;
  if (!ReadCsvRecord(stream, file.string(), &line, &header)) return rows;
  while (ReadCsvRecord(stream, file.string(), &line, &fields)) {
    // Every row of a file nrslam wrote has the header's fields: fewer or more is damage.
    if (fields.size() != header.size()) {
      throw Error(file.string() + ":" + std::to_string(line) + ": " + std::to_string(fields.size()) +
                  " fields where the header has " + std::to_string(header.size()) + " (a damaged or cut-short file?)");
    }
    std::map<std::string, std::string> row;
    for (size_t i = 0; i < header.size(); ++i) row[header[i]] = fields[i];
    rows.push_back(std::move(row));
  }
  return rows;
}

double Number(const std::map<std::string, std::string>& row, const std::string& key) {
  const auto found = row.find(key);
  if (found == row.end() || found->second.empty()) return std::nan("");
  try {
    return std::stod(found->second);
  } catch (const std::exception&) {
    return std::nan("");
  }
}

RunPoints ReadRunPoints(const std::filesystem::path& run_folder) {
  RunPoints points;
  for (const auto& row : ReadCsv(run_folder / "points.csv")) {
    const double frame = Number(row, "frame"), id = Number(row, "point_id");
    const double u = Number(row, "u"), v = Number(row, "v"), z = Number(row, "z_est");
    if (!std::isfinite(frame) || !std::isfinite(id) || !std::isfinite(u) || !std::isfinite(v)) {
      throw Error((run_folder / "points.csv").string() + ": a row without frame, point_id, u or v");
    }
    points[static_cast<int>(frame)][static_cast<int64_t>(id)] = {cv::Point2d(u, v), z};
  }
  return points;
}

EvaluationOptions RunEvaluationOptions(const std::filesystem::path& run_folder) {
  const std::string where = (run_folder / "config.json").string();
  const Json config = ReadJsonFile(run_folder / "config.json");
  return config.contains("options") ? OptionsFromJson<SystemOptions>(config.at("options"), where).evaluation
                                    : OptionsFromJson<EvaluationOptions>(config.value("evaluation", Json::object()), where);
}

CommonPointsComparison CompareRunFolders(const std::filesystem::path& a, const std::filesystem::path& b) {
  const Json config = ReadJsonFile(a / "config.json");
  const Json other_config = ReadJsonFile(b / "config.json");
  for (const auto& [folder, json] : {std::pair(a, config), std::pair(b, other_config)}) {
    // An external result's ids may number pixels or rows (system/external_result.h).
    if (!json.value("ids_name_points", true)) {
      throw Error(folder.string() + " has no point ids (depth images, or a CSV without point_id): there are no "
                  "common points to compare on");
    }
  }
  const std::string sequence = config.at("sequence").get<std::string>();
  const std::string other = other_config.at("sequence").get<std::string>();
  if (other != sequence) throw Error("the runs are of different sequences: " + sequence + " and " + other);
  const SequenceReader reader(sequence);
  if (!reader.has_depth()) throw Error("sequence " + sequence + " has no depth to compare against");
  // Scored as run a scored itself.
  // A frame whose ground truth cannot be read was scored in neither run: it is left out here too.
  const auto depth_mm = [&](int frame) {
    std::string problem;
    return reader.TryReadDepthMm(frame, &problem);
  };
  return CompareOnCommonPoints(ReadRunPoints(a), ReadRunPoints(b), depth_mm, RunEvaluationOptions(a));
}

}  // namespace nrslam
