// A table prints the same cells as fixed-width text, Markdown and LaTeX, with each format's
// special characters escaped, so a results table pastes into notes and papers as it is.
#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "nrslam/util/text_table.h"

namespace nrslam {
namespace {

TextTable Example() {
  TextTable table({"sequence", "RMSE mm"});
  table.AddRow({"sim_3 [k=2|D=5]", "0.707"});
  table.AddRow({"50% & #1 {a} ~x^2 \\"});  // a short row: the missing cell is empty
  return table;
}

TEST(TextTable, PrintsFixedWidthColumns) {
  std::ostringstream text;
  Example().Print(text);
  EXPECT_EQ(text.str(),
            "sequence             RMSE mm\n"
            "----------------------------\n"
            "sim_3 [k=2|D=5]        0.707\n"
            "50% & #1 {a} ~x^2 \\         \n");
}

TEST(TextTable, AlignsCellsByCharactersNotBytes) {
  TextTable table({"sequence", "change"});
  table.AddRow({"colon-\u00fc", "k: 1.1 \u2192 2"});  // ü is 2 bytes in UTF-8, → 3
  table.AddRow({"colon-ab", "k: 1.1 -> 2"});
  std::ostringstream text;
  table.Print(text);
  EXPECT_EQ(text.str(),
            "sequence       change\n"
            "---------------------\n"
            "colon-\u00fc    k: 1.1 \u2192 2\n"
            "colon-ab  k: 1.1 -> 2\n");
}

TEST(TextTable, PrintsAMarkdownPipeTable) {
  std::ostringstream markdown;
  Example().PrintMarkdown(markdown);
  EXPECT_EQ(markdown.str(),
            "| sequence | RMSE mm |\n"
            "| :--- | ---: |\n"
            "| sim_3 [k=2\\|D=5] | 0.707 |\n"
            "| 50% & #1 {a} ~x^2 \\ |  |\n");
}

TEST(TextTable, PrintsABooktabsTabularWithLatexEscaped) {
  std::ostringstream latex;
  Example().PrintLatex(latex);
  EXPECT_EQ(latex.str(),
            "\\begin{tabular}{lr}\n"
            "\\toprule\n"
            "sequence & RMSE mm \\\\\n"
            "\\midrule\n"
            "sim\\_3 [k=2|D=5] & 0.707 \\\\\n"
            "50\\% \\& \\#1 \\{a\\} \\textasciitilde{}x\\textasciicircum{}2 \\textbackslash{} &  \\\\\n"
            "\\bottomrule\n"
            "\\end{tabular}\n");
}

}  // namespace
}  // namespace nrslam
