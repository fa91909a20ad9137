#pragma once
// The generic replay (odometry/replay.h) of a model's kinematics K (kinematic_model.h).

#include <cstddef>
#include <utility>

#include "odometry/encoder_samples.h"
#include "odometry/pose2.h"
#include "odometry/replay.h"

namespace fitcal {

// Replays samples [begin, end) with the kinematics K at parameters p.
template <class K, typename T, typename Visitor = replay_internal::NoVisit>
Pose2<T> ReplayKinematics(const K& kinematics, const T* p, const EncoderSamples& samples,
                          std::size_t begin, std::size_t end, const Pose2<T>& start,
                          Visitor&& visit = Visitor()) {
  const auto prepared = kinematics.Prepare(p);
  const auto step = [&kinematics, &prepared ](const double* values, double dt, T* dx, T* dy,
                                              T* dtheta) __attribute__((always_inline)) {
    kinematics.BodyStep(prepared, values, dt, dx, dy, dtheta);
  };
  return ReplaySteps(step, samples, begin, end, start, std::forward<Visitor>(visit));
}
template <class K, typename T, typename Visitor = replay_internal::NoVisit>
Pose2<T> ReplayKinematics(const T* p, const EncoderSamples& samples, std::size_t begin,
                          std::size_t end, const Pose2<T>& start, Visitor&& visit = Visitor()) {
  return ReplayKinematics(K(), p, samples, begin, end, start, std::forward<Visitor>(visit));
}

}  // namespace fitcal
