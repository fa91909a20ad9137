#pragma once
// The approval tests' matcher of printed text (generalise_approval_test and others): an expected
// line matches a printed one with the same words and the same numbers, a number with a fractional
// part to one unit in its last printed decimal (the last bits of sums over runs evaluated in
// parallel and of fits stopped on Ceres' tolerances may round either way), a whole number exactly
// ("drift 2 m" is not "drift 1 m", "(342 windows)" not "(341 windows)"). And a line matches only
// within its block: the expected lines come in blocks, and all the lines of one block must be
// found in one printed block (lines between blank lines), so "ATE RMSE" of one candidate's table
// never stands in for another's.

#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

namespace fitcal::testing {

inline std::vector<std::string> Tokens(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> out;
  for (std::string t; in >> t;) out.push_back(t);
  return out;
}

// A printed number ("0.0176", "-9.1%", "+49.9%", "342"): its value and the tolerance of a match,
// one unit in its last printed decimal place, 0 for a whole number; false for any other token.
inline bool PrintedNumber(std::string token, double* value, double* tolerance) {
  if (!token.empty() && token.back() == '%') token.pop_back();
  char* end = nullptr;
  *value = std::strtod(token.c_str(), &end);
  if (token.empty() || end != token.c_str() + token.size()) return false;
  const std::size_t dot = token.find('.');
  const int decimals = dot == std::string::npos ? 0 : static_cast<int>(token.size() - dot - 1);
  *tolerance = decimals == 0 ? 0.0 : std::pow(10.0, -decimals);
  return true;
}

// One expected line against one printed line, both as tokens.
inline bool LineMatches(const std::vector<std::string>& want, const std::vector<std::string>& got) {
  if (got.size() != want.size()) return false;
  for (std::size_t k = 0; k < want.size(); ++k) {
    double a, b, tolerance, unused;
    if (PrintedNumber(want[k], &a, &tolerance) && PrintedNumber(got[k], &b, &unused)) {
      if (!(std::abs(a - b) <= tolerance * (1.0 + 1e-9))) return false;
    } else if (want[k] != got[k]) {
      return false;
    }
  }
  return true;
}

// The printed blocks of `out`: runs of non-blank lines, each line as tokens.
inline std::vector<std::vector<std::vector<std::string>>> PrintedBlocks(const std::string& out) {
  std::vector<std::vector<std::vector<std::string>>> blocks(1);
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);) {
    std::vector<std::string> t = Tokens(line);
    if (t.empty()) {
      if (!blocks.back().empty()) blocks.emplace_back();
    } else {
      blocks.back().push_back(std::move(t));
    }
  }
  return blocks;
}

// The lines of `expected` (one block) that no single printed block of `out` holds all of: empty
// when some printed block matches every line; else the lines missing from the printed block that
// matches most of them.
inline std::vector<std::string> MissingFromBlock(const std::string& out,
                                                 const std::vector<std::string>& expected) {
  std::vector<std::string> best = expected;
  for (const auto& block : PrintedBlocks(out)) {
    std::vector<std::string> missing;
    for (const std::string& line : expected) {
      const std::vector<std::string> want = Tokens(line);
      bool found = false;
      for (const auto& got : block) found = found || LineMatches(want, got);
      if (!found) missing.push_back(line);
    }
    if (missing.size() < best.size()) best = missing;
  }
  return best;
}

}  // namespace fitcal::testing
