#include "io/log_files.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <limits>
#include <new>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <utility>

#include "io/input_error.h"
#include "io/sample_checks.h"
#include "io/text_file.h"
#include "io/warnings.h"
#include "odometry/text_format.h"

namespace fitcal::io {

namespace {

constexpr int kMaxColumns = 1 + kMaxChannels;

// Splits `line` at `separator` (or at runs of blanks when separator is ' ') into exactly n
// numbers; throws with the file, the line and the offending field otherwise.
// The common case of a comma-separated row of n finite numbers, parsed in one pass without
// splitting (the loaders' hot loop). Accepts exactly what the general path below accepts; returns
// false on anything unusual, and the general path then finds and reports the problem.
bool ParseCommaRowFast(std::string_view line, int n, double* out) {
  const char* p = line.data();
  const char* const end = p + line.size();
  for (int i = 0; i < n; ++i) {
    while (p < end && (*p == ' ' || *p == '\t')) ++p;
    if (p < end && *p == '+') ++p;
    const auto result = std::from_chars(p, end, out[i]);
    if (result.ec != std::errc() || result.ptr == p || !std::isfinite(out[i])) return false;
    p = result.ptr;
    while (p < end && (*p == ' ' || *p == '\t')) ++p;
    if (i + 1 < n) {
      if (p == end || *p != ',') return false;
      ++p;
    }
  }
  return p == end;
}

void ParseRow(std::string_view line, char separator, int n, const std::string& path,
              int line_number, double* out) {
  if (separator == ',' && ParseCommaRowFast(line, n, out)) return;
  int count = 0;
  std::size_t pos = 0;
  while (pos <= line.size()) {
    std::size_t end;
    if (separator == ' ') {
      while (pos < line.size() && (line[pos] == ' ' || line[pos] == '\t')) ++pos;
      if (pos >= line.size()) break;
      end = pos;
      while (end < line.size() && line[end] != ' ' && line[end] != '\t') ++end;
    } else {
      end = line.find(separator, pos);
      if (end == std::string_view::npos) end = line.size();
    }
    const std::string_view field = line.substr(pos, end - pos);
    if (count >= n) {
      throw InputError(InputErrorKind::kWrongColumnCount, path, line_number,
                       "expected " + std::to_string(n) + " fields, found more");
    }
    bool finite = true;
    if (!ParseDouble(field, &out[count], &finite)) {
      throw InputError(InputErrorKind::kNonNumeric, path, line_number,
                       "field " + std::to_string(count + 1) + " is not a number: '" +
                           std::string(Trim(field)) + "'");
    }
    if (!finite) {
      throw InputError(InputErrorKind::kNonFinite, path, line_number,
                       "field " + std::to_string(count + 1) + " is not finite: '" +
                           std::string(Trim(field)) + "'");
    }
    ++count;
    pos = end + 1;
  }
  if (count != n) {
    throw InputError(InputErrorKind::kWrongColumnCount, path, line_number,
                     "expected " + std::to_string(n) + " fields, found " + std::to_string(count));
  }
}

void ExpectHeader(std::string_view line, const std::array<std::string_view, 4>& names,
                  const std::string& path, int line_number) {
  const std::vector<std::string> fields = SplitCsvFields(line);
  if (!std::equal(fields.begin(), fields.end(), names.begin(), names.end())) {
    throw InputError(
        InputErrorKind::kBadHeader, path, line_number,
        "header must be '" + Joined(names, ",") + "', found '" + std::string(line) + "'");
  }
}

void CheckIncreasing(double previous, double t, const std::string& path, int line_number) {
  if (!(t > previous)) {
    throw InputError(InputErrorKind::kNonIncreasingTime, path, line_number,
                     "time " + std::to_string(t) + " s is not after the previous row's " +
                         std::to_string(previous) + " s");
  }
}

bool IsBlank(std::string_view line) { return Trim(line).empty(); }

// An angle in (-pi, pi] (WrapAngle's interval mirrored: a reading of exactly half a turn is +pi).
double WrapToPi(double angle_rad) { return -WrapAngle(-angle_rad); }

// Which channel each CSV column (after t) carries, and whether it holds ticks. Columns are
// matched by name (ChannelInfo::rate_column / ticks_column); a header of the legacy positional
// form `t,w_a,w_b,w_c` (or ticks_a..) is accepted for three-channel robots whatever their wheel
// names, as fitcal always read it.
struct ColumnPlan {
  std::vector<int> channel_of_column;
  std::vector<bool> ticks;
  bool any_ticks = false;
};

std::string ExpectedHeader(const Robot& robot) {
  std::string out = "t";
  for (const ChannelInfo& c : robot.channels) {
    out += "," + c.rate_column;
    if (!c.ticks_column.empty()) out += "|" + c.ticks_column;
  }
  return out;
}

bool MatchLegacyHeader(const std::vector<std::string>& names, const Robot& robot,
                       ColumnPlan* plan) {
  if (robot.NumChannels() != 3 || names.size() != 4) return false;
  static const char* kLegacy[2][3] = {{"w_a", "w_b", "w_c"}, {"ticks_a", "ticks_b", "ticks_c"}};
  for (int kind = 0; kind < 2; ++kind) {
    bool match = true;
    for (int i = 0; i < 3; ++i) match = match && names[i + 1] == kLegacy[kind][i];
    if (!match) continue;
    plan->channel_of_column = {0, 1, 2};
    plan->ticks.assign(3, kind == 1);
    plan->any_ticks = kind == 1;
    return true;
  }
  return false;
}

ColumnPlan PlanColumns(std::string_view header, const Robot& robot, const std::string& path) {
  const std::vector<std::string> names = SplitCsvFields(header);
  const auto bad_header = [&](const std::string& why) {
    return InputError(InputErrorKind::kBadHeader, path, 1,
                      why + "; header must be '" + ExpectedHeader(robot) + "'");
  };
  if (names.empty() || names[0] != "t") throw bad_header("the first column must be 't'");
  ColumnPlan plan;
  if (MatchLegacyHeader(names, robot, &plan)) return plan;
  std::vector<bool> seen(robot.channels.size(), false);
  for (std::size_t col = 1; col < names.size(); ++col) {
    int found = -1;
    bool ticks = false;
    for (int c = 0; c < robot.NumChannels(); ++c) {
      const ChannelInfo& info = robot.channels[c];
      if (names[col] == info.rate_column ||
          (!info.ticks_column.empty() && names[col] == info.ticks_column)) {
        found = c;
        ticks = names[col] == info.ticks_column;
      }
    }
    if (found < 0) {
      for (const ChannelInfo& info : robot.channels) {
        if (info.kind == ChannelKind::kAngle && names[col] == "ticks_" + info.name) {
          throw bad_header("column '" + names[col] + "' holds counts of the angle channel '" +
                           info.name + "': declare " + info.name +
                           "_encoder: {ticks_per_rev: N, zero_tick: Z} in the robot YAML");
        }
      }
      throw bad_header("column '" + names[col].substr(0, 40) + "' is no channel of the robot");
    }
    if (seen[found]) throw bad_header("channel '" + robot.channels[found].name + "' appears twice");
    seen[found] = true;
    plan.channel_of_column.push_back(found);
    plan.ticks.push_back(ticks);
    // An angle channel's counts are converted by its own `<channel>_encoder:` block.
    plan.any_ticks = plan.any_ticks || (ticks && robot.channels[found].kind != ChannelKind::kAngle);
  }
  for (int c = 0; c < robot.NumChannels(); ++c) {
    if (!seen[c]) throw bad_header("channel '" + robot.channels[c].name + "' is missing");
  }
  return plan;
}

// 0, 1, ..., n - 1: the columns of a row in the robot's channel order.
std::vector<int> Identity(int n) {
  std::vector<int> out(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) out[static_cast<std::size_t>(i)] = i;
  return out;
}

}  // namespace

EncoderRowConverter::EncoderRowConverter(const Robot& robot, std::vector<int> channel_of_column,
                                         std::vector<bool> ticks_column)
    : robot_(robot),
      channel_of_column_(std::move(channel_of_column)),
      ticks_column_(std::move(ticks_column)),
      previous_(channel_of_column_.size(), 0.0) {
  log_.samples = EncoderSamples(robot.NumChannels());
  angle_encoder_.assign(channel_of_column_.size(), nullptr);
  reading_grid_.resize(channel_of_column_.size());
  for (std::size_t j = 0; j < channel_of_column_.size(); ++j) {
    if (!ticks_column_[j]) continue;
    const ChannelInfo& channel = robot.channels[channel_of_column_[j]];
    if (channel.kind == ChannelKind::kWheelRate) any_ticks_ = true;
    for (const AngleEncoder& e : robot.angle_encoders) {
      if (e.channel == channel.name) angle_encoder_[j] = &e;
    }
    if (channel.kind == ChannelKind::kAngle && angle_encoder_[j] == nullptr) {
      throw std::logic_error("angle channel '" + channel.name + "' in counts without its encoder");
    }
  }
  if (any_ticks_ && robot.encoder) {
    rad_per_tick_ = 2.0 * M_PI / robot.encoder->ticks_per_rev;
    cumulative_ = robot.encoder->cumulative;
    if (robot.encoder->counter_bits > 0) {
      counter_modulus_ = std::ldexp(1.0, robot.encoder->counter_bits);
    }
  }
}

double AngleOfCount(const AngleEncoder& encoder, double count) {
  return WrapToPi(2.0 * M_PI * (count - encoder.zero_tick) / encoder.ticks_per_rev);
}

EncoderRowConverter::EncoderRowConverter(const Robot& robot)
    : EncoderRowConverter(robot, Identity(robot.NumChannels()),
                          std::vector<bool>(robot.channels.size(), false)) {}

void EncoderRowConverter::Add(double t_s, const double* row) {
  const std::size_t n = channel_of_column_.size();
  if (log_.t_s.empty() && cumulative_) {
    // Cumulative counts: row 0's count is the wheel's absolute angle (mod one revolution).
    log_.start_angle_rad.assign(static_cast<std::size_t>(robot_.NumChannels()),
                                std::numeric_limits<double>::quiet_NaN());
    for (std::size_t j = 0; j < n; ++j) {
      const int c = channel_of_column_[j];
      if (!ticks_column_[j] || robot_.channels[c].kind == ChannelKind::kAngle) continue;
      const double angle = std::fmod(rad_per_tick_ * row[j], 2.0 * M_PI);
      log_.start_angle_rad[static_cast<std::size_t>(c)] = angle < 0.0 ? angle + 2.0 * M_PI : angle;
    }
  }
  if (!log_.t_s.empty()) {
    const double dt = t_s - log_.t_s.back();
    double values[kMaxChannels];
    for (std::size_t j = 0; j < n; ++j) {
      const int c = channel_of_column_[j];
      if (angle_encoder_[j] != nullptr) {
        // Counts of an absolute encoder: the mean of the interval's two readings (robot.h),
        // taken across the +-pi seam the short way.
        const double a0 = AngleOfCount(*angle_encoder_[j], previous_[j]);
        const double a1 = AngleOfCount(*angle_encoder_[j], row[j]);
        values[c] = WrapToPi(a0 + 0.5 * std::remainder(a1 - a0, 2.0 * M_PI));
      } else if (ticks_column_[j]) {
        double dticks = cumulative_ ? row[j] - previous_[j] : row[j];
        // A counter of declared width counts modulo 2^bits: the increment is the residue nearest
        // zero (a running total past 2^bits - 1, or a negative count stored unsigned).
        if (counter_modulus_ > 0.0) {
          dticks -= counter_modulus_ * std::round(dticks / counter_modulus_);
        }
        values[c] = rad_per_tick_ * dticks / dt;
      } else if (robot_.channels[c].kind == ChannelKind::kAngle) {
        values[c] = 0.5 * (previous_[j] + row[j]);  // mean over the interval (robot.h)
      } else {
        values[c] = row[j];
      }
    }
    log_.samples.push_back(dt, values);
  }
  for (std::size_t j = 0; j < n; ++j) {
    previous_[j] = row[j];
    if (robot_.channels[channel_of_column_[j]].kind == ChannelKind::kAngle) {
      reading_grid_[j].Add(row[j]);
    }
  }
  log_.t_s.push_back(t_s);
}

EncoderLog EncoderRowConverter::Take() {
  log_.reading_resolution.assign(static_cast<std::size_t>(robot_.NumChannels()), {});
  for (std::size_t j = 0; j < channel_of_column_.size(); ++j) {
    if (robot_.channels[channel_of_column_[j]].kind != ChannelKind::kAngle) continue;
    // Counts: the encoder's count is the step, whatever the readings visited.
    log_.reading_resolution[static_cast<std::size_t>(channel_of_column_[j])] =
        reading_grid_[j].Resolution(
            angle_encoder_[j] ? 2.0 * M_PI / angle_encoder_[j]->ticks_per_rev : 0.0);
  }
  return std::move(log_);
}

namespace {

// Finite numbers no robot produces, named instead of fitted (a corrupted field, a unit slip such
// as nanoseconds for seconds): wheel rates beyond 1e4 rad/s (95,000 rpm), angles beyond 1e4 rad,
// times beyond 1e10 s (the year 2286 as Unix time; nanosecond stamps are ~1e18), positions beyond
// 1e7 m (no map frame on Earth spans that).
constexpr double kMaxWheelRateRadPerS = 1e4;
constexpr double kMaxAngleRad = 1e4;
constexpr double kMaxTimeS = 1e10;
constexpr double kMaxPositionM = 1e7;

void CheckTimePlausible(double t_s, const std::string& path, int line_number) {
  if (std::abs(t_s) > kMaxTimeS) {
    throw InputError(InputErrorKind::kImplausibleValue, path, line_number,
                     "time " + MessageNumber(t_s) + " s is not a plausible time (limit " +
                         MessageNumber(kMaxTimeS) +
                         " s; nanoseconds or microseconds instead of s?)");
  }
}

// The width in bits of a counter whose wrap would make a jump of `ticks` (within 5 % of 2^bits,
// from 8 to 32 bits), 0 when none.
int WrapBitsOf(double ticks) {
  if (std::abs(ticks) < 128.0) return 0;
  for (int bits = 8; bits <= 32; ++bits) {
    const double wrap = std::ldexp(1.0, bits);
    if (std::abs(std::abs(ticks) - wrap) <= 0.05 * wrap) return bits;
  }
  return 0;
}

std::string CounterWrapMessage(int bits) {
  const std::string b = std::to_string(bits);
  const std::string fix =
      bits == 16 || bits == 32
          ? "declare its width in the robot YAML (encoder: {..., counter_bits: " +
                b + "}) and fitcal unwraps it"
          : "unwrap the counts (add 2^" + b + " after each wrap) before importing";
  return "the tick counter jumps by about 2^" + b + " ticks in one interval: a " + b +
         "-bit counter that wraps inside the run; " + fix;
}

// The last interval's channel values against the limits above. A wheel's counts that the glitch
// screen below reads (screened[c]) are left to it, unless they are the wrap of an undeclared
// counter width.
void CheckSamplePlausible(const EncoderSamples& samples, const Robot& robot,
                          const std::vector<bool>& screened, const std::string& path,
                          int line_number) {
  if (samples.empty()) return;
  const ConstSampleView s = samples.back();
  for (int c = 0; c < robot.NumChannels(); ++c) {
    const bool angle = robot.channels[c].kind == ChannelKind::kAngle;
    const double limit = angle ? kMaxAngleRad : kMaxWheelRateRadPerS;
    if (std::abs(s.value[c]) <= limit) continue;
    if (!angle && robot.encoder && robot.encoder->cumulative &&
        robot.encoder->counter_bits == 0) {  // a wrap, not a rate
      const int bits =
          WrapBitsOf(s.value[c] * s.dt_s * robot.encoder->ticks_per_rev / (2.0 * M_PI));
      if (bits > 0) {
        throw InputError(InputErrorKind::kImplausibleValue, path, line_number,
                         CounterWrapMessage(bits));
      }
    }
    if (screened[static_cast<std::size_t>(c)]) continue;
    throw InputError(InputErrorKind::kImplausibleValue, path, line_number,
                     "channel '" + robot.channels[c].name + "': " + MessageNumber(s.value[c]) +
                         (angle ? " rad is not a physical angle (limit "
                                : " rad/s is not a physical wheel rate (limit ") +
                         MessageNumber(limit) + "; wrong units or a corrupted field?)");
  }
}

// Clock steps and gaps: an interval longer than kGapFactor times the log's median interval (and
// than kMinGapS) while a wheel turns in it or next to it. A rate log's row holds the mean rate of
// its interval, so a clock that jumps 60 s forward multiplies that interval's travel by the jump
// over the true interval, and lost rows leave motion no one measured: refused, not fitted. A gap
// at rest (the recorder idling) is harmless and accepted.
constexpr double kGapFactor = 20.0;
constexpr double kMinGapS = 0.5;
constexpr double kTurningRadPerS = 0.01;

double MedianIntervalS(const EncoderSamples& samples) {
  // A strided subset keeps this O(1) in memory for logs of millions of rows.
  const std::size_t stride = std::max<std::size_t>(1, samples.size() / 100000);
  std::vector<double> dt;
  for (std::size_t k = 0; k < samples.size(); k += stride) dt.push_back(samples[k].dt_s);
  std::nth_element(dt.begin(), dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2), dt.end());
  return dt[dt.size() / 2];
}

// Index of the first sample that is a gap while moving, or samples.size().
std::size_t FindClockGap(const EncoderSamples& samples, const Robot& robot, double* median_s) {
  if (samples.size() < 3) return samples.size();
  *median_s = MedianIntervalS(samples);
  const double limit = std::max(kGapFactor * *median_s, kMinGapS);
  for (std::size_t k = 0; k < samples.size(); ++k) {
    if (samples[k].dt_s <= limit) continue;
    if (WheelsTurn(samples, k, robot) || (k > 0 && WheelsTurn(samples, k - 1, robot)) ||
        WheelsTurn(samples, k + 1, robot))
      return k;
  }
  return samples.size();
}

// The file lines of sorted data rows (row 0 is the first after the header; 0 for a row past the
// end), in one pass, blank lines skipped as the reader skips them. Only on the error path: the
// file is read again.
std::vector<int> LinesOfDataRows(const std::string& path, const std::vector<std::size_t>& rows) {
  std::vector<int> out;
  TextFileReader lines(path);
  std::string_view line;
  lines.Next(&line);  // header
  std::size_t seen = 0;
  while (out.size() < rows.size() && lines.Next(&line)) {
    if (IsBlank(line)) continue;
    while (out.size() < rows.size() && rows[out.size()] == seen) out.push_back(lines.line_number());
    ++seen;
  }
  out.resize(rows.size(), 0);
  return out;
}

// Memory that runs out while a file is read is reported with the file (the loaders' boundary).
template <typename Fn>
auto ReportingOutOfMemory(const std::string& path, Fn&& fn) -> decltype(fn()) {
  try {
    return fn();
  } catch (const std::bad_alloc&) {
    throw InputError(InputErrorKind::kOutOfMemory, path, 0,
                     "out of memory while reading this file (split the log, or give fitcal more "
                     "memory)");
  }
}

// Counter glitches. A recorder's counter sometimes delivers one wrong count (a stale read, a
// torn 32-bit read, a bit flip): one interval, or the two a wrong running total bounds, then the
// counter goes on. Replayed, it is a jump of the robot; named instead, and bridged.
// - Too fast: a rim speed beyond kMaxRimSpeedMps on the robot's smallest nominal wheel radius.
//   20 m/s (72 km/h) is over three times the top speed of the fastest wheeled mobile robots
//   fitcal calibrates (warehouse AGVs ~2 m/s, forklifts and tuggers ~6 m/s, outdoor delivery and
//   field robots <= 6 m/s): no robot with wheels of that size turns them that fast, while a torn
//   or flipped count of a 16- or 32-bit counter is thousands of times a real interval's.
// - Backwards inside forward motion: a count of the opposite sign to the wheel's motion, beyond
//   kJitterTicks (a quadrature count flickers by one at an edge), while the medians of the
//   kGlitchWindow intervals before and of those after both move the same way by more than
//   kJitterTicks over its duration, and departing from that motion by more than kSpreadFactor
//   times the scatter of those neighbours about it (plus the jitter). A wheel that really slows,
//   stops or oscillates does so over several intervals, and its neighbours scatter with it: the
//   OptiOdom robots' real counts dip to -3 ticks among +11 (diff drive) and swing through -38
//   among +15 (omni3), none of them glitches; the largest departure of their 4 robots' logs is
//   6.8 times it (omni3; diff drive 5.8), a third of kSpreadFactor. A counter glitch departs by
//   hundreds of ticks from neighbours that scatter by one or two.
// A wrong running total (cumulative counts) bounds two intervals whose sum moves as the wheel
// around them does: both get their mean rate, exact in travel. Otherwise the interval takes the
// rate around it. More than kMaxGlitchShare of a log's intervals is not a glitch but a wrong
// encoder block: refused.
constexpr double kMaxRimSpeedMps = 20.0;
constexpr double kJitterTicks = 2.0;
constexpr std::size_t kGlitchWindow = 5;
constexpr double kSpreadFactor = 20.0;
constexpr double kMaxGlitchShare = 0.01;

// rad/s above which a wheel's count is a glitch: kMaxRimSpeedMps over the smallest nominal wheel
// radius (parameters of a `..radius_m` bounds group); the loader's own limit when none is named.
double GlitchRateLimit(const Robot& robot) {
  double r_min = std::numeric_limits<double>::infinity();
  for (int k = 0; k < robot.NumParameters(); ++k) {
    if (robot.parameters[k].IsWheelRadius() && robot.nominal[k] > 0.0)
      r_min = std::min(r_min, robot.nominal[k]);
  }
  if (!std::isfinite(r_min)) return kMaxWheelRateRadPerS;
  return std::min(kMaxRimSpeedMps / r_min, kMaxWheelRateRadPerS);
}

// The wheel's motion around interval k: the medians of up to kGlitchWindow rates before and
// after it (bridged intervals skipped; NaN with fewer than 3), their mean, and the scatter of
// those rates about that mean (their median absolute deviation). Fixed arrays: this runs on
// every suspicious interval of logs of millions of rows.
struct Neighbourhood {
  double before = std::numeric_limits<double>::quiet_NaN();
  double after = std::numeric_limits<double>::quiet_NaN();
  double around = 0.0;
  double scatter = 0.0;
};

double MedianOf(double* v, std::size_t n) {
  std::nth_element(v, v + n / 2, v + n);
  return v[n / 2];
}

Neighbourhood NeighbourhoodOf(const EncoderSamples& samples, int c, std::size_t k,
                              const std::vector<bool>& bridged) {
  std::array<double, 2 * kGlitchWindow> all{};
  std::size_t n_all = 0;
  Neighbourhood out;
  for (int side : {-1, +1}) {
    std::array<double, kGlitchWindow> rates{};
    std::size_t n = 0;
    for (std::size_t step = 1; step <= 2 * kGlitchWindow && n < kGlitchWindow; ++step) {
      if (side < 0 && step > k) break;
      const std::size_t i = side < 0 ? k - step : k + step;
      if (i >= samples.size()) break;
      if (bridged[i]) continue;
      rates[n++] = samples[i].value[c];
      all[n_all++] = samples[i].value[c];
    }
    if (n >= 3) (side < 0 ? out.before : out.after) = MedianOf(rates.data(), n);
  }
  const bool has_before = std::isfinite(out.before), has_after = std::isfinite(out.after);
  if (has_before || has_after) {
    out.around = has_before && has_after ? 0.5 * (out.before + out.after)
                                         : (has_before ? out.before : out.after);
  }
  for (std::size_t i = 0; i < n_all; ++i) all[i] = std::abs(all[i] - out.around);
  if (n_all > 0) out.scatter = MedianOf(all.data(), n_all);
  return out;
}

struct Glitch {
  std::size_t row = 0;  // data row (0 = the first after the header) of the wrong count
  std::string what;
  // 16 when the count is the wrap of a 16-bit counter declared as 32 bits (a jump of 2^16
  // ticks): 0 otherwise.
  int narrower_wrap_bits = 0;
  bool running_total = false;  // a wrong running total, bridged with the travel kept
  // 16 or 32 when an increment of an undeclared counter is within 5 % of 2^bits: a negative
  // count stored unsigned (-1 as 65535); 0 otherwise.
  int unsigned_negative_bits = 0;
  std::string count = "";  // with unsigned_negative_bits: "channel 'right' counts 65535 ..."
};

class GlitchScreen {
 public:
  GlitchScreen(const Robot& robot, EncoderLog* log)
      : robot_(robot),
        samples_(log->samples),
        rad_per_tick_(2.0 * M_PI / robot.encoder->ticks_per_rev),
        rate_limit_(GlitchRateLimit(robot)),
        bridged_(samples_.size(), false) {}

