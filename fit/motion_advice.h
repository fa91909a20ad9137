#pragma once
// What to drive to determine a direction the training runs left undetermined (issue 29 item 5,
// issue 30 item 2: advice from candidate motions for every model). A small set of standard
// motions - a straight run, a sideways run, a half turn on the spot, quarter circles to each side -
// is realised for the model at hand through its ChannelsForTwist (a motion the model cannot drive
// is skipped: a differential drive does not go sideways), each as a noise-free run judged at its
// final pose (Palacin Eq. 14). A motion determines the direction when k runs of it, added to the
// training runs, bring the direction's posterior fraction to kMaxPosteriorFraction
// (fit/determined_directions.h): the data's information 1 / f^2 plus k times the run's own.
//
// The common scale of wheels and track is the case that matters on closed loops: every loop ends
// where it started whatever the scale, a straight run's end moves with it.

#include <string>
#include <vector>

#include "fit/determined_directions.h"
#include "models/model_interface.h"
#include "odometry/aligned_run.h"

namespace fitcal {

struct StandardMotion {
  std::string words;  // "a straight run of 2 m"
  Twist twist;        // robot frame, held for duration_s
  double duration_s = 0.0;
};

// The motions advised from, at walking pace (0.3 m/s, 0.6 rad/s on the spot).
std::vector<StandardMotion> StandardMotions();

// The noise-free run of `motion` from the origin with the channel values that drive it with
// parameters p (sampled every 0.02 s; the ground truth's final pose is the twist's exact end);
// false when the model cannot drive it.
bool RunOfMotion(const RobotModelInterface& model, const std::vector<double>& p,
                 const StandardMotion& motion, AlignedRun* run);

struct MotionThatDetermines {
  std::string words;
  int runs = 0;  // runs of it that determine the direction
};

// The motions that determine `d` in at most kMaxAdvisedRuns runs each, fewest runs first.
inline constexpr int kMaxAdvisedRuns = 10;
std::vector<MotionThatDetermines> MotionsThatDetermine(const UndeterminedDirection& d,
                                                       const RobotModelInterface& model,
                                                       const std::vector<double>& p,
                                                       const ResidualWeights& weights);

// One line for the terminal: "to determine it, drive ..." or, when no standard motion does, what
// else would.
std::string MotionAdviceLine(const std::vector<MotionThatDetermines>& motions);

}  // namespace fitcal
