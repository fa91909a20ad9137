#pragma once
// CLI11 validators shared by the subcommands, so a malformed flag value is a usage error (exit 2,
// one line) found while the command line is parsed, before any file is read.

#include <CLI/CLI.hpp>
#include <stdexcept>
#include <string>

#include "validation/run_split.h"

namespace fitcal::tools {

// A repetition list such as "1-5" or "1,3,7" (validation/run_split.h); "auto" too when allowed.
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

}  // namespace fitcal::tools