  void Screen(int c) {
    std::fill(bridged_.begin(), bridged_.end(), false);
    for (std::size_t k = 0; k < samples_.size(); ++k) {
      if (bridged_[k]) continue;
      std::string what = TooFast(c, k);
      if (what.empty() && !TurnsAgainstANeighbour(c, k)) continue;
      const Neighbourhood around = NeighbourhoodOf(samples_, c, k, bridged_);
      if (what.empty()) what = Backwards(c, k, around);
      if (what.empty()) continue;
      const double ticks = Ticks(c, k);  // before the bridge replaces it
      const int wrap_bits = WrapBitsOf(ticks);
      const std::string count = Prefix(c, k);
      glitches_.push_back(Bridge(c, k, around.around, what));
      // A flipped bit of a running total jumps by 2^b and back: bridged as a wrong total, not a
      // wrap; a wrap jumps once.
      // Only a width counter_bits may declare (16 under 32): a glitch's count near 2^10 is a
      // coincidence (the wrapped tricycle's glitches), a jump within 5 % of 2^16 is not.
      if (wrap_bits == 16 && robot_.encoder->counter_bits == 32 &&
          !glitches_.back().running_total) {
        glitches_.back().narrower_wrap_bits = wrap_bits;
      }
      if ((wrap_bits == 16 || wrap_bits == 32) && !robot_.encoder->cumulative &&
          robot_.encoder->counter_bits == 0 && ticks > 0.0) {
        glitches_.back().unsigned_negative_bits = wrap_bits;
        glitches_.back().count = count;
      }
    }
  }
  const std::vector<Glitch>& glitches() const { return glitches_; }

