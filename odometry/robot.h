#pragma once
// What fitcal knows about one robot before fitting, for any kinematic model: its encoder
// channels, its parameters (names built from the robot's own wheel names, units, nominal values,
// the box the fit may search) and what is held fixed by construction (gauge). Filled by the
// model's YAML reader (models/<model>/..._yaml.cc); read by every generic algorithm.

#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "odometry/effects.h"

namespace fitcal {

struct EncoderLog;  // odometry/run_log.h

struct Interval {
  double lo = 0.0;
  double hi = 0.0;
  bool Contains(double v) const { return v >= lo && v <= hi; }
  double Width() const { return hi - lo; }
};

// What one encoder column measures.
//   kWheelRate  a wheel's mean rate over the interval (rad/s); from ticks when the log has ticks.
//   kAngle      an absolute angle such as a steering or castor pivot angle (rad). The loader turns
//               the readings at the row times into the mean over each interval (the midpoint of
//               the two readings): the body motion of an interval is best approximated at its
//               middle (midpoint rule), and a reading at either end would lag or lead by dt/2.
enum class ChannelKind { kWheelRate, kAngle };

struct ChannelInfo {
  std::string name;  // the robot's own name for it ("a", "left", "steering")
  ChannelKind kind = ChannelKind::kWheelRate;
  // Encoder CSV column names that carry this channel: rate (or angle) and, for wheel rates, the
  // ticks column ("w_a" / "ticks_a"; "steering").
  std::string rate_column;
  std::string ticks_column;
};

// How the encoders count, when the logs hold ticks instead of wheel rates (robot YAML `encoder:`):
// ticks per wheel revolution (gear ratio x counts per motor revolution) and whether the log holds
// running totals (cumulative) or increments since the previous row.
// counter_bits (16 or 32; 0 = not declared): the width of the recorder's counter, whose counts
// wrap modulo 2^bits (running totals and per-interval counts alike); declared, they are unwrapped
// on load, undeclared a wrap is refused.
struct EncoderTicks {
  double ticks_per_rev = 0.0;
  bool cumulative = false;
  int counter_bits = 0;
};

// An angle channel recorded as counts of an absolute encoder (robot YAML
// `<channel>_encoder: {ticks_per_rev: N, zero_tick: Z}`, CSV column `ticks_<channel>`):
//   angle = 2 pi (count - zero_tick) / ticks_per_rev, wrapped to (-pi, pi].
struct AngleEncoder {
  std::string channel;
  double ticks_per_rev = 0.0;
  double zero_tick = 0.0;
};

// kRatio: a dimensionless factor (a steering gain): unit "1" (SI's unit of a dimensionless
// quantity), changes printed in % like a length's.
enum class ParameterUnit { kLength, kAngle, kRatio };

struct ParameterInfo {
  std::string name;   // "R_a", "r_left", "wheelbase"
  std::string group;  // the YAML's bounds key the parameter belongs to ("distance_m", ...)
  ParameterUnit unit = ParameterUnit::kLength;
  // Printed unit and factor: lengths in m, angles in deg (I/O edge only), ratios 1.
  const char* DisplayUnit() const {
    return unit == ParameterUnit::kAngle ? "deg" : unit == ParameterUnit::kRatio ? "1" : "m";
  }
  // The key of its value in a calibrated YAML's `sigma:` and in tables of values: the name with
  // its unit ("r_left_m", "delta_a_deg"); a ratio's name alone, as its robot YAML key.
  std::string KeyName() const {
    return unit == ParameterUnit::kRatio ? name : name + "_" + DisplayUnit();
  }
  double DisplayScale() const { return unit == ParameterUnit::kAngle ? 180.0 / M_PI : 1.0; }
  // A wheel's radius: a parameter of a `..radius_m` bounds group.
  bool IsWheelRadius() const {
    return group.size() >= 8 && group.compare(group.size() - 8, 8, "radius_m") == 0;
  }
  // Identifiability measures lengths as relative changes and angles in radians, so that one
  // number means the same for every parameter (a 1 % radius change ~ a 0.01 rad turn).
  double RelativeScale(double value) const {
    return unit == ParameterUnit::kAngle ? 1.0 : std::abs(value) > 0.0 ? std::abs(value) : 1.0;
  }
};

// A parameter the model holds at its nominal value because no odometry data can determine it
// (the combination it enters is fixed by another), with the reason in words.
struct HeldParameter {
  int index = 0;
  std::string reason;
};

struct Robot {
  std::string model;  // the YAML's `model:`
  std::string name;
  std::vector<ChannelInfo> channels;
  std::vector<ParameterInfo> parameters;
  std::vector<double> nominal;   // the fit's start (Palacin Eq. 15 for omni3)
  std::vector<Interval> bounds;  // absolute, per parameter (Palacin Eq. 16 for omni3)
  std::vector<HeldParameter> held;
  std::optional<EncoderTicks> encoder;  // set when the encoder logs are in ticks
  std::vector<AngleEncoder> angle_encoders;  // angle channels that may be recorded as counts
  // Effects beyond the model's parameters (robot YAML `effects:`, written by `fitcal diagnose`).
  std::vector<effects::EffectValue> effects;
  // A model whose robots record their encoders in a file format of their own (ASOC's cumulative
  // wheel angles and pivot readings) reads it here, as the model's channels: true when `path` is
  // in that format and *log was filled; false sends the file to the generic encoder CSV reader.
  // The data-set loader (io/dataset.cc) calls it without knowing any model.
  std::function<bool(const std::string& path, EncoderLog* log)> read_own_encoder_file;

  int NumParameters() const { return static_cast<int>(parameters.size()); }
  int NumChannels() const { return static_cast<int>(channels.size()); }
  bool IsHeld(int k) const {
    for (const HeldParameter& h : held) {
      if (h.index == k) return true;
    }
    return false;
  }
  int NumFree() const { return NumParameters() - static_cast<int>(held.size()); }
  // One flag per parameter: whether it is held (the fits' and the gate's `held` vectors).
  std::vector<bool> HeldFlags() const {
    std::vector<bool> flags(parameters.size(), false);
    for (const HeldParameter& h : held) flags[h.index] = true;
    return flags;
  }
  // Whether these channels let the effect act (effects::ChannelsCanCarry).
  bool CanShow(effects::EffectId id) const {
    bool has_angle = false;
    for (const ChannelInfo& c : channels) has_angle = has_angle || c.kind == ChannelKind::kAngle;
    return effects::ChannelsCanCarry(id, NumChannels(), has_angle);
  }
  // "R_a [m]" for tables.
  std::string LabelOf(int k) const {
    return parameters[k].name + " [" + parameters[k].DisplayUnit() + "]";
  }
};

}  // namespace fitcal
