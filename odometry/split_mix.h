#pragma once
// SplitMix64 (Steele, Lea, Flood 2014): a seed and a stream index mixed into one generator seed,
// the one mixer of every simulator (sim/stepped_run.h, models/asoc/asoc_extras.h): its outputs
// are fixed, so a seed names the same data set on every machine.

#include <cstdint>

namespace fitcal {

inline std::uint64_t SplitMix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

}  // namespace fitcal