 private:
  double Ticks(int c, std::size_t k) const {
    return samples_[k].value[c] * samples_[k].dt_s / rad_per_tick_;
  }
  std::string Prefix(int c, std::size_t k) const {
    return StrFormat("channel '%s' counts %.0f ticks in %.4g s", robot_.channels[c].name.c_str(),
                     Ticks(c, k), samples_[k].dt_s);
  }
  std::string TooFast(int c, std::size_t k) const {
    if (!(std::abs(samples_[k].value[c]) > rate_limit_)) return "";
    return Prefix(c, k) +
           StrFormat(
               " (%.4g rad/s): beyond %.4g rad/s, a rim speed of %.0f m/s that no robot with "
               "wheels of its size reaches",
               samples_[k].value[c], rate_limit_, kMaxRimSpeedMps);
  }
  // Cheap first look: a count beyond the jitter whose sign differs from a neighbour's (most
  // intervals turn as their neighbours do and are not looked at further).
  bool TurnsAgainstANeighbour(int c, std::size_t k) const {
    const double d = Ticks(c, k);
    if (!(std::abs(d) > kJitterTicks)) return false;
    return k == 0 || k + 1 == samples_.size() || d * Ticks(c, k - 1) <= 0.0 ||
           d * Ticks(c, k + 1) <= 0.0;
  }
  std::string Backwards(int c, std::size_t k, const Neighbourhood& n) const {
    if (!std::isfinite(n.before) || !std::isfinite(n.after) || (n.before > 0.0) != (n.after > 0.0))
      return "";
    const double dt = samples_[k].dt_s, jitter = kJitterTicks * rad_per_tick_ / dt;
    const double v = samples_[k].value[c];
    if (!(std::min(std::abs(n.before), std::abs(n.after)) > jitter)) return "";
    if (!(v * (n.before > 0.0 ? 1.0 : -1.0) < -jitter)) return "";
    if (!(std::abs(v - n.around) > kSpreadFactor * (n.scatter + jitter))) return "";
    const double to_ticks = dt / rad_per_tick_;
    return Prefix(c, k) +
           StrFormat(
               ": backwards against the wheel's motion around it (%.1f and %.1f ticks per "
               "interval before and after, scattered by %.1f)",
               n.before * to_ticks, n.after * to_ticks, n.scatter * to_ticks);
  }
  // A wrong running total first (the pair of intervals it bounds, after then before k), else the
  // interval alone.
  Glitch Bridge(int c, std::size_t k, double around, const std::string& what) {
    const double off = std::abs(samples_[k].value[c] - around);
    if (robot_.encoder->cumulative) {
      for (std::size_t a : {k, k - 1}) {
        if (a >= samples_.size() || a + 1 >= samples_.size() || bridged_[a] || bridged_[a + 1])
          continue;
        const double span = samples_[a].dt_s + samples_[a + 1].dt_s;
        const double merged = (samples_[a].value[c] * samples_[a].dt_s +
                               samples_[a + 1].value[c] * samples_[a + 1].dt_s) /
                              span;
        if (!(std::abs(merged - around) < 0.25 * off)) continue;
        samples_[a].value[c] = samples_[a + 1].value[c] = merged;
        bridged_[a] = bridged_[a + 1] = true;
        return {a + 1,
                what +
                    "; the running total of this row dropped from the fit (the two "
                    "intervals it bounds bridged, travel kept)",
                0, true};
      }
    }
    samples_[k].value[c] = around;
    bridged_[k] = true;
    return {k + 1, what + "; dropped from the fit (the interval takes the rate around it, " +
                       StrFormat("%.4g rad/s", around) + ")"};
  }

