// The documentation's links resolve: every relative link in the README, the docs pages and the
// library folders' READMEs names a file that exists and, with a #fragment, a heading of that
// file. The pages name each other's sections often, and a page split or a renamed heading
// would otherwise leave links that lead nowhere. The pages that the code, the tools' help, the
// manifests and CI name must exist too.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "nrslam/util/text_file.h"
#include "temp_folder.h"

namespace {
namespace fs = std::filesystem;

const fs::path kSourceDir = NRSLAM_SOURCE_DIR;

struct NumberedLine {
  int number;  // from 1, as an editor counts
  std::string text;
};

// The lines of a Markdown text outside fenced code blocks, where a "](" is code, not a link.
std::vector<NumberedLine> ProseLines(const std::string& text) {
  std::vector<NumberedLine> lines;
  std::istringstream in(text);
  bool fenced = false;
  int number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    if (line.rfind("```", 0) == 0) {
      fenced = !fenced;
      continue;
    }
    if (!fenced) lines.push_back({number, line});
  }
  return lines;
}

// The anchor GitHub gives a heading: lower case, spaces to hyphens, ASCII punctuation other than
// '-' and '_' dropped. Bytes of other scripts are kept, as GitHub keeps letters of any script
// (a symbol such as '×' would be dropped there; no linked heading has one).
std::string HeadingAnchor(const std::string& heading) {
  std::string anchor;
  for (const char c : heading) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte >= 0x80 || std::isalnum(byte) || c == '-' || c == '_') {
      anchor += static_cast<char>(byte < 0x80 ? std::tolower(byte) : byte);
    } else if (c == ' ') {
      anchor += '-';
    }
  }
  return anchor;
}

// Every anchor of a Markdown file's headings; a repeated heading's later anchors get -1, -2, ...
std::set<std::string> Anchors(const fs::path& file) {
  std::set<std::string> anchors;
  std::map<std::string, int> seen;
  static const std::regex heading(R"(^#{1,6}\s+(.*?)\s*$)");
  for (const NumberedLine& line : ProseLines(nrslam::FileText(file))) {
    std::smatch match;
    if (!std::regex_match(line.text, match, heading)) continue;
    const std::string anchor = HeadingAnchor(match[1].str());
    const int count = seen[anchor]++;
    anchors.insert(count == 0 ? anchor : anchor + "-" + std::to_string(count));
  }
  return anchors;
}

// One line per relative link of `file` that does not resolve, naming the file, the line and why.
std::vector<std::string> BrokenLinks(const fs::path& file) {
  std::vector<std::string> broken;
  static const std::regex link(R"(\]\(([^)\s]+)\))");
  for (const NumberedLine& numbered : ProseLines(nrslam::FileText(file))) {
    const std::string& line = numbered.text;
    for (auto it = std::sregex_iterator(line.begin(), line.end(), link); it != std::sregex_iterator(); ++it) {
      const std::string target = (*it)[1].str();
      if (target.find("://") != std::string::npos || target.rfind("mailto:", 0) == 0) continue;
      const size_t hash = target.find('#');
      const std::string path_part = target.substr(0, hash);
      const fs::path linked = path_part.empty() ? file : file.parent_path() / path_part;
      const std::string where = file.string() + ":" + std::to_string(numbered.number) + ": " + target;
      if (!fs::exists(linked)) {
        broken.push_back(where + ": no such file");
        continue;
      }
      if (hash == std::string::npos) continue;
      if (!Anchors(linked).count(target.substr(hash + 1))) broken.push_back(where + ": no such heading");
    }
  }
  return broken;
}

std::vector<fs::path> DocumentationFiles() {
  std::vector<fs::path> files = {kSourceDir / "README.md"};
  for (const fs::path& folder : {kSourceDir / "docs", kSourceDir / "nrslam"}) {
    for (const fs::directory_entry& entry : fs::recursive_directory_iterator(folder)) {
      if (entry.path().extension() == ".md") files.push_back(entry.path());
    }
  }
  return files;
}

