// libFuzzer entry point for one loader (FITCAL_FUZZ_TARGET_NAME, set by tests/fuzz/CMakeLists.txt).
// Only InputError may come out of a loader; anything else aborts and libFuzzer keeps the input.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fitcal::fuzz::RunFuzzTarget(FITCAL_FUZZ_TARGET_NAME,
                              std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}