  const Robot& robot_;
  EncoderSamples& samples_;
  double rad_per_tick_;
  double rate_limit_;
  std::vector<bool> bridged_;
  std::vector<Glitch> glitches_;
};

// The lines of the glitches' rows, sorted by row.
std::vector<int> SortedGlitchLines(const std::string& path, std::vector<Glitch>* all) {
  std::sort(all->begin(), all->end(),
            [](const Glitch& a, const Glitch& b) { return a.row < b.row; });
  std::vector<std::size_t> rows;
  for (const Glitch& g : *all) rows.push_back(g.row);
  return LinesOfDataRows(path, rows);
}

// More than kMaxGlitchShare of the `total` intervals of a log (samples of a track: `counted`)
// is not a glitch but `hint`: refused. Else each is warned, `file:line: <kind> glitch: <what>`.
void WarnGlitchesOrRefuse(const std::string& path, const std::string& kind,
                          const std::string& counted, const std::string& hint,
                          const std::vector<Glitch>& all, const std::vector<int>& lines,
                          std::size_t total) {
  const double allowed = std::max(1.0, kMaxGlitchShare * static_cast<double>(total));
  if (static_cast<double>(all.size()) > allowed) {
    // Intervals, not glitches: two wheels glitching in one interval count once ("6837 of 3568
    // intervals" said the count of both wheels of a wrong `cumulative:`).
    std::vector<std::size_t> distinct;
    for (const Glitch& g : all) distinct.push_back(g.row);
    distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
    throw InputError(InputErrorKind::kImplausibleValue, path, lines.front(),
                     std::to_string(distinct.size()) + " of " + std::to_string(total) + " " +
                         counted + " are " + kind + " glitches, the first here: " +
                         all.front().what + "; more than 1 % is not a glitch but " + hint);
  }
  for (std::size_t i = 0; i < all.size(); ++i)
    Warn(path, lines[i], kind + " glitch: " + all[i].what);
}

// The same for a log's intervals (a wrong block: `hint`), each glitch counted in the log.
void WarnAndCountGlitches(const std::string& path, const std::string& kind,
                          const std::string& hint, const std::vector<Glitch>& all,
                          const std::vector<int>& lines, EncoderLog* log) {
  WarnGlitchesOrRefuse(path, kind, "intervals", hint, all, lines, log->samples.size());
  log->dropped_glitches += static_cast<int>(all.size());
}

// Screens every wheel channel read as counts, names each glitch with its line (a warning) and
// counts them in log->dropped_glitches.
void DropCounterGlitches(const std::string& path, const Robot& robot,
                         const std::vector<bool>& screened, EncoderLog* log) {
  GlitchScreen screen(robot, log);
  for (int c = 0; c < robot.NumChannels(); ++c) {
    if (screened[static_cast<std::size_t>(c)]) screen.Screen(c);
  }
  std::vector<Glitch> all = screen.glitches();
  if (all.empty()) return;
  const std::vector<int> lines = SortedGlitchLines(path, &all);
  for (std::size_t i = 0; i < all.size(); ++i) {
    if (all[i].narrower_wrap_bits == 0) continue;
    // Not a glitch but the wrap of a narrower counter: bridging each would drop real travel
    // and warn on every wrap.
    const std::string b = std::to_string(all[i].narrower_wrap_bits);
    throw InputError(InputErrorKind::kImplausibleValue, path, lines[i],
                     "the tick counter jumps by about 2^" + b + " ticks in one interval: a " + b +
                         "-bit counter that wraps, not the " +
                         std::to_string(robot.encoder->counter_bits) +
                         " bits encoder.counter_bits declares; declare counter_bits: " + b);
  }
  for (std::size_t i = 0; i < all.size(); ++i) {
    if (all[i].unsigned_negative_bits == 0) continue;
    // Every backwards interval of such a log is one: a warning each flooded the terminal (97
    // lines) before the share refused the log.
    const std::string b = std::to_string(all[i].unsigned_negative_bits);
    throw InputError(InputErrorKind::kImplausibleValue, path, lines[i],
                     all[i].count + ": an increment of about 2^" + b + " is a negative count "
                     "stored as an unsigned " + b + "-bit number; declare counter_bits: " + b +
                     " in the robot YAML's encoder block and fitcal reads the counts signed");
  }
  WarnAndCountGlitches(path, "counter", "a wrong encoder block (ticks_per_rev, cumulative, "
                       "counter_bits?)", all, lines, log);
}

// Angle glitches. An absolute encoder sometimes delivers one wrong angle (a torn read, a bit
// flip): the steering or castor angle jumps out and back in one reading. Replayed, the robot
// turns sharply for two intervals. An interval's angle is the mean of its two readings (robot.h),
// so one wrong reading moves the two intervals it bounds by half its error each, the same way.
// It is named when those two intervals depart from the intervals on each side, both the same way,
// by a reading error of more than kMaxAngleRateRadPerS over the longer of them (and at least
// kMinAngleGlitchRad), while the two outer intervals agree, and the two inner ones, to a quarter
// of it. 20 rad/s is twice a fast steering servo (60 deg in 0.1 s) and turns a castor through
// half a turn in 0.16 s; a real swing that fast does not come back within one reading. The
// OptiOdom tricycle's largest out-and-back step is one 0.45 deg count (0.008 rad) at 20 Hz, where
// the limit is 1 rad. Differences are taken the short way round (a castor near +-pi). The two
// intervals take the angle between their outer neighbours.
constexpr double kMaxAngleRateRadPerS = 20.0;
constexpr double kMinAngleGlitchRad = 0.1;

// The glitch of the reading that bounds intervals k and k + 1 (data row k + 1), bridged.
std::optional<Glitch> AngleGlitchAt(const Robot& robot, int c, std::size_t k,
                                    EncoderSamples& samples) {
  const double before = samples[k - 1].value[c], after = samples[k + 2].value[c];
  const double out = WrapAngle(samples[k].value[c] - before);
  const double back = WrapAngle(samples[k + 1].value[c] - after);
  const double error = 2.0 * std::min(std::abs(out), std::abs(back));  // of the reading
  const double limit = std::max(kMinAngleGlitchRad,
                                kMaxAngleRateRadPerS * std::max(samples[k].dt_s,
                                                                samples[k + 1].dt_s));
  if (!(out * back > 0.0 && error > limit)) return std::nullopt;
  const double between = WrapAngle(after - before);
  const double inner = WrapAngle(samples[k + 1].value[c] - samples[k].value[c]);
  if (!(std::abs(between) < 0.25 * error && std::abs(inner) < 0.25 * error)) return std::nullopt;
  // In the column's own range, not wrapped.
  samples[k].value[c] = samples[k + 1].value[c] = before + 0.5 * between;
  return Glitch{k + 1, StrFormat("channel '%s' reads about %.4g rad off the angle around it "
                                 "(%.4g rad) and comes back at the next reading, faster than "
                                 "%.0f rad/s; dropped from the fit (the two intervals it bounds "
                                 "take the angle around it)",
                                 robot.channels[c].name.c_str(), std::copysign(error, out),
                                 samples[k].value[c], kMaxAngleRateRadPerS)};
}

void DropAngleGlitches(const std::string& path, const Robot& robot, EncoderLog* log) {
  std::vector<Glitch> all;
  for (int c = 0; c < robot.NumChannels(); ++c) {
    if (robot.channels[c].kind != ChannelKind::kAngle) continue;
    for (std::size_t k = 1; k + 2 < log->samples.size(); ++k) {
      if (std::optional<Glitch> g = AngleGlitchAt(robot, c, k, log->samples)) all.push_back(*g);
    }
  }
  if (all.empty()) return;
  const std::vector<int> lines = SortedGlitchLines(path, &all);
  WarnAndCountGlitches(path, "angle", "a wrong angle column (degrees or counts read as "
                       "radians, a swapped column?)", all, lines, log);
}

EncoderLog ReadEncoderRows(TextFileReader& lines, const Robot& robot, std::vector<bool>* screened) {
  const std::string& path = lines.path();
  std::string_view line;
  if (!lines.Next(&line) || IsBlank(line)) {
    throw InputError(InputErrorKind::kEmptyFile, path, 1,
                     "empty file (expected header '" + ExpectedHeader(robot) + "')");
  }
  const ColumnPlan plan = PlanColumns(line, robot, path);
  if (plan.any_ticks && !(robot.encoder && robot.encoder->ticks_per_rev > 0.0)) {
    throw InputError(InputErrorKind::kBadHeader, path, lines.line_number(),
                     "encoder ticks need 'encoder: {ticks_per_rev: N, cumulative: false|true}' "
                     "in the robot YAML");
  }
  const int num_columns = 1 + robot.NumChannels();
  // Wheels read as counts are screened for glitches after the whole log is read.
  screened->assign(robot.channels.size(), false);
  for (std::size_t j = 0; j < plan.ticks.size(); ++j) {
    const int c = plan.channel_of_column[j];
    (*screened)[static_cast<std::size_t>(c)] =
        plan.ticks[j] && robot.channels[c].kind == ChannelKind::kWheelRate;
  }
  EncoderRowConverter converter(robot, plan.channel_of_column, plan.ticks);
  // Reserve exactly once (one row per line, counted at memchr speed in a first pass) so that a
  // large log holds its samples (8 bytes of time + one row) and is never copied while growing.
  converter.Reserve(lines.CountLinesAndRewind());
  lines.Next(&line);  // the header again
  double row[kMaxColumns];
  double previous_t = 0.0;
  bool first = true;
  while (lines.Next(&line)) {
    if (IsBlank(line)) continue;
    ParseRow(line, ',', num_columns, path, lines.line_number(), row);
    CheckTimePlausible(row[0], path, lines.line_number());
    if (!first) CheckIncreasing(previous_t, row[0], path, lines.line_number());
    converter.Add(row[0], row + 1);
    CheckSamplePlausible(converter.samples(), robot, *screened, path, lines.line_number());
    previous_t = row[0];
    first = false;
  }
  return converter.Take();
}

// A running tick counter that wraps inside a run (a 16-bit count passing 65535 -> 0) turns one
// interval into a jump of about -2^bits ticks: a rate thousands of times its neighbours'. Such an
// interval, whose tick count lies within 5 % of a power of two from 2^8 to 2^32 and is over a
// hundred times the run's median moving interval, is a wrap: refused with its line (fitcal does
// not guess the counter's width). Returns the sample index, or samples.size().
std::size_t FindCounterWrap(const EncoderLog& log, const Robot& robot, int* bits) {
  const EncoderSamples& samples = log.samples;
  if (!robot.encoder || !robot.encoder->cumulative || robot.encoder->counter_bits > 0 ||
      samples.size() < 3)
    return samples.size();
  const double ticks_per_rad = robot.encoder->ticks_per_rev / (2.0 * M_PI);
  std::vector<double> moving;
  for (std::size_t k = 0; k < samples.size();
       k += std::max<std::size_t>(1, samples.size() / 20000)) {
    for (int c = 0; c < robot.NumChannels(); ++c) {
      const double ticks = std::abs(samples[k].value[c] * samples[k].dt_s * ticks_per_rad);
      if (robot.channels[c].kind == ChannelKind::kWheelRate && ticks > 0.0) moving.push_back(ticks);
    }
  }
  if (moving.empty()) return samples.size();
  std::nth_element(moving.begin(), moving.begin() + static_cast<std::ptrdiff_t>(moving.size() / 2),
                   moving.end());
  const double median = moving[moving.size() / 2];
  for (std::size_t k = 0; k < samples.size(); ++k) {
    for (int c = 0; c < robot.NumChannels(); ++c) {
      if (robot.channels[c].kind != ChannelKind::kWheelRate) continue;
      const double ticks = std::abs(samples[k].value[c] * samples[k].dt_s * ticks_per_rad);
      if (ticks < 100.0 * median) continue;
      *bits = WrapBitsOf(ticks);
      if (*bits > 0) return k;
    }
  }
  return samples.size();
}

}  // namespace

