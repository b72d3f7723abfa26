// One flow's work on the lines a model holds, shared by the one-process and
// the MPI model: the phase tables, then the blocks of lines, in one parallel
// region; and the FFT floor, the same transforms timed alone.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <thread>

#include "../../core/error.hpp"
#include "../../core/threads.hpp"
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

// The flow of a gathered block x of `count` lines d0 .. d0+count-1: forward
// transform along s, the lines' increments (exp(t Lambda_l) - 1) / N from
// T's phase tables (`sign` = -sigma of the direction), backward transform.
inline void flow_block(LineTransforms &T, int N, int d0, int count, double sign, double *x) {
    T.forward(count, x);
    apply_phase(N, d0, count, T.phase(), sign, x);
    T.backward(count, x);
}

// Up to this many threads one of them, the writer, moves every block in
// and out of the modes, and the others only transform (run_line_flows).
constexpr int kMostThreadsPerWriter = 4;

inline void spin_pause() {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
}

// A wait for another thread of the team: spins, then yields the processor.
// With more threads than free processors the thread waited for may be the
// one not running, and a wait that only spun held the processor it needed
// for the rest of its time slice: 3 and 4 threads on a 2-core host took 9 to
// 19 s for two steps at N = 125, against 0.15 s on one. The spins cover a
// block's transform (about 13 us at N = 125), the usual wait, so a team on
// free processors never yields; `yield_at` is 16 where the team has more
// threads than the process has processors.
class TeamWait {
public:
    explicit TeamWait(int yield_at) : yield_at_(yield_at) {}
    void operator()() {
        if (++spins_ < yield_at_) {
            spin_pause();
            return;
        }
        spins_ = 0;
        std::this_thread::yield();
    }
    void reset() { spins_ = 0; }

private:
    int spins_ = 0;
    int yield_at_;
};

// Writes the phase tables of the transformed line spectrum (write_phase),
// then, for every block b of `lines` lines and a block buffer x, calls
// gather(b, x) (the lines out of the modes), transform(b, x) (forward,
// phase, backward) and scatter(b, x) (the increments into the modes).
//
// On 2 .. kMostThreadsPerWriter threads, thread 0 alone gathers and
// scatters, in the order of the blocks, through a ring of two buffers a
// thread; every thread transforms the blocks gathered, claimed in order
// (thread 0 when it has nothing to move). The phase tables are the other
// threads' to write while thread 0 gathers the first blocks: written by
// every thread with a barrier after them, they kept thread 0 waiting for
// the slowest before it gathered anything, and at N = 125 (4 blocks a
// flow) two threads took a step 5-8% longer. Two threads each writing its own
// blocks put both in every row of the modes, which on a host with two free
// cores made a step 0.67-0.88x as fast as on one thread at N = 125 .. 375
// (design.md, "Threads"); handed over, 1.13-1.67x, at the price of every
// block's buffer crossing between the cores. Beyond that many threads one
// writer could not keep up, and each thread moves its own blocks whole.
//
// Each block meets the same operations whichever thread runs them, so the
// results are the same for every thread count.
template <class Gather, class Transform, class Scatter>
void run_line_flows(LineTransforms &T, int N, int lines, int threads, double factor, Gather &&gather,
                    Transform &&transform, Scatter &&scatter) {
    const int blocks = blocks_of(lines);
    auto phase = [&](int l) { write_phase(N, l, factor, T.spectrum(), T.phase()); };
#if LPI_HAVE_OPENMP
    threads = team_size_here(threads);
    if (threads > 1 && blocks > 1) {
        const int yield_at = threads > omp_get_num_procs() ? 16 : 1 << 12;
        enum : int { kEmpty, kGathered, kTransformed };
        std::atomic<int> *stage = T.handover();
        for (int b = 0; b < blocks; ++b) stage[b].store(kEmpty, std::memory_order_relaxed);
        std::atomic<int> next_transform{0}, phases_written{0};
        const int ring = static_cast<int>(T.buffers());
        auto buffer = [&](int b) { return T.block(static_cast<std::size_t>(b % ring)); };
        auto transform_and_hand_back = [&](int b) {
            transform(b, buffer(b));
            stage[b].store(kTransformed, std::memory_order_release);
        };
        // The transformers write the phase tables, each its own range of l,
        // while the writer gathers the first blocks, which need no tables;
        // a block is transformed once all the ranges are written. (The team
        // may have fewer threads than asked for; alone, the writer writes
        // them all.)
#pragma omp parallel num_threads(threads)
        {
            const int transformers = omp_get_num_threads() - 1;
            auto phase_tables_written = [&] {
                return phases_written.load(std::memory_order_acquire) == transformers;
            };
            if (transformers == 0)
                for (int l = 0; l < N; ++l) phase(l);
            if (transformers + 1 > kMostThreadsPerWriter) {
#pragma omp for schedule(static)
                for (int l = 0; l < N; ++l) phase(l);
                double *x = T.block(static_cast<std::size_t>(this_thread()));
#pragma omp for schedule(static)
                for (int b = 0; b < blocks; ++b) {
                    gather(b, x);
                    transform(b, x);
                    scatter(b, x);
                }
            } else if (this_thread() == 0) {
                // The writer: gather up to a ring ahead, scatter in order,
                // transform when neither can go on.
                int gathered = 0, scattered = 0;
                TeamWait wait(yield_at);
                while (scattered < blocks) {
                    if (gathered < blocks && gathered - scattered < ring) {
                        gather(gathered, buffer(gathered));
                        stage[gathered].store(kGathered, std::memory_order_release);
                        ++gathered;
                        wait.reset();
                    } else if (stage[scattered].load(std::memory_order_acquire) == kTransformed) {
                        scatter(scattered, buffer(scattered));
                        ++scattered;
                        wait.reset();
                    } else {
                        int b = next_transform.load(std::memory_order_relaxed);
                        if (b < gathered && phase_tables_written() &&
                            next_transform.compare_exchange_strong(b, b + 1)) {
                            transform_and_hand_back(b);
                            wait.reset();
                        } else {
                            wait();
                        }
                    }
                }
            } else {
                const int range = this_thread() - 1;
                for (int l = N * range / transformers; l < N * (range + 1) / transformers; ++l) phase(l);
                phases_written.fetch_add(1, std::memory_order_release);
                TeamWait wait(yield_at);
                while (!phase_tables_written()) wait();
                for (int b; (b = next_transform.fetch_add(1)) < blocks;) {
                    wait.reset();
                    while (stage[b].load(std::memory_order_acquire) != kGathered) wait();
                    transform_and_hand_back(b);
                }
            }
        }
        return;
    }
#else
    static_cast<void>(threads);
#endif
    // One thread: plain loops. Work sharing outside a region of the library's
    // own would bind to the caller's enclosing OpenMP team, if it has one
    // (a host program stepping its handles from a parallel region), and share
    // out, or wait at a barrier for, threads working on other handles.
    for (int l = 0; l < N; ++l) phase(l);
    double *x = T.block(0);
    for (int b = 0; b < blocks; ++b) {
        gather(b, x);
        transform(b, x);
        scatter(b, x);
    }
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
        if (team_size_here(threads) > 1 && blocks > 1) {
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
