#pragma once
// The resolution of an angle channel's readings, seen in the readings themselves. An absolute
// encoder's count - or the digits a recorder prints - puts every reading on a grid v0 + k q.
// Quantisation is not always noise: while the robot holds an angle (driving straight, an arc)
// and nothing else moves the reading, it stays on one count, so its error is a constant in
// [-q/2, q/2] that no amount of driving averages away (docs/everyday_driving.md, "Sigmas that
// cover": a 12-bit steering encoder put the fitted offset beyond 3 sigma). Noise of the readings
// before the count (dither, sigma_n) spreads a held angle over neighbouring counts, and the mean
// reading's bias then shrinks as the sawtooth's first harmonic does, exp(-2 pi^2 sigma_n^2 / q^2)
// (Widrow and Kollar, "Quantization Noise", 2008, Ch. 4). The fit's sigma has a floor the data
// cannot lower: ReadingResolution::BiasSigma (calibrate/reading_resolution_uncertainty.h).

#include <cstdint>
#include <map>

namespace fitcal {

struct ReadingResolution {
  double step_rad = 0.0;  // q; 0: no grid seen
  // The flicker: readings with two before them, and those that leave the previous reading's count
  // and come straight back (a, b, a). Counts, so that runs pool.
  std::int64_t readings = 0, reversals = 0;
  // sigma_n / q (NoiseOverStepOfReversals of reversals / readings).
  double NoiseOverStep() const;
  // The standard deviation of the constant error of a held angle's mean reading: q / sqrt(12)
  // (uniform over a count) times exp(-2 pi^2 (sigma_n / q)^2).
  double BiasSigma() const;
};

// The readings' noise over the step, sigma_n / q, whose flicker rate is `reversals_per_reading`:
// the fraction of readings that leave the previous one's count and come straight back (a, b, a).
// For a held angle anywhere in its count (uniform) and Gaussian noise, that rate is the mean over
// the count of p (1 - p), p the chance that the noisy angle lies outside the count; inverted on
// [0, 0.5] (0.5 and above: the bias is gone, exp(-2 pi^2 / 4) = 0.7 %). Ramps of a noiseless
// angle make no such pattern. A log that holds mostly one angle near its count's centre flickers
// less than the uniform spread assumes and reads as less noise: the floor then errs wide.
double NoiseOverStepOfReversals(double reversals_per_reading);

class ReadingGrid {
 public:
  void Add(double reading);
  // The readings' resolution: the grid and the flicker over it (step 0: no grid), or with
  // `known_step_rad` > 0 (an absolute encoder's count) that step and the flicker. The grid: its
  // step q is the 10th percentile of the gaps between consecutive distinct readings (a fast sweep
  // skips counts; a glitch makes a few odd gaps); at least 99 % of the readings lie within 1 % of
  // q of the grid through the most frequent reading, on at least kMinGridValues distinct places,
  // and q is at least kMinStepRad.
  // Else none: too few distinct values (a few set-points), or values off any grid (a continuous,
  // noisy channel). Readings held at 8 or more set-points and never between them would pass as a
  // grid as wide as their spacing.
  ReadingResolution Resolution(double known_step_rad = 0.0) const;

  static constexpr int kMinGridValues = 8;
  // Finer steps are round-off between computed readings, not a count (a 29-bit encoder's count is
  // 1.2e-8 rad).
  static constexpr double kMinStepRad = 1e-8;
  // Beyond this many distinct readings the channel is taken as continuous (a 16-bit encoder's
  // whole turn fits).
  static constexpr int kMaxDistinct = 65536;

 private:
  double Step() const;

  std::map<double, std::int64_t> count_of_value_;
  std::int64_t total_ = 0;
  bool continuous_ = false;
  // The flicker: readings with two before them, and those that repeat the one two back after a
  // change (a, b, a).
  double before_ = 0.0, last_ = 0.0;
  std::int64_t with_two_before_ = 0, reversals_ = 0;
};

}  // namespace fitcal
