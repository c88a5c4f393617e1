// util: a whole text file at once. Writing one (a results table, a report, a baseline) so that a
// reader never finds half of one: a full disk or a missing folder is an error, not a silently
// short file. Reading one whole (a calibration, a child process's log), or opening one to read
// with a folder in its place named as such: a folder opens as a stream on Linux and fails only
// when read, which a line-by-line reader takes for an empty file.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>

namespace nrslam {

// Writes `text` as the whole content of `path`, whole or not at all: into a temporary file
// beside it, renamed over `path` once written (an interrupted write leaves the old file).
// Throws Error naming the file when it cannot be written.
void WriteTextFile(const std::filesystem::path& path, const std::string& text);

// Closes `file`, written piece by piece to `path` (a run's points.csv as its frames come);
// throws Error naming `path` when any of it could not be written.
void CloseWritten(std::ofstream& file, const std::filesystem::path& path);

// `path` opened to read; throws Error naming it when it cannot be opened, or when it is a folder
// ("… is a folder, not a `kind`", e.g. "JSON file").
std::ifstream OpenToRead(const std::filesystem::path& path, const std::string& kind);

// Every byte of `path`, as written; "" when it cannot be opened or is a folder. For files whose
// absence the caller handles itself (a log a killed process never wrote, a /proc entry gone with
// its process).
std::string FileText(const std::filesystem::path& path);

}  // namespace nrslam
