#pragma once
// --tie and --hold (fit/parameter_tying.h), declared, read and printed in one place for every
// command that fits a reduced model beside (or instead of) the full one: `fit`, `generalise`,
// `compare`. One parser, so that a name `fit` accepts is accepted everywhere and a refusal reads
// the same.

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "fit/parameter_tying.h"
#include "odometry/robot.h"

namespace fitcal::tools {

struct TyingFlags {
  // --tie "R_a,R_b,R_c" (repeatable): each a group of parameters sharing one value; --hold
  // "delta_a,delta_b": parameters held at their nominal values.
  std::vector<std::string> tie;
  std::vector<std::string> hold;
  bool empty() const { return tie.empty() && hold.empty(); }
};

// Declares --tie and --hold on `app`, bound to `flags`.
void AddTyingFlags(CLI::App& app, TyingFlags& flags);

// The tying the flags name, checked against `robot` (CheckTying): "" with *tying filled, or one
// line saying what is wrong (the caller prints it and exits 2).
std::string ReadTying(const TyingFlags& flags, const Robot& robot, ParameterTying* tying);

// "tied (one value): R_a=R_b=R_c" per group and "held at nominal (--hold): ..." on stdout.
void PrintTying(const ParameterTying& tying);

}  // namespace fitcal::tools
