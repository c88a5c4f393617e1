// batch: reading back what nrslam_run wrote in a run folder (system/run_sequence.h lists the
// files), and comparing two run folders of one sequence on the points both report.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "nrslam/eval/common_points.h"

namespace nrslam {

// Rows of a CSV file nrslam wrote (a run's points.csv or metrics.csv, an evaluation's tables) by
// column name. Throws Error, naming the line, when a row has more or fewer fields than the header.
std::vector<std::map<std::string, std::string>> ReadCsv(const std::filesystem::path& file);
// A row's field as a number; NaN when missing, empty or not a number.
double Number(const std::map<std::string, std::string>& row, const std::string& key);

// points.csv as pixels and estimated depths per frame.
RunPoints ReadRunPoints(const std::filesystem::path& run_folder);

// The evaluation options the run was scored with (config.json): a run of ours by its options,
// an external result by its own.
EvaluationOptions RunEvaluationOptions(const std::filesystem::path& run_folder);

// Both runs must be of the same sequence (their config.json says which) and it must have
// depth. Throws Error otherwise.
CommonPointsComparison CompareRunFolders(const std::filesystem::path& a, const std::filesystem::path& b);

}  // namespace nrslam
