#pragma once
// Runs one loader of tests/fuzz/loader_fuzz_targets.h on a byte string: shared by the libFuzzer
// executables (fuzz_main.cc) and the corpus replay test that ctest runs
// (tests/fuzz_corpus_test.cc).

#include <string>
#include <string_view>
#include <vector>

namespace fitcal::fuzz {

// Names of the targets in loader_fuzz_targets.h, in file order.
std::vector<std::string> FuzzTargetNames();

// Writes `bytes` to the target's file in a private scratch directory and runs the loader.
// Returns true if the loader accepted the input, false if it threw InputError; anything else
// (another exception, a crash) escapes. Throws std::invalid_argument for an unknown target.
bool RunFuzzTarget(const std::string& target, std::string_view bytes);

}  // namespace fitcal::fuzz
