#pragma once
// The command examples of README.md and docs/*.md, as docs_commands_test reads them at test time
// (issue 43: a documented command must not break silently). Markdown in, blocks and their
// annotations out; no process is run here, so the rules are tested on their own.
//
// Every fenced ```sh block is run by default (expected exit 0). A block that needs more says so in
// an HTML comment on the line before its opening fence (invisible on the rendered page):
//
//   <!-- doc-test
//   needs: ../shared/data/optiodom       paths (from the repository root) the block reads; absent:
//                                        the block is skipped, and the test says so
//   setup: fitcal fit --logs data/flower --out cal.yaml   shell run first (repeatable), must exit 0
//   exit: 5                              the status the block ends with (bash -e), default 0
//   writes: report/index.html cal.yaml   files or directories it must leave (non-empty); every
//                                        --out / --calibration-out of a command is checked anyway
//   prints: verdict: PASS                text its output must hold (repeatable)
//   -->
//
// or, alone: `synopsis` (flags in brackets, placeholders: every --flag must be one that
// `fitcal <command> --help` lists), `benchmarks` (each line runs with --benchmark_list_tests and
// must list at least one benchmark), `skip: <why it cannot run in a test>`. A fitcal command in a
// block of another language (or none) fails the test unless the block is annotated `skip:` or
// `synopsis`, so an example cannot slip in untested.

#include <string>
#include <vector>

namespace fitcal::testing::docs {

enum class Mode { kRun, kSynopsis, kBenchmarks, kSkip };

struct Annotation {
  Mode mode = Mode::kRun;
  std::string skip_reason;
  int exit_status = 0;
  std::vector<std::string> needs, setup, writes, prints;
};

struct DocBlock {
  std::string file;  // as given to ReadDocBlocks
  int line = 0;      // of the opening fence, 1-based
  std::string language;
  std::string body;  // the lines between the fences, each ending in '\n'
  bool annotated = false;
  Annotation annotation;
};

struct DocParse {
  std::vector<DocBlock> blocks;       // every block to run or check, in the file's order
  std::vector<std::string> problems;  // "<file>:<line>: what is wrong", one per problem
};

// The blocks of one markdown text. Only sh blocks and annotated or command-holding blocks of
// other languages are returned; the problems name annotations that are malformed, unattached or
// misplaced and commands outside sh blocks that nobody annotated.
DocParse ParseDocBlocks(const std::string& file, const std::string& markdown);

// True when `line` (one line of a block) runs fitcal: "fitcal fit ...", "build/tools/fitcal",
// "$ fitcal"; not the banner "fitcal 0.1.0 ..." nor a message "fitcal fit: ...".
bool IsFitcalCommand(const std::string& line);

// The commands of a block: continuation lines (a trailing backslash) joined, comments (" #" to
// the end) and blank lines dropped.
std::vector<std::string> Commands(const std::string& body);

// The synopsis lines of a block: like Commands, and a line that does not start a fitcal command
// continues the previous one (an indented line of optional flags).
std::vector<std::string> SynopsisCommands(const std::string& body);

// The subcommand of a fitcal command line ("import optiodom", "" for the default fit) and every
// --flag it names.
struct CommandWords {
  std::string subcommand;
  std::vector<std::string> flags;
};
CommandWords ParseCommandWords(const std::string& command);

// The paths a command writes by its flags (--out, --calibration-out), as written; a path holding
// a shell variable is left out (its value is not known here).
std::vector<std::string> OutputPaths(const std::string& command);

// True when `help` (the output of --help) lists `flag` as a whole word.
bool HelpListsFlag(const std::string& help, const std::string& flag);

// `text` with every path under /tmp/ moved under `scratch_tmp` (the test's own directory), so
// that documented paths such as /tmp/od_diff neither collide between runs nor touch the user's.
std::string MapTmp(const std::string& text, const std::string& scratch_tmp);

}  // namespace fitcal::testing::docs
