// One flow's work on the lines a model holds, shared by the one-process and
// the MPI model: the phase tables, then the blocks of lines, in one parallel
// region; and the FFT floor, the same transforms timed alone.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include "../../core/error.hpp"
#include "kernels.hpp"
#include "lpi_config.h"
#include "projective_line.hpp"
#include "transforms.hpp"

#if LPI_HAVE_OPENMP
#include <omp.h>
#endif

namespace lpi {
namespace sine_euler {

inline int this_thread() {
#if LPI_HAVE_OPENMP
    return omp_get_thread_num();
#else
    return 0;
#endif
}

// Block b of `lines` lines (kBlock each, the last one the remainder).
inline int blocks_of(int lines) { return (lines + kBlock - 1) / kBlock; }
inline int lines_in_block(int lines, int b) { return lines - b * kBlock < kBlock ? lines - b * kBlock : kBlock; }

// Writes the phase tables of the transformed line spectrum (write_phase),
// then calls move_block(b, x) for every block b of `lines` lines with the
// block buffer x of its thread. The implicit barrier between the two loops
// orders them; blocks are the same whichever thread runs them, so the
// results are the same for every thread count.
template <class MoveBlock>
void run_line_flows(LineTransforms &T, int N, int lines, int threads, double factor, MoveBlock &&move_block) {
    const int blocks = blocks_of(lines);
    auto phase = [&](int l) { write_phase(N, l, factor, T.spectrum(), T.phase()); };
#if LPI_HAVE_OPENMP
    if (threads > 1 && blocks > 1) {
#pragma omp parallel num_threads(threads)
        {
#pragma omp for schedule(static)
            for (int l = 0; l < N; ++l) phase(l);
#pragma omp for schedule(static)
            for (int b = 0; b < blocks; ++b) move_block(b, T.block(static_cast<std::size_t>(this_thread())));
        }
        return;
    }
#endif
    // One thread: plain loops. Work sharing outside a region of the library's
    // own would bind to the caller's enclosing OpenMP team, if it has one
    // (a host program stepping its handles from a parallel region), and share
    // out, or wait at a barrier for, threads working on other handles.
    for (int l = 0; l < N; ++l) phase(l);
    for (int b = 0; b < blocks; ++b) move_block(b, T.block(0));
}

// The flow count of `steps` steps of `flows_per_step` flows: LPI_ERR_INVALID
// for steps < 1, LPI_ERR_OVERFLOW when it does not fit a std::size_t.
inline std::size_t flow_count(std::size_t flows_per_step, std::int64_t steps) {
    if (steps < 1) fail(LPI_ERR_INVALID, "nsteps must be >= 1, got " + std::to_string(steps));
    if (flows_per_step == 0 || static_cast<std::uint64_t>(steps) > SIZE_MAX / flows_per_step)
        fail(LPI_ERR_OVERFLOW, "nsteps = " + std::to_string(steps) + " times " +
                                   std::to_string(flows_per_step) + " flows per step overflows the flow count");
    return flows_per_step * static_cast<std::size_t>(steps);
}

// Seconds that `flows` flows' transforms alone take (the line spectrum's and
// a forward and backward transform of every block), on T's plans, buffers
// and threads, on zeros.
inline double time_line_transforms(LineTransforms &T, int N, int lines, int threads, std::size_t flows) {
    const int blocks = blocks_of(lines);
    std::memset(T.spectrum(), 0, sizeof(double) * 2 * N);
    for (int i = 0; i < threads; ++i)
        std::memset(T.block(static_cast<std::size_t>(i)), 0, sizeof(double) * 2 * N * kBlock);
    const auto start = std::chrono::steady_clock::now();
    auto transform_block = [&](int b, double *x) {
        T.forward(lines_in_block(lines, b), x);
        T.backward(lines_in_block(lines, b), x);
    };
    for (std::size_t f = 0; f < flows; ++f) {
        T.transform_spectrum();
#if LPI_HAVE_OPENMP
        // As run_line_flows: one thread runs plain loops and enters no
        // OpenMP region (libgomp exits the process when it cannot allocate
        // a region's team).
        if (threads > 1 && blocks > 1) {
#pragma omp parallel for num_threads(threads) schedule(static)
            for (int b = 0; b < blocks; ++b) transform_block(b, T.block(static_cast<std::size_t>(this_thread())));
            continue;
        }
#endif
        for (int b = 0; b < blocks; ++b) transform_block(b, T.block(0));
    }
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace sine_euler
}  // namespace lpi
