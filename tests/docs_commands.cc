#include "tests/docs_commands.h"

#include <cctype>
#include <regex>
#include <sstream>

namespace fitcal::testing::docs {
namespace {

constexpr char kAnnotationStart[] = "<!-- doc-test";

std::string Trim(const std::string& s) {
  const auto first = s.find_first_not_of(" \t");
  if (first == std::string::npos) return "";
  return s.substr(first, s.find_last_not_of(" \t") - first + 1);
}

bool StartsWith(const std::string& s, const std::string& prefix) {
  return s.compare(0, prefix.size(), prefix) == 0;
}

std::vector<std::string> Words(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

std::vector<std::string> SplitLines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// A comment starts at a '#' that begins a word (bash's rule, quotes aside: no example quotes one).
std::string WithoutComment(const std::string& line) {
  for (std::size_t i = 0; i < line.size(); ++i) {
    if (line[i] == '#' && (i == 0 || line[i - 1] == ' ' || line[i - 1] == '\t')) {
      return line.substr(0, i);
    }
  }
  return line;
}

std::string Unquoted(std::string word) {
  if (word.size() >= 2 && (word.front() == '\'' || word.front() == '"') &&
      word.back() == word.front()) {
    word = word.substr(1, word.size() - 2);
  }
  return word;
}

// One "key: value" or bare word of an annotation into `a`; "" or the problem.
std::string ReadAnnotationLine(const std::string& line, Annotation* a) {
  if (line == "synopsis") {
    a->mode = Mode::kSynopsis;
    return "";
  }
  if (line == "benchmarks") {
    a->mode = Mode::kBenchmarks;
    return "";
  }
  const auto colon = line.find(':');
  if (colon == std::string::npos) return "'" + line + "' is not 'key: value'";
  const std::string key = Trim(line.substr(0, colon)), value = Trim(line.substr(colon + 1));
  if (value.empty()) return "'" + key + ":' has no value";
  if (key == "skip") {
    a->mode = Mode::kSkip;
    a->skip_reason = value;
  } else if (key == "exit") {
    try {
      std::size_t used = 0;
      a->exit_status = std::stoi(value, &used);
      if (used != value.size()) throw std::invalid_argument(value);
    } catch (const std::exception&) {
      return "exit: '" + value + "' is not a number";
    }
  } else if (key == "needs" || key == "writes") {
    for (const std::string& w : Words(value)) (key == "needs" ? a->needs : a->writes).push_back(w);
  } else if (key == "setup") {
    a->setup.push_back(value);
  } else if (key == "prints") {
    a->prints.push_back(value);
  } else {
    return "unknown key '" + key + "' (known: needs, setup, exit, writes, prints, skip, synopsis, " +
           "benchmarks)";
  }
  return "";
}

bool IsShell(const std::string& language) {
  return language == "sh" || language == "bash" || language == "shell" || language == "console";
}

}  // namespace

bool IsFitcalCommand(const std::string& line) {
  static const std::regex command(
      R"(^(\$ +)?([^ ]*/)?fitcal( +[a-z][a-z0-9-]*)*( +(-|<|\[|\.\.\.)|$).*)");
  return std::regex_match(Trim(line), command);
}

DocParse ParseDocBlocks(const std::string& file, const std::string& markdown) {
  DocParse parse;
  const std::vector<std::string> lines = SplitLines(markdown);
  const auto problem = [&](int line, const std::string& what) {
    parse.problems.push_back(file + ":" + std::to_string(line) + ": " + what);
  };
  bool pending = false;  // an annotation waits for its block
  int pending_line = 0;
  Annotation annotation;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string line = Trim(lines[i]);
    const int number = static_cast<int>(i) + 1;
    if (StartsWith(line, kAnnotationStart)) {
      if (pending) problem(pending_line, "doc-test annotation not followed by a fenced block");
      pending = true;
      pending_line = number;
      annotation = Annotation{};
      std::string text = line.substr(sizeof(kAnnotationStart) - 1);
      while (text.find("-->") == std::string::npos && i + 1 < lines.size()) {
        text += "\n" + lines[++i];
      }
      const auto end = text.find("-->");
      if (end == std::string::npos) problem(pending_line, "doc-test annotation without -->");
      for (const std::string& raw : SplitLines(text.substr(0, end))) {
        const std::string entry = Trim(raw);
        if (entry.empty()) continue;
        if (const std::string why = ReadAnnotationLine(entry, &annotation); !why.empty()) {
          problem(pending_line, "doc-test annotation: " + why);
        }
      }
      continue;
    }
    if (!StartsWith(line, "```")) {
      if (pending && !line.empty()) {
        problem(pending_line, "doc-test annotation not followed by a fenced block");
        pending = false;
      }
      continue;
    }
    DocBlock block;
    block.file = file;
    block.line = number;
    block.language = Trim(line.substr(3));
    while (++i < lines.size() && !StartsWith(Trim(lines[i]), "```")) block.body += lines[i] + "\n";
    block.annotated = pending;
    block.annotation = pending ? annotation : Annotation{};
    pending = false;
    bool has_command = false;
    for (const std::string& body_line : SplitLines(block.body)) {
      has_command = has_command || IsFitcalCommand(body_line);
    }
    const Mode mode = block.annotation.mode;
    if (!IsShell(block.language)) {
      if (!block.annotated && !has_command) continue;  // YAML, output: nothing to run
      if (!block.annotated) {
        problem(number, "a fitcal command in a ```" + block.language +
                            " block: mark the block ```sh so that it runs, or annotate it "
                            "<!-- doc-test skip: why -->");
        continue;
      }
      if (mode != Mode::kSkip && mode != Mode::kSynopsis) {
        problem(number, "only an sh block runs; annotate a ```" + block.language +
                            " block 'skip: why' or 'synopsis'");
        continue;
      }
    }
    if (mode == Mode::kSkip && !block.annotation.setup.empty()) {
      problem(number, "a skipped block has no setup");
    }
    parse.blocks.push_back(std::move(block));
  }
  if (pending) problem(pending_line, "doc-test annotation not followed by a fenced block");
  return parse;
}

std::vector<std::string> Commands(const std::string& body) {
  std::vector<std::string> commands;
  std::string current;
  for (const std::string& raw : SplitLines(body)) {
    std::string line = Trim(raw);
    const bool continues = !line.empty() && line.back() == '\\';
    if (continues) line.pop_back();
    current += WithoutComment(line) + " ";
    if (continues) continue;
    if (!Trim(current).empty()) commands.push_back(Trim(current));
    current.clear();
  }
  if (!Trim(current).empty()) commands.push_back(Trim(current));
  return commands;
}

std::vector<std::string> SynopsisCommands(const std::string& body) {
  std::vector<std::string> commands;
  for (const std::string& command : Commands(body)) {
    if (IsFitcalCommand(command) || commands.empty()) {
      commands.push_back(command);
    } else {
      commands.back() += " " + command;
    }
  }
  return commands;
}

CommandWords ParseCommandWords(const std::string& command) {
  CommandWords words;
  bool in_subcommand = false, subcommand_done = false;
  for (std::string w : Words(command)) {
    if (!in_subcommand && !subcommand_done) {
      if (w == "fitcal" || (w.size() > 7 && w.compare(w.size() - 7, 7, "/fitcal") == 0)) {
        in_subcommand = true;
      }
      continue;
    }
    if (in_subcommand && std::regex_match(w, std::regex("[a-z][a-z0-9-]*"))) {
      words.subcommand += (words.subcommand.empty() ? "" : " ") + w;
      continue;
    }
    in_subcommand = false;
    subcommand_done = true;
    static const std::regex flag(R"(--[a-z][a-z0-9-]*)");
    for (std::sregex_iterator it(w.begin(), w.end(), flag), end; it != end; ++it) {
      const std::size_t at = static_cast<std::size_t>(it->position());
      if (at == 0 || w[at - 1] == '[') words.flags.push_back(it->str());
    }
  }
  return words;
}

std::vector<std::string> OutputPaths(const std::string& command) {
  std::vector<std::string> paths;
  const std::vector<std::string> words = Words(command);
  for (std::size_t i = 0; i < words.size(); ++i) {
    for (const std::string flag : {"--out", "--calibration-out"}) {
      std::string path;
      if (words[i] == flag && i + 1 < words.size()) path = words[i + 1];
      if (StartsWith(words[i], flag + "=")) path = words[i].substr(flag.size() + 1);
      path = Unquoted(path);
      if (!path.empty() && path.find('$') == std::string::npos) paths.push_back(path);
    }
  }
  return paths;
}

bool HelpListsFlag(const std::string& help, const std::string& flag) {
  for (std::size_t at = help.find(flag); at != std::string::npos; at = help.find(flag, at + 1)) {
    const std::size_t end = at + flag.size();
    const bool word_end = end == help.size() || !(std::isalnum(static_cast<unsigned char>(help[end])) ||
                                                  help[end] == '-' || help[end] == '_');
    if (word_end) return true;
  }
  return false;
}

std::string MapTmp(const std::string& text, const std::string& scratch_tmp) {
  static const std::regex tmp(R"((^|[\s='"])/tmp/)");
  return std::regex_replace(text, tmp, "$1" + scratch_tmp + "/");
}

}  // namespace fitcal::testing::docs
