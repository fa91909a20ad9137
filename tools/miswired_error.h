#pragma once
// The recordings' channel order or signs are not the documented ones (another mapping explains
// the ground truth better): every import says so with exit status 4, as `fit` does for the same
// finding (README, exit codes), not 1 (bad input) or 3 (which means a fit that did not converge).

#include <stdexcept>

namespace fitcal::tools {

class MiswiredError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline constexpr int kMiswiredExitCode = 4;

}  // namespace fitcal::tools
