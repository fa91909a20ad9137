#pragma once
// CLI11 validators shared by the subcommands, so a malformed flag value is a usage error (exit 2,
// one line) found while the command line is parsed, before any file is read.

#include <CLI/CLI.hpp>
#include <stdexcept>
#include <string>

#include "fit/run_split.h"

namespace fitcal::tools {

// A repetition list such as "1-5" or "1,3,7" (fit/run_split.h); "auto" too when allowed.
inline CLI::Validator RepetitionListValidator(bool allow_auto = false) {
  return CLI::Validator(
      [allow_auto](std::string& text) {
        if (allow_auto && text == "auto") return std::string();
        try {
          ParseRepetitionList(text);
          return std::string();
        } catch (const std::invalid_argument& e) {
          return std::string(e.what());
        }
      },
      "REPS", "repetition list");
}

// --threads: a whole number from 0 (all cores) to kMaxThreads, said in fitcal's words instead of
// the parser's ("could not be converted").
inline constexpr int kMaxThreads = 1024;
inline CLI::Validator ThreadCountValidator() {
  return CLI::Validator(
      [](std::string& text) {
        std::size_t used = 0;
        long value = -1;
        try {
          value = std::stol(text, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used == 0 || used != text.size() || value < 0 || value > kMaxThreads) {
          return "must be a whole number of worker threads from 0 (all cores) to " +
                 std::to_string(kMaxThreads) + ", found '" + text.substr(0, 40) + "'";
        }
        return std::string();
      },
      "THREADS", "thread count");
}

// --out: a path, never the empty string (found before any work, not after a whole fit).
inline CLI::Validator NonEmptyPathValidator() {
  return CLI::Validator(
      [](std::string& text) {
        return text.empty() ? std::string("is empty; name the file or directory to write")
                            : std::string();
      },
      "PATH", "non-empty path");
}

// Adds the validators above to every --threads and --out option of `app` and its subcommands,
// so that every command refuses these alike.
inline void AddCommonValidators(CLI::App& app) {
  if (CLI::Option* threads = app.get_option_no_throw("--threads")) {
    threads->check(ThreadCountValidator());
  }
  if (CLI::Option* out = app.get_option_no_throw("--out")) out->check(NonEmptyPathValidator());
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
    AddCommonValidators(*sub);
  }
}

}  // namespace fitcal::tools
