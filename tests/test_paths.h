#pragma once
// Where the tests find the checkout, the shared data (../shared beside it) and the build.
//
// The paths are compiled once per build directory (tests/test_paths.cc.in, configured by CMake),
// not passed to every test as -D definitions: a test object then does not depend on where it was
// built, so ccache reuses it in another clone and between the Release and sanitizer builds
// (tools/test.sh), which compile the tests with the same flags.
#include <string>

namespace fitcal::test_paths {
extern const char* const kSourceDir;
extern const char* const kSharedDir;
extern const char* const kBinaryDir;
}  // namespace fitcal::test_paths

#define FITCAL_SOURCE_DIR (std::string(::fitcal::test_paths::kSourceDir))
#define FITCAL_SHARED_DIR (std::string(::fitcal::test_paths::kSharedDir))
#define FITCAL_BINARY_DIR (std::string(::fitcal::test_paths::kBinaryDir))
