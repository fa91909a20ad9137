#pragma once
// Where the tests find the checkout, the shared data (../shared beside it, or $FITCAL_SHARED_DIR
// where set: a git worktree elsewhere has no ../shared, and its real-data tests would skip) and
// the build.
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
// $FITCAL_SHARED_DIR when set and not empty, kSharedDir otherwise. A function, not a constant
// initialised from the environment: tests read it in initialisers at namespace scope, which may
// run before another file's dynamic initialisation.
std::string SharedDir();
}  // namespace fitcal::test_paths

#define FITCAL_SOURCE_DIR (std::string(::fitcal::test_paths::kSourceDir))
#define FITCAL_SHARED_DIR (::fitcal::test_paths::SharedDir())
#define FITCAL_BINARY_DIR (std::string(::fitcal::test_paths::kBinaryDir))
