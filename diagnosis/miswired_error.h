#pragma once
// The recordings' channel order or signs are not the documented ones (another mapping explains
// the ground truth better): every import says so with exit status 4, as `fit` does for the same
// finding (README, exit codes), not 1 (bad input) or 3 (which means a fit that did not converge).

#include "io/command_failure.h"

namespace fitcal {

inline constexpr int kMiswiredExitCode = 4;

class MiswiredError : public CommandFailure {
 public:
  explicit MiswiredError(const std::string& what) : CommandFailure(kMiswiredExitCode, what) {}
};

}  // namespace fitcal
