#pragma once
// How a fitcal process asks glibc to keep the memory it frees. A fit allocates and frees the same
// large buffers (Jacobians, replays, residual vectors) again and again. With glibc's defaults each
// block above 128 KiB is its own mmap, and the heap's top is given back to the kernel whenever
// 128 KiB of it is free, so every reallocation costs fresh, zeroed pages: on an
// IndependentDiagnose data set (diagnose --threads 1, 32 runs) 53-75 thousand page faults and
// 0.45-0.70 s of system time beside 1.5-1.6 s of user. Kept for the next allocation instead (up
// to 32 MiB a block, glibc's upper bound, nothing trimmed below 1 GiB): 10 thousand faults, 0.1 s
// system, 1.1 s user, the peak resident size the same (50 MB). Where memory lies changes no
// result. Called first thing by the fitcal binary (cli/command_line.cc) and by every test and
// benchmark process (tests/test_paths.cc.in), so that in-process fits allocate as the binary's.

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace fitcal {

inline void KeepFreedMemoryForReuse() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024);
  mallopt(M_TRIM_THRESHOLD, 1024 * 1024 * 1024);
#endif
}

}  // namespace fitcal
