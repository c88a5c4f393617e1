#include "nrslam/util/text_table.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace nrslam {

size_t DisplayWidth(const std::string& text) {
  return static_cast<size_t>(std::count_if(text.begin(), text.end(), [](char byte) {
    return (static_cast<unsigned char>(byte) & 0xC0) != 0x80;  // not a continuation byte
  }));
}

namespace {

std::string MarkdownCell(const std::string& text) {
  std::string escaped;
  for (char c : text) escaped += c == '|' ? std::string("\\|") : std::string(1, c);
  return escaped;
}

std::string LatexCell(const std::string& text) {
  std::string escaped;
  for (char c : text) {
    switch (c) {
      case '\\': escaped += "\\textbackslash{}"; break;
      case '~': escaped += "\\textasciitilde{}"; break;
      case '^': escaped += "\\textasciicircum{}"; break;
      case '&': case '%': case '$': case '#': case '_': case '{': case '}': escaped += std::string("\\") + c; break;
      default: escaped += c;
    }
  }
  return escaped;
}

// The cells of `row` rendered by `cell`, as many as the header has, joined by `separator`.
std::string JoinCells(const std::vector<std::string>& row, size_t columns, std::string (*cell)(const std::string&),
                      const std::string& separator) {
  std::vector<std::string> cells;
  for (size_t c = 0; c < columns; ++c) cells.push_back(cell(c < row.size() ? row[c] : ""));
  return Join(cells, separator);
}

}  // namespace

void TextTable::Print(std::ostream& out) const {
  std::vector<size_t> widths(header_.size(), 0);
  auto measure = [&](const std::vector<std::string>& row) {
    for (size_t c = 0; c < row.size() && c < widths.size(); ++c) widths[c] = std::max(widths[c], DisplayWidth(row[c]));
  };
  measure(header_);
  for (const auto& row : rows_) measure(row);
  auto print_row = [&](const std::vector<std::string>& row) {
    for (size_t c = 0; c < widths.size(); ++c) {
      const std::string cell = c < row.size() ? row[c] : "";
      const std::string padding(widths[c] - DisplayWidth(cell), ' ');
      out << (c ? "  " + padding + cell : cell + padding);  // the first column left-aligned, the rest right
    }
    out << '\n';
  };
  print_row(header_);
  size_t total = 0;
  for (size_t w : widths) total += w;
  out << std::string(total + 2 * (widths.size() - 1), '-') << '\n';
  for (const auto& row : rows_) print_row(row);
}

void TextTable::PrintMarkdown(std::ostream& out) const {
  out << "| " << JoinCells(header_, header_.size(), MarkdownCell, " | ") << " |\n|";
  for (size_t c = 0; c < header_.size(); ++c) out << (c ? " ---: |" : " :--- |");
  out << '\n';
  for (const auto& row : rows_) out << "| " << JoinCells(row, header_.size(), MarkdownCell, " | ") << " |\n";
}

void TextTable::PrintLatex(std::ostream& out) const {
  out << "\\begin{tabular}{l" << std::string(header_.empty() ? 0 : header_.size() - 1, 'r') << "}\n\\toprule\n"
      << JoinCells(header_, header_.size(), LatexCell, " & ") << " \\\\\n\\midrule\n";
  for (const auto& row : rows_) out << JoinCells(row, header_.size(), LatexCell, " & ") << " \\\\\n";
  out << "\\bottomrule\n\\end{tabular}\n";
}

std::string FormatDuration(double seconds) {
  const long rounded = std::lround(std::max(0.0, seconds));
  if (rounded < 90) return std::to_string(rounded) + " s";
  const long minutes = std::lround(seconds / 60);
  if (minutes < 90) return std::to_string(minutes) + " min";
  return std::to_string(minutes / 60) + " h " + std::to_string(minutes % 60) + " min";
}

std::string Join(const std::vector<std::string>& items, const std::string& separator) {
  std::string out;
  for (size_t i = 0; i < items.size(); ++i) out += (i ? separator : "") + items[i];
  return out;
}

std::string FormatFixed(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", decimals, value);
  return text;
}

}  // namespace nrslam
