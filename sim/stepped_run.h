#pragma once
// The flower's time-stepped physics for any model on the seam (SteppedOptions in
// model_simulator.h), one run at a time. Internal to the simulator: SimulateRuns calls it when
// SimulationOptions::stepped is set.
//
// Per substep h (Palacin's APR-02 as data/flower was made):
//   target  = ChannelsForTwist(p_commanded, twist of the segment holding t + h/2), 0 at rest
//   x      += (1 - exp(-h / tau)) (target - x)                 controller lag, channel state x
//   s_i     = exp(-h / T) s_i + sigma sqrt(1 - exp(-2h / T)) N  slip, Ornstein-Uhlenbeck
//   c_i     = x_i (1 + s_i) (1 + e_i cos A_i)                   contact rate (wheel channels)
//   v       = Step(p_true, c, dt) / dt                          the model's body twist
//   pose   += h R(theta + h omega / 2) v                        midpoint heading
//   A_i    += h x_i                                             wheel angle, counted by encoders
// Random draws, in the order the shipped flower drew them (so it is reproduced bit for bit): the
// start pose (x, y, heading), the initial slips, the first ground-truth time, then per latch the
// encoder jitter and per ground-truth sample three noises and the next interval, and per substep
// the slips. The generator is std::mt19937_64 (fully specified by the standard) seeded by
// SplitMix64(seed ^ SplitMix64(run index)), with hand-written distributions.

#include <cstdint>
#include <string>
#include <vector>

#include "models/model_interface.h"
#include "odometry/split_mix.h"
#include "sim/model_simulator.h"

namespace fitcal::sim {

// Empty when the stepped options are valid for a robot of num_channels channels, else what is
// wrong.
std::string CheckSteppedOptions(const SteppedOptions& stepped, double encoder_period_s,
                                int num_channels);

// One run (options.stepped set); `stream` is the run's index in the simulation.
ModelSimulatedRun SimulateSteppedRun(const RobotModelInterface& model,
                                     const std::vector<double>& true_parameters,
                                     const TrajectorySpec& spec, const SimulationOptions& options,
                                     std::uint64_t stream);

}  // namespace fitcal::sim
