// util: CSV as nrslam writes it (run folders, evaluation results) and reads it back (run
// folders, other systems' estimates). RFC 4180 quoting: a field holding a comma, a quote or a
// line break is quoted, with its quotes doubled.
#pragma once

#include <istream>
#include <string>
#include <vector>

namespace nrslam {

// `text` as one CSV field: quoted only when it needs to be.
std::string CsvField(const std::string& text);

// Reads the next record of `in` into `fields`, unquoted, passing over blank lines. A quoted
// field may hold commas, quotes and line breaks, so a record can span lines; `*line` counts the lines read so far
// (for messages). A '\r' before a line break (a file written on Windows) and a UTF-8 byte-order
// mark before the first line (as spreadsheets write) are dropped.
// Returns false at the end of the stream. Throws Error naming `file` and the line when the
// stream ends inside a quoted field (a file cut short).
bool ReadCsvRecord(std::istream& in, const std::string& file, int* line, std::vector<std::string>* fields);

}  // namespace nrslam
