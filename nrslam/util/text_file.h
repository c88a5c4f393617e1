// util: writing a whole text file (a results table, a report, a baseline) so that a reader never
// finds half of one: a full disk or a missing folder is an error, not a silently short file.
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

}  // namespace nrslam
