#include "nrslam/util/csv.h"

#include "nrslam/util/error.h"

namespace nrslam {

std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

namespace {

// The next line of `in` without its line break, '\r\n' included.
bool ReadLine(std::istream& in, std::string* text, int* line) {
  if (!std::getline(in, *text)) return false;
  if (!text->empty() && text->back() == '\r') text->pop_back();
  ++*line;
  return true;
}

}  // namespace

bool ReadCsvRecord(std::istream& in, const std::string& file, int* line, std::vector<std::string>* fields) {
  fields->clear();
  std::string text;
  do {
    if (!ReadLine(in, &text, line)) return false;
    // The byte-order mark some programs (spreadsheets, Python's utf-8-sig) put before the header.
    if (*line == 1 && text.rfind("\xEF\xBB\xBF", 0) == 0) text.erase(0, 3);
  } while (text.empty());
  const int first_line = *line;
  std::string field;
  bool quoted = false;
  size_t i = 0;
  while (true) {
    if (i == text.size()) {
      if (!quoted) break;
      // A line break inside a quoted field belongs to the field.
      if (!ReadLine(in, &text, line)) {
        throw Error(file + ":" + std::to_string(first_line) + ": a quoted field is not closed (is the file cut short?)");
      }
      field += '\n';
      i = 0;
      continue;
    }
    const char c = text[i++];
    if (quoted) {
      if (c != '"') {
        field += c;
      } else if (i < text.size() && text[i] == '"') {  // a doubled quote is one quote
        field += '"';
        ++i;
      } else {
        quoted = false;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields->push_back(std::move(field));
      field.clear();
    } else {
      field += c;
    }
  }
  fields->push_back(std::move(field));
  return true;
}

}  // namespace nrslam
