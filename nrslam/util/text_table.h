// util: fixed-width text tables and the number and list formatting of the programs' summaries.
#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace nrslam {

class TextTable {
 public:
  explicit TextTable(std::vector<std::string> header) : header_(std::move(header)) {}
  void AddRow(std::vector<std::string> row) { rows_.push_back(std::move(row)); }
  // Columns right-aligned except the first; a rule under the header.
  void Print(std::ostream& out) const;
  // The same table as Markdown (a pipe table, aligned as Print aligns it), for notes and issues.
  void PrintMarkdown(std::ostream& out) const;
  // The same table as a LaTeX tabular with booktabs rules, LaTeX's special characters escaped,
  // to paste into a paper (needs \usepackage{booktabs}).
  void PrintLatex(std::ostream& out) const;

 private:
  std::vector<std::string> header_;
  std::vector<std::vector<std::string>> rows_;
};

// Fixed-point text of a number: FormatFixed(3.14159, 2) == "3.14".
std::string FormatFixed(double value, int decimals);
// A duration as a person reads it, rounded to what matters at its size: "42 s", "6 min",
// "1 h 20 min".
std::string FormatDuration(double seconds);
// Terminal columns of a text: one per UTF-8 code point, not per byte, so that a sequence named
// "colon-ü" or an option change "a → b" does not push a table's row out of line.
size_t DisplayWidth(const std::string& text);
// The items with `separator` between them: Join({"a", "b"}, ", ") == "a, b".
std::string Join(const std::vector<std::string>& items, const std::string& separator);

}  // namespace nrslam
