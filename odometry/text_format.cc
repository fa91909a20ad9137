#include "odometry/text_format.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <vector>

namespace fitcal {
namespace {

std::string VStrFormat(const char* format, va_list args) __attribute__((format(printf, 1, 0)));

std::string VStrFormat(const char* format, va_list args) {
  char small[256];
  va_list copy;
  va_copy(copy, args);
  const int n = std::vsnprintf(small, sizeof small, format, copy);
  va_end(copy);
  if (n < 0) return {};
  if (static_cast<size_t>(n) < sizeof small) return std::string(small, static_cast<size_t>(n));
  // Longer than the buffer on the stack: format again into one of the exact size.
  std::vector<char> large(static_cast<size_t>(n) + 1);
  std::vsnprintf(large.data(), large.size(), format, args);
  return std::string(large.data(), static_cast<size_t>(n));
}

// The number of conversions in `format` ("%%" is none); false when one is not of a double.
bool CountDoubleConversions(const char* format, int* count) {
  *count = 0;
  for (const char* c = format; *c != '\0'; ++c) {
    if (*c != '%') continue;
    ++c;
    if (*c == '%') continue;
    while (*c != '\0' && std::strchr("-+ #0", *c) != nullptr) ++c;
    while (*c >= '0' && *c <= '9') ++c;
    if (*c == '.') {
      ++c;
      while (*c >= '0' && *c <= '9') ++c;
    }
    if (*c == '\0' || std::strchr("fFeEgGaA", *c) == nullptr) return false;
    ++*count;
  }
  return true;
}

}  // namespace

std::string FormatDouble(const char* format, double value) {
  int conversions = 0;
  if (!CountDoubleConversions(format, &conversions) || conversions != 1) {
    throw std::logic_error(std::string("FormatDouble: \"") + format +
                           "\" is not one conversion of a double");
  }
  if (!std::isfinite(value)) return "-";
  return StrFormat(format, value);
}

std::string StrFormat(const char* format, ...) {
  va_list args;
  va_start(args, format);
  std::string text = VStrFormat(format, args);
  va_end(args);
  return text;
}

std::string StrFormatFinite(double value, const char* format, ...) {
  if (!std::isfinite(value)) return "-";
  va_list args;
  va_start(args, format);
  std::string text = VStrFormat(format, args);
  va_end(args);
  return text;
}

std::string MessageNumber(double value) { return StrFormat("%.6g", value); }

}  // namespace fitcal
