#pragma once
// CLI11 validators shared by the subcommands, so a malformed flag value is a usage error (exit 2,
// one line) found while the command line is parsed, before any file is read.

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>

#include "fit/run_split.h"

namespace fitcal::tools {

// Once `app` is parsed, the long names of the flags given on its command line ("--method") into
// *given: what a command reads later to tell a flag given from its default.
inline void RecordGivenFlags(CLI::App& app, std::set<std::string>* given) {
  app.callback([&app, given] {
    for (const CLI::Option* option : app.get_options()) {
      if (option->count() > 0) given->insert(option->get_name());
    }
  });
}

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

// --joints: each comma-separated item a joint name. An empty item (`--joints ,`) made CLI11 take
// the flags that followed as joint names (`--out` written into the controller's wheel names,
// exit 0): an item that is empty or starts with "--" (a long flag; one dash may begin a name) is
// refused.
inline CLI::Validator JointNameValidator() {
  return CLI::Validator(
      [](std::string& text) {
        if (text.empty()) return std::string("holds an empty joint name (a stray comma?)");
        if (text.rfind("--", 0) == 0) {
          return "takes joint names, not '" + text + "' (a flag? give the names, comma-separated)";
        }
        return std::string();
      },
      "NAME,...", "joint names");
}

// The whole text read as a double (strtod's syntax: "nan" and "inf" too); nothing when any of it
// is not part of the number.
inline std::optional<double> WholeTextNumber(const std::string& text) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size()) return std::nullopt;
  return value;
}

// A number option: nan and inf parse as doubles and pass CLI11's PositiveNumber and Range (every
// comparison with nan is false), then reach the fit as a weight or a bound of nan.
inline CLI::Validator FiniteNumberValidator() {
  return CLI::Validator(
      [](std::string& text) {
        const std::optional<double> value = WholeTextNumber(text);
        if (value && !std::isfinite(*value)) {
          return "must be a finite number, found '" + text.substr(0, 40) + "'";
        }
        return std::string();  // not a number at all: CLI11's conversion says so
      },
      "", "finite number");
}

// A number above 0 (or at least 0), said in fitcal's words: CLI11's PositiveNumber prints its
// range up to the largest double in 300 digits.
inline CLI::Validator SignValidator(bool zero_allowed) {
  return CLI::Validator(
      [zero_allowed](std::string& text) {
        const std::optional<double> value = WholeTextNumber(text);
        if (!value) return "must be a number, found '" + text.substr(0, 40) + "'";
        if (zero_allowed ? *value >= 0 : *value > 0) return std::string();
        return std::string(zero_allowed ? "must be 0 or more" : "must be above 0") + ", found '" +
               text.substr(0, 40) + "'";
      },
      zero_allowed ? "NONNEGATIVE" : "POSITIVE", zero_allowed ? "non-negative" : "positive");
}
inline CLI::Validator PositiveNumber() { return SignValidator(false); }
inline CLI::Validator NonNegativeNumber() { return SignValidator(true); }

// A residual's sigma no finer than `floor` (1e-9 m, a nanometre): 1e-300 weighed a metre as 1e300,
// the squared cost overflowed, the solve failed and its tables printed nan.
inline CLI::Validator SigmaAtLeast(double floor, const std::string& unit) {
  return CLI::Validator(
      [floor, unit](std::string& text) {
        const std::optional<double> value = WholeTextNumber(text);
        if (!value) return "must be a number, found '" + text.substr(0, 40) + "'";
        if (*value >= floor) return std::string();
        char line[160];
        std::snprintf(line, sizeof line, "must be at least %g %s (finer than any ground truth), "
                      "found '%s'", floor, unit.c_str(), text.substr(0, 40).c_str());
        return std::string(line);
      },
      "SIGMA", "sigma");
}

// Adds the validators above to every --threads and --out option and every floating-point option
// (CLI11 names their type FLOAT) of `app` and its subcommands, so that every command refuses
// these alike.
inline void AddCommonValidators(CLI::App& app) {
  if (CLI::Option* threads = app.get_option_no_throw("--threads")) {
    threads->check(ThreadCountValidator());
  }
  if (CLI::Option* out = app.get_option_no_throw("--out")) out->check(NonEmptyPathValidator());
  for (CLI::Option* option : app.get_options()) {
    if (option->get_type_name().rfind("FLOAT", 0) == 0) option->check(FiniteNumberValidator());
  }
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
    AddCommonValidators(*sub);
  }
}

}  // namespace fitcal::tools
