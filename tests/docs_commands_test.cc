// Every command example of README.md and docs/*.md runs as documented (issue 43). The blocks are
// read at test time (tests/docs_commands.h: which blocks, and the doc-test annotations) and run
// with bash against the built binary in a scratch directory laid out like the repository: `fitcal`
// on PATH, build/tools and build/tests, the shipped data/ entries, ../shared when it exists, and
// /tmp/ paths moved into the scratch. Each block is checked for its documented exit status and
// the files it writes; a doc file's blocks share one scratch directory and run in order, as a
// reader follows the page. A block needing ../shared is skipped, saying so, where it is absent.
//
// ctest runs one test per doc file (FITCAL_DOC names it); without FITCAL_DOC every doc runs.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "tests/bench/bench_support.h"
#include "tests/docs_commands.h"
#include "tests/test_files.h"

namespace fitcal::testing::docs {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = FITCAL_SOURCE_DIR;
const fs::path kBuild = FITCAL_BINARY_DIR;
const fs::path kShared = FITCAL_SHARED_DIR;  // what the docs call ../shared

// The doc files to run: FITCAL_DOC (relative to the repository), or README.md and docs/*.md.
std::vector<std::string> DocFiles() {
  if (const char* one = std::getenv("FITCAL_DOC"); one != nullptr && *one != '\0') return {one};
  std::vector<std::string> files{"README.md"};
  std::vector<std::string> docs;
  for (const auto& e : fs::directory_iterator(kSource / "docs")) {
    if (e.path().extension() == ".md") docs.push_back("docs/" + e.path().filename().string());
  }
  std::sort(docs.begin(), docs.end());
  files.insert(files.end(), docs.begin(), docs.end());
  return files;
}

// Where a doc's commands run: <root>/repo is the working directory, <root>/shared its ../shared,
// <root>/bin on PATH, <root>/tmp stands for /tmp. Removed afterwards.
class Scratch {
 public:
  Scratch() {
    std::random_device rd;
    root_ = fs::temp_directory_path() / ("fitcal_docs_" + std::to_string(rd()));
    fs::create_directories(repo() / "build");
    fs::create_directories(repo() / "data");
    fs::create_directories(root_ / "bin");
    fs::create_directories(tmp());
    for (const char* dir : {"tools", "tests"}) fs::create_directory_symlink(kBuild / dir, repo() / "build" / dir);
    for (const auto& e : fs::directory_iterator(kSource / "data")) {
      fs::create_symlink(e.path(), repo() / "data" / e.path().filename());  // the shipped data sets
    }
    if (fs::exists(kShared)) fs::create_directory_symlink(fs::canonical(kShared), root_ / "shared");
    fs::create_symlink(kBuild / "tools" / "fitcal", root_ / "bin" / "fitcal");
    fs::create_symlink(kBuild / "tests" / "robot_bag_writer", root_ / "bin" / "robot_bag_writer");
  }
  ~Scratch() {
    std::error_code ec;
    fs::remove_all(root_, ec);
  }
  fs::path repo() const { return root_ / "repo"; }
  fs::path tmp() const { return root_ / "tmp"; }

  // `script` run by bash -e in repo(), /tmp/ mapped; its exit status and what it printed.
  struct Result {
    int status = -1;
    std::string output;
  };
  Result Run(const std::string& script) const {
    const fs::path file = root_ / "script.sh", out = root_ / "output.txt";
    WriteFileBytes(file, "set -e -o pipefail\n" + MapTmp(script, tmp().string()) + "\n");
    const std::string command = "cd '" + repo().string() + "' && PATH='" + (root_ / "bin").string() +
                                "':\"$PATH\" timeout 300 bash '" + file.string() + "' > '" +
                                out.string() + "' 2>&1";
    const int status = std::system(command.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, ReadFileBytes(out)};
  }
  // A path a block names, as the block sees it.
  fs::path Resolve(const std::string& path) const { return repo() / MapTmp(path, tmp().string()); }

