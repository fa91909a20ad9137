#pragma once
// Palacin Table 4 on any data set (`fitcal compare`): every trajectory strategy (STA..STE,
// explicit label lists, "all" or a label prefix) x every fit method x training on the first k
// repetitions, each fit (and the model's closed forms) scored by CF (Eq. 14) on its training runs
// and on every trajectory of the held-out repetitions. The decisions of the comparison - which
// strategies apply to the data set, which repetitions validate, which fits run - live here; the
// command reads its flags, loads the runs, calls CompareMethods and writes the rows.

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "calibrate/fit_methods.h"
#include "fit/nlopt_search.h"
#include "fit/parameter_tying.h"
#include "fit/strategies.h"
#include "models/model_interface.h"
#include "odometry/aligned_run.h"

namespace fitcal {

struct ComparisonRow {
  std::string strategy;
  std::string method;
  int repetitions = 0;             // 0 = the uncalibrated reference row
  std::vector<double> parameters;  // empty for the uncalibrated reference row
  double cf_calibration = NAN;
  double cf_validation = NAN;
  double improvement_percent = NAN;
  int evaluations = 0;
  double wall_s = 0.0;
  std::string termination;
  bool usable = true;
  std::vector<ConvergencePoint> trace;
};

// What to watch while the fits run (the command prints it on a terminal); either may be empty.
struct ComparisonProgress {
  // `label` is "<strategy> <method> x<k>".
  std::function<void(const std::string& label, const NloptProgress&)> during;
  std::function<void(const std::string& label, const ComparisonRow&)> done;
};

struct ComparisonRequest {
  std::string data_name;  // the data set as the user named it, for the refusals
  RobotModelPtr model;
  std::vector<AlignedRun> runs;
  std::vector<const FitMethod*> methods;
  std::vector<TrajectoryStrategy> strategies;  // as ParseCompareStrategy read them
  // False: the strategies of the default list the data set has are kept, or "all" when it has
  // none (STA..STE need the flower's labels).
  bool strategies_given = true;
  std::vector<int> counts;           // training repetitions k, sorted, unique, >= 1
  std::vector<int> validation_reps;  // empty: the repetitions after the largest k
  FitMethodSettings settings;
  ParameterTying tying;  // not empty: every method also fits the reduced model, "<method> (tied)"
  int threads = 0;
  ComparisonProgress progress;
};

struct MethodComparison {
  // Not empty: the request does not fit the data set (the command's usage error, exit 2).
  std::string refusal;
  std::vector<int> validation_reps;
  std::size_t num_validation = 0;  // runs of the validation repetitions
  // The uncalibrated reference row first, then for every strategy and k the closed forms' rows
  // and each method's fit (and, with a tying, its tied fit right after it).
  std::vector<ComparisonRow> rows;
};

// "all" (every trajectory of the data set) and "<prefix>*" (the labels starting with prefix, e.g.
// "circular/*") are resolved against the runs by CompareMethods; anything else is
// fit/strategies.h's ParseStrategy (throws std::invalid_argument).
TrajectoryStrategy ParseCompareStrategy(const std::string& text);

// Throws std::invalid_argument when "all" or a prefix matches no trajectory of the data set.
MethodComparison CompareMethods(ComparisonRequest request);

}  // namespace fitcal
