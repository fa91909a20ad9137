#pragma once

#include <string>
#include <utility>

namespace fitcal {

// The refusal of a check that reports through `std::string* error` (an options struct's
// IsValid, a decoder): sets the reason and returns false, so that each check is one statement,
// `if (max_effects < 0) return Invalid(error, "max_effects must be >= 0");`.
inline bool Invalid(std::string* error, std::string reason) {
  *error = std::move(reason);
  return false;
}

}  // namespace fitcal
