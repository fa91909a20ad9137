#include "io/input_error.h"

namespace fitcal::io {

const char* ToString(InputErrorKind kind) {
  switch (kind) {
    case InputErrorKind::kMissingFile:
      return "missing file";
    case InputErrorKind::kEmptyFile:
      return "empty file";
    case InputErrorKind::kBadHeader:
      return "bad header";
    case InputErrorKind::kWrongColumnCount:
      return "wrong column count";
    case InputErrorKind::kNonNumeric:
      return "non-numeric field";
    case InputErrorKind::kNonFinite:
      return "non-finite value";
    case InputErrorKind::kNonIncreasingTime:
      return "time not increasing";
    case InputErrorKind::kTooFewSamples:
      return "too few samples";
    case InputErrorKind::kNoOverlap:
      return "no time overlap";
    case InputErrorKind::kUnknownModel:
      return "unknown model";
    case InputErrorKind::kDuplicateRunId:
      return "duplicate run id";
    case InputErrorKind::kWrongYamlType:
      return "wrong YAML type";
    case InputErrorKind::kMissingKey:
      return "missing key";
    case InputErrorKind::kUnknownKey:
      return "unknown key";
    case InputErrorKind::kBadValue:
      return "bad value";
    case InputErrorKind::kBadPath:
      return "bad path";
    case InputErrorKind::kYamlSyntax:
      return "YAML syntax";
    case InputErrorKind::kTooLarge:
      return "file too large";
    case InputErrorKind::kOutOfMemory:
      return "out of memory";
    case InputErrorKind::kDuplicateKey:
      return "duplicate key";
    case InputErrorKind::kDuplicateRun:
      return "duplicate run";
    case InputErrorKind::kImplausibleValue:
      return "implausible value";
    case InputErrorKind::kClockGap:
      return "clock gap";
    case InputErrorKind::kNoMotion:
      return "no motion";
  }
  return "input error";
}

std::string OneLine(const std::string& text, std::size_t max_chars) {
  std::string out = text;
  for (char& c : out) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  }
  if (out.size() <= max_chars) return out;
  const std::string gap = "...[" + std::to_string(out.size() - max_chars) + " bytes]...";
  const std::size_t keep = max_chars > gap.size() ? max_chars - gap.size() : 0;
  return out.substr(0, keep - keep / 3) + gap + out.substr(out.size() - keep / 3);
}

namespace {
// One line of at most ~500 characters whatever the loaders echo: the path and the message are
// each clamped (a path near PATH_MAX, a header line of a binary file).
std::string Format(const std::string& file, int line, const std::string& message) {
  std::string out = OneLine(file, 200);
  if (line > 0) out += ":" + std::to_string(line);
  return out + ": " + OneLine(message, 300);
}
}  // namespace

InputError::InputError(InputErrorKind kind, std::string file, int line, const std::string& message)
    : std::runtime_error(Format(file, line, message)),
      kind_(kind),
      file_(std::move(file)),
      line_(line) {}

}  // namespace fitcal::io