bool WheelsTurn(const EncoderSamples& samples, std::size_t k, const Robot& robot) {
  if (k >= samples.size()) return false;
  for (int c = 0; c < robot.NumChannels(); ++c) {
    if (robot.channels[c].kind == ChannelKind::kWheelRate &&
        std::abs(samples[k].value[c]) > kTurningRadPerS)
      return true;
  }
  return false;
}

EncoderLog ReadEncoderCsv(const std::string& path, const Robot& robot) {
  std::vector<bool> screened;
  EncoderLog log = ReportingOutOfMemory(path, [&] {
    TextFileReader lines(path);
    return ReadEncoderRows(lines, robot, &screened);
  });
  if (log.t_s.size() < 2) {
    throw InputError(InputErrorKind::kTooFewSamples, path, 0,
                     "needs at least two rows (a start time and one interval), found " +
                         std::to_string(log.t_s.size()));
  }
  double median_s = 0.0;
  const std::size_t gap = FindClockGap(log.samples, robot, &median_s);
  if (gap < log.samples.size()) {
    throw InputError(InputErrorKind::kClockGap, path, LinesOfDataRows(path, {gap + 1})[0],
                     "the clock jumps " + MessageNumber(log.samples[gap].dt_s) +
                         " s (the log's median interval is " + MessageNumber(median_s) +
                         " s) while the wheels turn: a clock step or lost rows inside a moving "
                         "stretch; refused (cut the run into two runs there)");
  }
  int bits = 0;
  const std::size_t wrap = FindCounterWrap(log, robot, &bits);
  if (wrap < log.samples.size()) {
    const int line = LinesOfDataRows(path, {wrap + 1})[0];
    throw InputError(InputErrorKind::kImplausibleValue, path, line, CounterWrapMessage(bits));
  }
  DropCounterGlitches(path, robot, screened, &log);
  DropAngleGlitches(path, robot, &log);
  // The model's own checks of what its channels hold (a steering angle in degrees or ticks, ...).
  RunSampleCheck(robot.model, log, path);
  return log;
}

