// Instruction sets a function may be compiled for beside the baseline and
// chosen at run time (x86-64 with GCC or Clang; elsewhere the baseline alone).
// The baseline computes the same bits: what differs is speed.
#pragma once

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define LPI_FMA_DISPATCH 1
// std::fma as one instruction instead of a call into libm (about 3 ns each):
// every helper a function inlines is compiled for its target.
#define LPI_TARGET_FMA __attribute__((target("fma")))
#else
#define LPI_FMA_DISPATCH 0
#endif

namespace lpi {

inline bool cpu_has_fma() {
#if LPI_FMA_DISPATCH
    static const bool fma = __builtin_cpu_supports("fma");
    return fma;
#else
    return false;
#endif
}

}  // namespace lpi
