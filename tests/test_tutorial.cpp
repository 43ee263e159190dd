// docs/tutorial.md run as a reader runs it: its YAML blocks written to the
// files their first line names, every line of its `sh` blocks run in order
// from a fresh folder laid out like the checkout (build/ and models/ linked
// in), each exit status checked (0 unless the line says "# exits N"). The
// commands are read from the page, so the page and the test cannot drift.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "test_support.h"

namespace {

namespace fs = std::filesystem;
using acyclic::test::binaryPath;
using acyclic::test::readFile;
using acyclic::test::sourcePath;

struct Block {
  std::string language;
  std::vector<std::string> lines;
};

std::vector<Block> fencedBlocks(const std::string& markdown) {
  std::vector<Block> blocks;
  std::istringstream in(markdown);
  std::string line;
  Block* open = nullptr;
  while (std::getline(in, line)) {
    if (line.rfind("```", 0) == 0) {
      if (open) {
        open = nullptr;
      } else {
        blocks.push_back({line.substr(3), {}});
        open = &blocks.back();
      }
    } else if (open) {
      open->lines.push_back(line);
    }
  }
  return blocks;
}

TEST(Tutorial, CommandsOfTheTutorialRunAsDocumented) {
  const std::vector<Block> blocks = fencedBlocks(readFile(sourcePath("docs/tutorial.md")));
  acyclic::test::TempDir dir;
  const fs::path root(dir.path());
  fs::create_directory_symlink(fs::path(ACYCLIC_BINARY_DIR), root / "build");
  fs::create_directory_symlink(fs::path(sourcePath("models")), root / "models");

  const std::regex file_line(R"(^# (my/\S+)$)"), exits(R"(# exits (\d+))");
  int files = 0, commands = 0;
  for (const Block& b : blocks) {
    if (b.language == "yaml" && !b.lines.empty()) {
      std::smatch m;
      if (!std::regex_match(b.lines.front(), m, file_line)) continue;  // a format example, not a file to write
      fs::create_directories((root / m[1].str()).parent_path());
      std::string text;
      for (const std::string& l : b.lines) text += l + "\n";
      dir.write(m[1].str(), text);
      ++files;
    } else if (b.language == "sh") {
      for (const std::string& l : b.lines) {
        if (l.empty() || l[0] == '#') continue;
        std::smatch m;
        const int expected = std::regex_search(l, m, exits) ? std::stoi(m[1].str()) : 0;
        const acyclic::test::ProcessRun r = acyclic::test::runProcess("cd '" + dir.path() + "' && " + l);
        EXPECT_EQ(r.status, expected) << l << "\n" << r.output;
        if (l.find("acyclic-check my/scenario.yaml") != std::string::npos && l.find("--") == std::string::npos) {
          EXPECT_NE(r.output.find("start stance: valid"), std::string::npos) << r.output;
        }
        if (l.find("acyclic-simulate") != std::string::npos && expected == 1) {
          EXPECT_NE(r.output.find("verdict: fell"), std::string::npos) << "the tutorial says it falls\n" << r.output;
        }
        ++commands;
      }
    }
  }
  EXPECT_EQ(files, 2);  // the scene and the scenario
  EXPECT_GE(commands, 8);
  // What the tutorial says each step leaves behind.
  for (const char* f : {"my/plan.json", "my/trajectory.json", "my/view/index.html", "my/simulation.json",
                        "my/step.pos", "my/step.waist", "my/step.zmp"})
    EXPECT_TRUE(fs::exists(root / f)) << f;
  EXPECT_FALSE(fs::is_empty(root / "my/plots")) << "acyclic-plot wrote no figure";
}

}  // namespace