namespace {

// TUM quaternions are written with a few decimals: four components rounded to 1e-4 put the norm
// at most ~2e-4 from 1, and float32 to ~1e-7. Within kQuaternionNormTolerance the quaternion is
// normalised (a warning says so); beyond it the numbers are not a rounded unit quaternion (a
// column shifted, a different convention, corruption), and the yaw of Eq. 1 - 2(qy^2 + qz^2),
// which assumes norm 1, would be wrong: refused.
constexpr double kQuaternionNormTolerance = 1e-3;
// Below this the norm is 1 to the file's printing precision: no warning.
constexpr double kQuaternionNormSilent = 1e-6;

struct QuaternionRepairs {
  int count = 0;
  int worst_line = 0;
  double worst_error = 0.0;
};

double YawOfTumRow(const double* row, const std::string& path, int line_number,
                   QuaternionRepairs* repairs) {
  double qx = row[4], qy = row[5], qz = row[6], qw = row[7];
  const double norm = std::sqrt(qx * qx + qy * qy + qz * qz + qw * qw);
  const double error = std::abs(norm - 1.0);
  if (!(error <= kQuaternionNormTolerance)) {
    throw InputError(InputErrorKind::kBadValue, path, line_number,
                     "quaternion is not a unit quaternion (norm " + MessageNumber(norm) +
                         "; fitcal normalises within " + MessageNumber(kQuaternionNormTolerance) +
                         " of 1, rounding, and refuses beyond)");
  }
  if (error > kQuaternionNormSilent) {
    ++repairs->count;
    if (error > repairs->worst_error) {
      repairs->worst_error = error;
      repairs->worst_line = line_number;
    }
  }
  qx /= norm, qy /= norm, qz /= norm, qw /= norm;
  return std::atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz));
}

