// The library's folders form layers: each folder's README says which folders it depends on
// ("Depends on ..."), its sources include from no other folder, and the include graph has no
// cycle, so no folder includes from one that depends on it. util is the bottom layer that
// every folder may use without naming it.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "nrslam/util/text_file.h"

namespace {
namespace fs = std::filesystem;

using ModuleGraph = std::map<std::string, std::set<std::string>>;

const fs::path kLibraryDir = NRSLAM_LIBRARY_DIR;

std::set<std::string> ModuleNames() {
  std::set<std::string> names;
  for (const fs::directory_entry& entry : fs::directory_iterator(kLibraryDir)) {
    if (entry.is_directory()) names.insert(entry.path().filename().string());
  }
  return names;
}

// The modules named in the README's "Depends on ..." sentence ("everything else": all of
// them), or nullopt when the README or the sentence is missing.
std::optional<std::set<std::string>> DeclaredDependencies(const std::string& module,
                                                          const std::set<std::string>& modules) {
  const fs::path readme = kLibraryDir / module / "README.md";
  if (!fs::exists(readme)) return std::nullopt;
  std::string text = nrslam::FileText(readme);
  for (char& c : text) {
    if (c == '\n') c = ' ';
  }
  std::smatch sentence;
  if (!std::regex_search(text, sentence, std::regex("Depends on ([^.]*)\\."))) return std::nullopt;
  std::set<std::string> declared;
  if (sentence[1].str().find("everything else") != std::string::npos) {
    declared = modules;
  } else {
    const std::regex word("[a-z_]+");
    const std::string named = sentence[1].str();
    for (std::sregex_iterator it(named.begin(), named.end(), word), end; it != end; ++it) {
      if (modules.count(it->str())) declared.insert(it->str());
    }
  }
  declared.erase(module);
  return declared;
}

// Which other folders each folder's sources include from.
ModuleGraph IncludeGraph(const std::set<std::string>& modules) {
  ModuleGraph graph;
  const std::regex include_line("#include \"nrslam/([a-z_]+)/");
  for (const std::string& module : modules) {
    graph[module];
    for (const fs::directory_entry& entry : fs::directory_iterator(kLibraryDir / module)) {
      const std::string extension = entry.path().extension().string();
      if (extension != ".h" && extension != ".cc") continue;
      const std::string text = nrslam::FileText(entry.path());
      for (std::sregex_iterator it(text.begin(), text.end(), include_line), end; it != end; ++it) {
        if ((*it)[1] != module) graph[module].insert((*it)[1]);
      }
    }
  }
  return graph;
}

// A cycle of the graph as "a -> b -> a", or "" when it has none.
std::string FindCycle(const ModuleGraph& graph) {
  std::map<std::string, int> state;  // 0 unvisited, 1 on the current path, 2 done
  std::vector<std::string> path;
  std::function<std::string(const std::string&)> visit = [&](const std::string& node) -> std::string {
    state[node] = 1;
    path.push_back(node);
    for (const std::string& next : graph.at(node)) {
      if (state[next] == 1) {
        std::string cycle;
        for (auto it = std::find(path.begin(), path.end(), next); it != path.end(); ++it) cycle += *it + " -> ";
        return cycle + next;
      }
      if (state[next] == 0 && graph.count(next)) {
        const std::string found = visit(next);
        if (!found.empty()) return found;
      }
    }
    path.pop_back();
    state[node] = 2;
    return "";
  };
  for (const auto& [node, edges] : graph) {
    if (state[node] != 0) continue;
    const std::string found = visit(node);
    if (!found.empty()) return found;
  }
  return "";
}

TEST(ModuleLayering, FindCycleFindsACycleAndOnlyACycle) {
  EXPECT_EQ(FindCycle({{"a", {"b"}}, {"b", {"c"}}, {"c", {}}}), "");
  EXPECT_EQ(FindCycle({{"a", {"b"}}, {"b", {"c"}}, {"c", {"a"}}}), "a -> b -> c -> a");
}

TEST(ModuleLayering, EveryFolderIncludesOnlyWhatItsReadmeDeclares) {
  const std::set<std::string> modules = ModuleNames();
  ASSERT_GE(modules.size(), 10u) << "no library folders under " << kLibraryDir;
  ASSERT_TRUE(modules.count("util"));
  const ModuleGraph graph = IncludeGraph(modules);
  for (const std::string& module : modules) {
    const std::optional<std::set<std::string>> declared = DeclaredDependencies(module, modules);
    if (!declared) {
      ADD_FAILURE() << module << "/README.md is missing or has no \"Depends on ...\" sentence";
      continue;
    }
    for (const std::string& used : graph.at(module)) {
      if (used == "util") continue;
      EXPECT_TRUE(declared->count(used)) << module << " includes from " << used
                                         << ", which its README's \"Depends on\" does not name";
    }
  }
}

TEST(ModuleLayering, NoFolderIncludesFromOneThatDependsOnIt) {
  const std::string cycle = FindCycle(IncludeGraph(ModuleNames()));
  EXPECT_EQ(cycle, "") << "include cycle between folders: " << cycle;
}

}  // namespace
