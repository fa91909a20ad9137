#pragma once
// The one error type for bad input: which file, which line (0 = the file as a whole), what kind of
// problem and a sentence for the user. Loaders throw it; the tool's edge prints What() as one line.

#include <cstddef>
#include <stdexcept>
#include <string>

namespace fitcal::io {

enum class InputErrorKind {
  kMissingFile,        // cannot open / read
  kEmptyFile,          // nothing but (optional) header
  kBadHeader,          // header row is not the expected one
  kWrongColumnCount,   // a row with too few or too many fields
  kNonNumeric,         // a field that is not a number
  kNonFinite,          // NaN, Inf or out of double range
  kNonIncreasingTime,  // t not strictly increasing
  kTooFewSamples,      // fewer than two samples
  kNoOverlap,          // ground truth and encoders do not share time
  kUnknownModel,       // robot model fitcal does not know
  kDuplicateRunId,     // two runs with one id
  kWrongYamlType,      // a YAML node of the wrong kind (map / list / scalar)
  kMissingKey,         // a required YAML key is absent
  kUnknownKey,         // a YAML key nobody reads
  kBadValue,           // a value out of its allowed range (bounds lo > hi, radius <= 0, ...)
  kBadPath,            // a path that escapes the data set directory
  kYamlSyntax,         // YAML that does not parse
  kTooLarge,           // a file larger than fitcal will hold in memory
  kOutOfMemory,        // memory ran out while the file was read
  kDuplicateKey,       // a YAML map with one key twice (yaml-cpp would keep one silently)
  kDuplicateRun,       // two runs of one data set with the same file or the same content
  kImplausibleValue,   // a finite number no robot can produce (1e300 rad/s, 1e18 s)
  kClockGap,           // a clock step or gap while the wheels turn
  kNoMotion,           // no run of the data set moves: nothing to calibrate
};

// `text` made fit for one line of a message: control characters (a newline in a YAML scalar,
// binary junk) shown as '?', and at most max_chars characters, the middle elided with the number
// of bytes left out (a 2 MB field is never echoed whole). Keeps the head and the tail, where a
// path's file name is.
std::string OneLine(const std::string& text, std::size_t max_chars = 240);

// `file:line: message` (`file: message` for line 0) in one line of at most ~500 characters
// whatever the loaders echo: what() of an InputError, and a warning (io/warnings.h).
std::string FileLineText(const std::string& file, int line, const std::string& message);

class InputError : public std::runtime_error {
 public:
  InputError(InputErrorKind kind, std::string file, int line, const std::string& message);

  InputErrorKind kind() const { return kind_; }
  const std::string& file() const { return file_; }
  int line() const { return line_; }

 private:
  InputErrorKind kind_;
  std::string file_;
  int line_;
};

}  // namespace fitcal::io