void CheckPosePlausible(const double* row, const std::string& path, int line_number) {
  CheckTimePlausible(row[0], path, line_number);
  if (std::abs(row[1]) > kMaxPositionM || std::abs(row[2]) > kMaxPositionM) {
    throw InputError(InputErrorKind::kImplausibleValue, path, line_number,
                     "position (" + MessageNumber(row[1]) + ", " + MessageNumber(row[2]) +
                         ") m is beyond any map (limit " + MessageNumber(kMaxPositionM) +
                         " m; wrong units or a corrupted field?)");
  }
}

// The first non-blank, non-comment line decides the format; *line is left on it.
bool DetectTum(TextFileReader& lines, std::string_view* line) {
  while (lines.Next(line)) {
    const std::string_view t = Trim(*line);
    if (t.empty() || t.front() == '#') continue;  // only TUM files carry '#' comments
    if (t.size() >= 2 && t[0] == 't' && t[1] == ',') {
      ExpectHeader(*line, {"t", "x", "y", "theta"}, lines.path(), lines.line_number());
      return false;
    }
    if (t.find(',') == std::string_view::npos) return true;
    throw InputError(InputErrorKind::kBadHeader, lines.path(), lines.line_number(),
                     "header must be 't,x,y,theta' (or a TUM file 't x y z qx qy qz qw'), found '" +
                         std::string(*line) + "'");
  }
  throw InputError(InputErrorKind::kEmptyFile, lines.path(), 1,
                   "empty file (expected header 't,x,y,theta' or TUM rows)");
}

// A ground-truth pose that leaves both neighbours faster than any robot drives or turns and lands
// far from them while they lie close together: a motion-capture marker swapped for one sample, a
// second body's pose on the track. Replayed, every window across it would fit the jump (a 2 m
// sample in each of six runs: the sigmas 120x wider). Dropped with a warning naming its line;
// more than kMaxGlitchShare of the samples is not a glitch but two bodies or frames on one track:
// refused.
struct PoseJump {
  double away, apart, rate;  // to the nearer neighbour, between the neighbours, the slower leg's
};