struct PageMention {
  std::string page;  // docs/<page>.md
  fs::path file;     // where it is named
};

// Every "docs/<page>.md" that the code, the tools' help, the manifests or CI name.
std::vector<PageMention> NamedDocsPages() {
  std::vector<PageMention> named;
  static const std::regex page(R"(docs/[A-Za-z0-9_-]+\.md)");
  std::vector<fs::path> files = {kSourceDir / ".ci" / "run"};
  for (const fs::path& folder : {kSourceDir / "nrslam", kSourceDir / "tools", kSourceDir / "data_manifests"}) {
    for (const fs::directory_entry& entry : fs::recursive_directory_iterator(folder)) {
      const std::string extension = entry.path().extension().string();
      if (extension == ".h" || extension == ".cc" || extension == ".json" || extension == ".md") {
        files.push_back(entry.path());
      }
    }
  }
  for (const fs::path& file : files) {
    const std::string text = nrslam::FileText(file);
    for (auto it = std::sregex_iterator(text.begin(), text.end(), page); it != std::sregex_iterator(); ++it) {
      named.push_back({it->str(), file});
    }
  }
  return named;
}

TEST(DocsLinks, HeadingAnchorsAreGitHubs) {
  EXPECT_EQ(HeadingAnchor("Tracking and the runner: `nrslam_run`"), "tracking-and-the-runner-nrslam_run");
  EXPECT_EQ(HeadingAnchor("Quick start (Debian 12)"), "quick-start-debian-12");
  EXPECT_EQ(HeadingAnchor("Mapping: the full monocular NR-SLAM"), "mapping-the-full-monocular-nr-slam");
  EXPECT_EQ(HeadingAnchor("Speed, and the changes tried on the solve"), "speed-and-the-changes-tried-on-the-solve");
}

TEST(DocsLinks, FindsEveryKindOfBrokenLink) {
  const fs::path folder = nrslam::UniqueTempFolder("docs_links");
  fs::create_directories(folder);
  std::ofstream(folder / "other.md") << "# Other page\n\n## A section\n\n## A section\n";
  std::ofstream(folder / "page.md")
      << "# Page\n\n"
         "[fine](other.md) [fine](other.md#a-section) [repeat](other.md#a-section-1) [here](#page)\n"
         "[web](https://example.org/missing.md) ![picture](other.md)\n"
         "[gone](missing.md) [no heading](other.md#no-section) [no heading here](#nowhere)\n"
         "```\n[code, not a link](missing.md)\n```\n";
  const std::vector<std::string> broken = BrokenLinks(folder / "page.md");
  fs::remove_all(folder);
  ASSERT_EQ(broken.size(), 3u) << ::testing::PrintToString(broken);
  EXPECT_NE(broken[0].find("missing.md: no such file"), std::string::npos);
  EXPECT_NE(broken[1].find("other.md#no-section: no such heading"), std::string::npos);
  EXPECT_NE(broken[2].find("#nowhere: no such heading"), std::string::npos);
}

TEST(DocsLinks, EveryRelativeLinkOfTheDocumentationResolves) {
  const std::vector<fs::path> files = DocumentationFiles();
  ASSERT_GE(files.size(), 7u);  // the README, five docs pages, the library's folder READMEs
  for (const fs::path& file : files) {
    for (const std::string& problem : BrokenLinks(file)) ADD_FAILURE() << problem;
  }
}

TEST(DocsLinks, EveryDocsPageTheCodeNamesExists) {
  const std::vector<PageMention> named = NamedDocsPages();
  ASSERT_GE(named.size(), 6u);  // the tools' help names a page each
  for (const PageMention& mention : named) {
    EXPECT_TRUE(fs::exists(kSourceDir / mention.page)) << mention.page << ", named in " << mention.file;
  }
}

}  // namespace
