// The one way to format numbers into text (odometry/text_format.h): StrFormat's output against
// snprintf's for the same literal, any length; FormatDouble's run-time check of a format chosen
// at run time, which throws rather than print a wrong number (issue 42).

#include "odometry/text_format.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace fitcal {
namespace {

TEST(TextFormat, StrFormatMatchesSnprintfAtAnyLength) {
  char expected[64];
  std::snprintf(expected, sizeof expected, "%d runs: CF %.4f -> %.4f", 20, 0.1366, 0.6691);
  EXPECT_EQ(StrFormat("%d runs: CF %.4f -> %.4f", 20, 0.1366, 0.6691), expected);
  EXPECT_EQ(StrFormat("%d runs: CF %.4f -> %.4f", 20, 0.1366, 0.6691),
            "20 runs: CF 0.1366 -> 0.6691");
  // Longer than the 256-byte buffer on the stack: formatted again, nothing cut.
  const std::string long_name(1000, 'r');
  const std::string text = StrFormat("%s = %.3f", long_name.c_str(), 1.5);
  EXPECT_EQ(text, long_name + " = 1.500");
}

TEST(TextFormat, StrFormatFiniteShowsADashForWhatWasNotMeasured) {
  EXPECT_EQ(StrFormatFinite(0.25, "%.2f m", 0.25), "0.25 m");
  EXPECT_EQ(StrFormatFinite(std::numeric_limits<double>::quiet_NaN(), "%.2f", 0.0), "-");
  EXPECT_EQ(StrFormatFinite(std::numeric_limits<double>::infinity(), "%.2f", 0.0), "-");
}

TEST(TextFormat, FormatDoubleTakesExactlyOneConversionOfADouble) {
  EXPECT_EQ(FormatDouble("%+.1f %%", 12.34), "+12.3 %");
  EXPECT_EQ(FormatDouble("%10.3e", 1234.5), " 1.234e+03");
  EXPECT_EQ(FormatDouble("%.2g", std::numeric_limits<double>::quiet_NaN()), "-");
  // The class of the defect: a format that would read an int, a string or two numbers.
  for (const char* bad : {"%d runs", "%s", "%.4f -> %.4f", "no conversion", "%ld", "%.3lf", "%"}) {
    EXPECT_THROW(FormatDouble(bad, 1.0), std::logic_error) << bad;
  }
}

}  // namespace
}  // namespace fitcal
