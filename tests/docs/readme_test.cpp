// The README as a newcomer reads it: at most 150 lines, the two commands first, a map from the
// paper's concepts to files in which every file exists, and every other path it names present in the
// tree (so a move or a rename that forgets the README fails here, not in a reader's hands).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace resecto {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = RESECTO_SOURCE_DIR;

std::vector<std::string> readme_lines() {
  std::ifstream in(kSource / "README.md");
  EXPECT_TRUE(in) << (kSource / "README.md") << " cannot be read";
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

/// The `code spans` of a line that look like paths: a '/', no space, no placeholder or wildcard.
std::vector<std::string> paths_in(const std::string& text) {
  static const std::regex code("`([^`]+)`");
  std::vector<std::string> paths;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), code); it != std::sregex_iterator(); ++it) {
    const std::string span = (*it)[1];
    if (span.find('/') == std::string::npos || span.find_first_of(" <>*|[]") != std::string::npos || span[0] == '-') continue;
    paths.push_back(span);
  }
  return paths;
}

/// The cells of a table row `| a | b |`, trimmed.
std::vector<std::string> cells(const std::string& row) {
  std::vector<std::string> out;
  std::stringstream in(row.substr(1));
  for (std::string cell; std::getline(in, cell, '|');) {
    const auto first = cell.find_first_not_of(' ');
    const auto last = cell.find_last_not_of(' ');
    out.push_back(first == std::string::npos ? "" : cell.substr(first, last - first + 1));
  }
  return out;
}

/// Rows (without header and rule) of the table under the heading `## title`.
std::vector<std::vector<std::string>> table_under(const std::vector<std::string>& lines, const std::string& title) {
  std::vector<std::vector<std::string>> rows;
  bool inside = false;
  int row = 0;
  for (const std::string& line : lines) {
    if (line.rfind("## ", 0) == 0) inside = line == "## " + title;
    if (!inside || line.empty() || line[0] != '|') continue;
    if (row++ >= 2) rows.push_back(cells(line));
  }
  return rows;
}

TEST(Readme, IsShortAndOpensWithTheTwoCommands) {
  const std::vector<std::string> lines = readme_lines();
  EXPECT_LE(lines.size(), 150u);
  ASSERT_GE(lines.size(), 5u);
  EXPECT_EQ(lines[3].rfind("bash scripts/setup.sh run", 0), 0u) << lines[3];
  EXPECT_EQ(lines[4].rfind("bash scripts/setup.sh test", 0), 0u) << lines[4];
  EXPECT_TRUE(fs::exists(kSource / "scripts" / "setup.sh"));
}

TEST(Readme, EveryFileOfTheConceptMapExists) {
  const auto rows = table_under(readme_lines(), "From the paper to the code");
  EXPECT_GE(rows.size(), 15u) << "the concept map is missing or shrank";
  for (const auto& row : rows) {
    ASSERT_EQ(row.size(), 2u) << "a concept row has a concept and its files";
    const std::vector<std::string> files = paths_in(row[1]);
    EXPECT_FALSE(files.empty()) << "concept '" << row[0] << "' names no file";
    for (const std::string& file : files) {
      EXPECT_TRUE(fs::is_regular_file(kSource / file)) << "concept '" << row[0] << "': " << file << " does not exist";
    }
  }
}

TEST(Readme, EveryFolderOfTheLayoutExists) {
  const auto rows = table_under(readme_lines(), "Layout");
  EXPECT_GE(rows.size(), 5u);
  for (const auto& row : rows) {
    const std::vector<std::string> folder = paths_in(row[0]);
    ASSERT_EQ(folder.size(), 1u) << row[0];
    EXPECT_TRUE(fs::is_directory(kSource / folder[0])) << folder[0];
    // A name in the description is the row's folder's (`base/` of `rtcore/`) or the tree's (`device/`).
    for (const std::string& sub : paths_in(row[1])) {
      EXPECT_TRUE(fs::exists(kSource / folder[0] / sub) || fs::exists(kSource / sub)) << folder[0] << " row: " << sub << " does not exist";
    }
  }
}

TEST(Readme, EveryPathItNamesExists) {
  // What the main job writes when it runs: named in the README, absent from a fresh clone.
  const std::vector<std::string> generated = {"out/"};
  bool in_layout = false;
  int named = 0;
  for (const std::string& line : readme_lines()) {
    if (line.rfind("## ", 0) == 0) in_layout = line == "## Layout";
    if (in_layout) continue;  // checked with its row's folder above
    for (const std::string& path : paths_in(line)) {
      if (std::find(generated.begin(), generated.end(), path) != generated.end()) continue;
      ++named;
      EXPECT_TRUE(fs::exists(kSource / path)) << path << " is named in the README but does not exist";
    }
  }
  EXPECT_GE(named, 20);
  // Images too.
  EXPECT_TRUE(fs::is_regular_file(kSource / "docs" / "console.png"));
}

}  // namespace
}  // namespace resecto