double Distance(const Pose2d& a, const Pose2d& b) { return std::hypot(b.x - a.x, b.y - a.y); }
double Turn(const Pose2d& a, const Pose2d& b) { return std::abs(WrapAngle(b.theta - a.theta)); }

// The lower quartile over the track of how far a sample's two neighbours lie apart, by
// `measure`: the track's own step or its noise where it stands, in its own units (positions in
// mm: 1000x, where a stop's noise passed for glitches of metres). A second body's samples
// interleaved leave it small: where one in two or three samples is the other body's, the
// neighbours of the others' samples are of one body.
template <typename Measure>
double TypicalApart(const GroundTruthTrack& track, Measure measure) {
  std::vector<double> apart;
  for (std::size_t i = 1; i + 1 < track.t_s.size(); ++i)
    apart.push_back(measure(track.world_T_robot[i - 1], track.world_T_robot[i + 1]));
  if (apart.empty()) return 0.0;
  std::nth_element(apart.begin(), apart.begin() + apart.size() / 4, apart.end());
  return apart[apart.size() / 4];
}

struct TrackSteps {
  double moved = 0.0, turned = 0.0;  // TypicalApart of positions (track units) and headings
};

std::optional<std::string> GroundTruthGlitchAt(const GroundTruthTrack& track, std::size_t i,
                                               const TrackSteps& typical) {
  const Pose2d& before = track.world_T_robot[i - 1];
  const Pose2d& p = track.world_T_robot[i];
  const Pose2d& after = track.world_T_robot[i + 1];
  const double dt_in = track.t_s[i] - track.t_s[i - 1], dt_out = track.t_s[i + 1] - track.t_s[i];
  const auto jump = [&](auto measure) {
    const double in = measure(before, p), out = measure(p, after);
    return PoseJump{std::min(in, out), measure(before, after), std::min(in / dt_in, out / dt_out)};
  };
  const PoseJump moved = jump(Distance), turned = jump(Turn);
  // Out and back 10x as far as the neighbours lie apart and as the track's typical step, at least
  // 0.1 m or 0.5 rad: no robot drives so (a stop's noise in a track of millimetres is 1000x, as
  // its steps are); faster than 5 m/s and 10 rad/s both ways: a sparse track (a pose every half
  // loop) moves slowly between its samples.
  if (moved.rate > 5.0 &&
      moved.away > std::max({0.1, 10.0 * moved.apart, 10.0 * typical.moved})) {
    return "the pose jumps " + MessageNumber(moved.away) + " m from both neighbours (" +
           MessageNumber(moved.apart) + " m apart) and back";
  }
  if (turned.rate > 10.0 &&
      turned.away > std::max({0.5, 10.0 * turned.apart, 10.0 * typical.turned})) {
    return "the heading jumps " + MessageNumber(turned.away) + " rad from both neighbours (" +
           MessageNumber(turned.apart) + " rad apart) and back";
  }
  return std::nullopt;
}

void DropGroundTruthGlitches(const std::string& path, const std::vector<int>& line_of_row,
                             GroundTruthTrack* track) {
  std::vector<Glitch> all;
  std::vector<int> lines;
  const TrackSteps typical{TypicalApart(*track, Distance), TypicalApart(*track, Turn)};
  for (std::size_t i = 1; i + 1 < track->t_s.size(); ++i) {
    if (std::optional<std::string> glitch = GroundTruthGlitchAt(*track, i, typical)) {
      all.push_back({i, *glitch + "; dropped"});
      lines.push_back(line_of_row[i]);
      ++i;  // its neighbour leaves it as fast: not a second glitch
    }
  }
  if (all.empty()) return;
  WarnGlitchesOrRefuse(path, "ground-truth", "samples", "two bodies or frames on one track", all,
                       lines, track->t_s.size());
  for (std::size_t g = all.size(); g-- > 0;) {
    const auto row = static_cast<std::ptrdiff_t>(all[g].row);
    track->t_s.erase(track->t_s.begin() + row);
    track->world_T_robot.erase(track->world_T_robot.begin() + row);
  }
}

GroundTruthTrack ReadGroundTruthRows(TextFileReader& lines) {
  const std::string& path = lines.path();
  GroundTruthTrack track;
  // At most a row per line: reserved once (as the encoder log) instead of copied while growing.
  const std::size_t most_rows = lines.CountLinesAndRewind();
  track.t_s.reserve(most_rows);
  track.world_T_robot.reserve(most_rows);
  std::string_view line;
  const bool tum = DetectTum(lines, &line);
  double row[kMaxColumns];
  QuaternionRepairs repairs;
  std::vector<int> line_of_row;
  line_of_row.reserve(most_rows);
  auto add = [&](const Pose2d& pose) {
    CheckPosePlausible(row, path, lines.line_number());
    if (!(std::abs(pose.theta) <= kMaxAngleRad)) {  // a heading, unwrapped, of 1600 turns at most
      throw InputError(InputErrorKind::kImplausibleValue, path, lines.line_number(),
                       "heading " + MessageNumber(pose.theta) + " rad is beyond any run (limit " +
                           MessageNumber(kMaxAngleRad) +
                           " rad; wrong units or a corrupted field?)");
    }
    if (!track.t_s.empty()) CheckIncreasing(track.t_s.back(), row[0], path, lines.line_number());
    track.t_s.push_back(row[0]);
    track.world_T_robot.push_back(pose);
    line_of_row.push_back(lines.line_number());
  };
  if (tum) {
    do {  // the line that decided the format is a data row
      const std::string_view t = Trim(line);
      if (t.empty() || t.front() == '#') continue;
      ParseRow(line, ' ', 8, path, lines.line_number(), row);
      add(Pose2d{row[1], row[2], YawOfTumRow(row, path, lines.line_number(), &repairs)});
    } while (lines.Next(&line));
  } else {
    while (lines.Next(&line)) {
      if (IsBlank(line)) continue;
      ParseRow(line, ',', 4, path, lines.line_number(), row);
      add(Pose2d{row[1], row[2], row[3]});
    }
  }
  if (repairs.count > 0) {
    Warn(path, repairs.worst_line,
         std::to_string(repairs.count) + " quaternion(s) normalised, norm up to " +
             MessageNumber(repairs.worst_error) + " from 1 (within the tolerance " +
             MessageNumber(kQuaternionNormTolerance) + ")");
  }
  DropGroundTruthGlitches(path, line_of_row, &track);
  return track;
}

}  // namespace

GroundTruthTrack ReadGroundTruth(const std::string& path) {
  GroundTruthTrack track = ReportingOutOfMemory(path, [&] {
    TextFileReader lines(path);
    return ReadGroundTruthRows(lines);
  });
  if (track.t_s.size() < 2) {
    throw InputError(
        InputErrorKind::kTooFewSamples, path, 0,
        "needs at least two ground-truth samples, found " + std::to_string(track.t_s.size()));
  }
  return track;
}

}  // namespace fitcal::io
