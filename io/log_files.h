#pragma once
// Loaders for the per-run log files of a data set (format: README.md, "Data set format").

#include <string>
#include <vector>

#include "odometry/reading_resolution.h"
#include "odometry/robot.h"
#include "odometry/run_log.h"

namespace fitcal::io {

// Encoder CSV, header `t,w_a,w_b,w_c`: t in s (strictly increasing), w the mean wheel rate in
// rad/s over (t(k-1), t(k)]; row 0 only sets the start time.
// Or header `t,ticks_a,ticks_b,ticks_c`: encoder ticks, which need `ticks` (the robot YAML's
// `encoder:` block). Increments: row k holds the ticks counted over (t(k-1), t(k)] and row 0's
// are ignored (counted before the start); cumulative: running totals, row 0 is the reference,
// and its count gives each wheel's absolute angle at the start (EncoderLog::start_angle_rad).
// Either way w_i(k) = 2 pi dticks_i(k) / (ticks_per_rev dt(k)). With `counter_bits: 16|32` the
// counts are modulo 2^bits and each increment is taken as the residue nearest zero (unwrapped);
// without it a wrap is refused. Glitches of a wheel's counter (a count no wheel of the robot's
// size turns, a backwards jump inside forward motion) are named with their line, bridged by the
// neighbouring counts and counted in EncoderLog::dropped_glitches.
// An angle channel declared with `<channel>_encoder: {ticks_per_rev: N, zero_tick: Z}` may be
// recorded as counts in `ticks_<channel>` (AngleOfCount).
// Any robot (odometry/robot.h): header `t,<column per channel>`, each channel's rate (or angle)
// column or its ticks column, in any order, matched by name; angle channels hold the reading at
// the row time and become the mean over each interval. A three-channel robot also accepts the
// positional legacy header above whatever its wheel names.
EncoderLog ReadEncoderCsv(const std::string& path, const Robot& robot);

// Turns encoder CSV rows (as written: per channel a rate, an angle reading at the row time, or
// ticks) into the interval samples of an EncoderLog, one row at a time; shared by the reader and
// by anything that produces rows in memory (simulators, importers, bag readers).
class EncoderRowConverter {
 public:
  // channel_of_column[j]: which robot channel column j holds; ticks_column[j]: in ticks.
  EncoderRowConverter(const Robot& robot, std::vector<int> channel_of_column,
                      std::vector<bool> ticks_column);
  // A converter for rows in the robot's channel order, no ticks.
  explicit EncoderRowConverter(const Robot& robot);
  void Reserve(std::size_t rows) {
    log_.t_s.reserve(rows);
    log_.samples.reserve(rows);
  }
  // t_s must increase (checked by the caller); row holds one value per column.
  void Add(double t_s, const double* row);
  const EncoderSamples& samples() const { return log_.samples; }
  // The log, with each angle channel's reading step (EncoderLog::reading_step_rad).
  EncoderLog Take();

 private:
  const Robot& robot_;
  std::vector<int> channel_of_column_;
  std::vector<bool> ticks_column_;
  std::vector<double> previous_;
  bool any_ticks_ = false;
  double rad_per_tick_ = 0.0;
  bool cumulative_ = false;
  double counter_modulus_ = 0.0;  // 2^counter_bits; 0 when the width is not declared
  std::vector<const AngleEncoder*> angle_encoder_;  // per column: an angle channel's counts
  std::vector<ReadingGrid> reading_grid_;           // per column: an angle channel's readings
  EncoderLog log_;
};

// An absolute encoder's count as an angle (odometry/robot.h AngleEncoder), in (-pi, pi].
double AngleOfCount(const AngleEncoder& encoder, double count);

// Whether a wheel (a rate channel) turns faster than 0.01 rad/s in sample k (false past the end):
// what the loaders call moving.
bool WheelsTurn(const EncoderSamples& samples, std::size_t k, const Robot& robot);

// Ground truth: CSV with header `t,x,y,theta` (s, m, m, rad), or a TUM trajectory
// (`t x y z qx qy qz qw`, blank-separated, '#' comments) whose yaw is taken from the quaternion.
GroundTruthTrack ReadGroundTruth(const std::string& path);

}  // namespace fitcal::io