 private:
  fs::path root_;
};

std::string Where(const DocBlock& b) { return b.file + ":" + std::to_string(b.line); }

std::string Tail(const std::string& text) {
  const std::size_t keep = 3000;
  return text.size() <= keep ? text : "..." + text.substr(text.size() - keep);
}

bool NonEmpty(const fs::path& p) {
  std::error_code ec;
  if (fs::is_directory(p, ec)) return !fs::is_empty(p, ec);
  return fs::is_regular_file(p, ec) && fs::file_size(p, ec) > 0;
}

// Files the block must leave: its `writes`, and every --out of its commands when it succeeds;
// when it fails, the --out of its last command must not exist (nothing written on a refusal).
void CheckOutputs(const DocBlock& b, const Scratch& s) {
  const std::vector<std::string> commands = Commands(b.body);
  std::vector<std::string> must_exist = b.annotation.writes;
  if (b.annotation.exit_status == 0) {
    for (const std::string& c : commands) {
      for (const std::string& p : OutputPaths(c)) must_exist.push_back(p);
    }
  } else if (!commands.empty()) {
    for (const std::string& p : OutputPaths(commands.back())) {
      EXPECT_FALSE(fs::exists(s.Resolve(p))) << Where(b) << ": a refused command wrote " << p;
    }
  }
  for (const std::string& p : must_exist) {
    EXPECT_TRUE(NonEmpty(s.Resolve(p))) << Where(b) << ": " << p << " was not written";
  }
}

void RunBlock(const DocBlock& b, const Scratch& s) {
  std::string setup;
  for (const std::string& line : b.annotation.setup) setup += line + "\n";
  if (!setup.empty()) {
    const Scratch::Result r = s.Run(setup);
    ASSERT_EQ(r.status, 0) << Where(b) << ": setup failed:\n" << Tail(r.output);
  }
  const Scratch::Result r = s.Run(b.body);
  EXPECT_EQ(r.status, b.annotation.exit_status) << Where(b) << ":\n" << b.body << Tail(r.output);
  for (const std::string& text : b.annotation.prints) {
    EXPECT_TRUE(Has(r.output, text)) << Where(b) << ": the output lacks '" << text << "':\n"
                                     << Tail(r.output);
  }
  CheckOutputs(b, s);
}

// Every flag of a synopsis is one its command's --help lists.
void CheckSynopsis(const DocBlock& b, const Scratch& s) {
  for (const std::string& line : SynopsisCommands(b.body)) {
    const CommandWords words = ParseCommandWords(line);
    const Scratch::Result help = s.Run("fitcal " + words.subcommand + " --help");
    ASSERT_EQ(help.status, 0) << Where(b) << ": 'fitcal " << words.subcommand
                              << " --help' failed:\n" << Tail(help.output);
    for (const std::string& flag : words.flags) {
      EXPECT_TRUE(HelpListsFlag(help.output, flag))
          << Where(b) << ": 'fitcal " << words.subcommand << "' has no flag " << flag;
    }
  }
}

// Every benchmark line names an executable whose filter selects at least one benchmark.
void CheckBenchmarks(const DocBlock& b, const Scratch& s) {
  for (const std::string& command : Commands(b.body)) {
    const Scratch::Result r = s.Run(command + " --benchmark_list_tests=true");
    EXPECT_EQ(r.status, 0) << Where(b) << ": " << command << "\n" << Tail(r.output);
    EXPECT_FALSE(r.output.empty()) << Where(b) << ": " << command << " selects no benchmark";
  }
}

// The first of the block's needs that is absent ("" when all are there); ../shared is kShared.
std::string MissingNeed(const DocBlock& b) {
  const std::string shared = "../shared";
  for (const std::string& need : b.annotation.needs) {
    const fs::path path = need.compare(0, shared.size(), shared) == 0
                              ? kShared.string() + need.substr(shared.size())
                              : (kSource / need).string();
    if (!fs::exists(path)) return need;
  }
  return "";
}

TEST(DocCommands, RunAsDocumented) {
  int ran = 0, skipped = 0;
  for (const std::string& doc : DocFiles()) {
    const DocParse parse = ParseDocBlocks(doc, ReadFileBytes(kSource / doc));
    for (const std::string& problem : parse.problems) ADD_FAILURE() << problem;
    const Scratch scratch;
    for (const DocBlock& b : parse.blocks) {
      if (b.annotation.mode == Mode::kSkip) {
        std::cout << Where(b) << ": not run: " << b.annotation.skip_reason << "\n";
        continue;
      }
      if (const std::string need = MissingNeed(b); !need.empty()) {
        std::cout << Where(b) << ": skipped: " << need << " is absent\n";
        ++skipped;
        continue;
      }
      SCOPED_TRACE(Where(b));
      switch (b.annotation.mode) {
        case Mode::kRun: RunBlock(b, scratch); break;
        case Mode::kSynopsis: CheckSynopsis(b, scratch); break;
        case Mode::kBenchmarks: CheckBenchmarks(b, scratch); break;
        case Mode::kSkip: break;
      }
      ++ran;
    }
  }
  std::cout << ran << " blocks run or checked, " << skipped << " skipped\n";
  if (ran == 0 && skipped > 0) GTEST_SKIP() << "every block needs what is absent";
}

// The rules themselves, on markdown written here.

TEST(DocCommandsParser, AFitcalCommandOutsideAnShBlockFails) {
  const DocParse p = ParseDocBlocks("x.md", "text\n```\nfitcal fit --logs d --out c.yaml\n```\n");
  ASSERT_EQ(p.problems.size(), 1u);
  EXPECT_TRUE(Has(p.problems[0], "x.md:2: a fitcal command in a ``` block")) << p.problems[0];
  const DocParse yaml = ParseDocBlocks("k.md", "```yaml\nargs:\n    fitcal report --logs \"$d\"\n```\n");
  EXPECT_EQ(yaml.problems.size(), 1u);
}

TEST(DocCommandsParser, OutputAndMessagesAreNotCommands) {
  EXPECT_FALSE(IsFitcalCommand("fitcal 0.1.0  omni3 robot 'apr02'  data set data/flower"));
  EXPECT_FALSE(IsFitcalCommand("fitcal fit: /tmp/x: not a directory"));
  EXPECT_TRUE(IsFitcalCommand("fitcal fit --logs DIR"));
  EXPECT_TRUE(IsFitcalCommand("  $ build/tools/fitcal report --logs d"));
  EXPECT_TRUE(IsFitcalCommand("fitcal fit ...  # the same"));
  EXPECT_TRUE(IsFitcalCommand("fitcal <command> --help"));
  const DocParse p = ParseDocBlocks("x.md", "```\nfitcal 0.1.0  omni3\n```\n```yaml\na: 1\n```\n");
  EXPECT_TRUE(p.problems.empty());
  EXPECT_TRUE(p.blocks.empty());
}

TEST(DocCommandsParser, AnnotationsAreReadAndCheckedStrictly) {
  const DocParse p = ParseDocBlocks("x.md",
                                    "<!-- doc-test\nneeds: ../shared/data\nexit: 5\nwrites: a b\n"
                                    "setup: fitcal simulate --out s\nprints: verdict: PASS\n-->\n"
                                    "```sh\nfitcal fit --logs s\n```\n"
                                    "<!-- doc-test skip: a Kubernetes manifest -->\n```yaml\n"
                                    "  fitcal fit --logs x\n```\n");
  EXPECT_TRUE(p.problems.empty()) << p.problems[0];
  ASSERT_EQ(p.blocks.size(), 2u);
  const Annotation& a = p.blocks[0].annotation;
  EXPECT_EQ(a.exit_status, 5);
  EXPECT_EQ(a.writes, (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(a.needs, (std::vector<std::string>{"../shared/data"}));
  EXPECT_EQ(a.prints, (std::vector<std::string>{"verdict: PASS"}));
  EXPECT_EQ(p.blocks[1].annotation.mode, Mode::kSkip);
  EXPECT_EQ(p.blocks[1].annotation.skip_reason, "a Kubernetes manifest");

  for (const char* bad : {"<!-- doc-test skip: -->\n```sh\nx\n```\n",
                          "<!-- doc-test exits: 1 -->\n```sh\nx\n```\n",
                          "<!-- doc-test exit: one -->\n```sh\nx\n```\n",
                          "<!-- doc-test exit: 1 -->\ntext\n```sh\nx\n```\n",
                          "<!-- doc-test benchmarks -->\n```yaml\nx\n```\n",
                          "<!-- doc-test exit: 1 -->\n"}) {
    EXPECT_FALSE(ParseDocBlocks("x.md", bad).problems.empty()) << bad;
  }
}

TEST(DocCommandsParser, CommandsOutputsAndFlags) {
  const std::vector<std::string> c =
      Commands("F=build/tools/fitcal  # the binary\n$F export ros2-control --calibration c.yaml \\\n"
               "    --out d.yaml --calibration-out 'e.yaml'\n\n");
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c[0], "F=build/tools/fitcal");
  EXPECT_EQ(OutputPaths(c[1]), (std::vector<std::string>{"d.yaml", "e.yaml"}));
  EXPECT_EQ(OutputPaths("fitcal fit --out=x.yaml --logs \"$d\" --out \"$o/c.yaml\""),
            std::vector<std::string>{"x.yaml"});
  const std::vector<std::string> s =
      SynopsisCommands("fitcal compare --logs DIR [--strategies STA]\n      [--out compare]\n"
                       "fitcal import optiodom <session>... --out <dir>\n");
  ASSERT_EQ(s.size(), 2u);
  const CommandWords compare = ParseCommandWords(s[0]);
  EXPECT_EQ(compare.subcommand, "compare");
  EXPECT_EQ(compare.flags, (std::vector<std::string>{"--logs", "--strategies", "--out"}));
  EXPECT_EQ(ParseCommandWords(s[1]).subcommand, "import optiodom");
  EXPECT_EQ(ParseCommandWords("fitcal --logs <dir> --method ceres").subcommand, "");
  EXPECT_TRUE(HelpListsFlag("  --out TEXT  Output\n  --outliers", "--out"));
  EXPECT_FALSE(HelpListsFlag("  --outliers UINT", "--out"));
  EXPECT_EQ(MapTmp("--out /tmp/a x=/tmp/b '/tmp/c' a/tmp/d", "/s/tmp"),
            "--out /s/tmp/a x=/s/tmp/b '/s/tmp/c' a/tmp/d");
}

}  // namespace
}  // namespace fitcal::testing::docs
