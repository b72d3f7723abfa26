// Sine-Euler on one thread: where a flow's time goes. The parts of a flow
// (SineEuler::flow in model.cpp) timed one by one, on the library's own
// kernels and plans (FFTW "measure", as in bench_sine_euler): the line
// spectrum (the direction's own line and its FFT: what stays serial when
// threads share a flow), the phase tables (two sines per entry), and for each
// block of lines the gather, the forward and backward FFTs, the phase and the
// scatter. Summed over every direction of the projective line, so that the
// Row, Column and General layouts weigh as they do in a step; per part the
// least of three passes. Prints ns per mode moved, the parts beside the FFTs
// ("rest / FFTs" is about what the step's ratio to the FFT floor of
// bench_sine_euler exceeds 1 by), the serial part's share of the flow, and
// the gather and scatter of each layout's directions by themselves, per mode
// those directions move (General blocks go one mode at a time: composite N
// pay for them). Each direction's blocks are moved where the model moves
// them (orientation, projective_line.hpp): Column directions in the
// transposed modes; "transp." is the two passes that carry the modes there
// and back, once a sweep of the directions (once a leapfrog step, of two
// sweeps, in a run). The
// table is printed for the kernels this CPU runs, then (where those are AVX2)
// for the baseline ones that CPUs without AVX2, and all but x86-64, run.
// Prints figures; asserts nothing.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include "models/sine_euler/hamiltonian.hpp"
#include "models/sine_euler/indexing.hpp"
#include "models/sine_euler/kernels.hpp"
#include "models/sine_euler/projective_line.hpp"
#include "models/sine_euler/transforms.hpp"
#include "bench_common.h"

namespace {

using namespace lpi::sine_euler;
using Clock = std::chrono::steady_clock;

enum Part { Spectrum, Tables, Gather, Transforms, Phase, Scatter, Transpose, kParts };

double seconds_since(Clock::time_point &start) {
    const Clock::time_point now = Clock::now();
    const double seconds = std::chrono::duration<double>(now - start).count();
    start = now;
    return seconds;
}

// A smooth field in a few low modes, Hermitian to the bit (each mode and its
// mirror real and equal), of unit size.
std::vector<double> field(int N) {
    std::vector<double> w(2 * static_cast<std::size_t>(N) * N, 0.0);
    const int modes[][2] = {{1, 2}, {1, -2}, {3, -1}, {5, 4}};
    for (const auto &m : modes)
        for (int sign : {1, -1}) {
            const std::size_t i = mode_index(modulo(sign * m[0], N), modulo(sign * m[1], N), N);
            w[2 * i] += 0.25;
        }
    return w;
}

// The kernels timed: those this CPU runs, or the baseline ones (which every
// CPU without AVX2 runs, and every CPU but x86-64).
struct Kernels {
    const char *name;
    decltype(&gather_block) gather;
    decltype(&scatter_block) scatter;
    decltype(&apply_phase) phase;
};

void measure(int N, const Kernels &kernels) {
    const std::vector<Direction> directions = projective_line(N);
    const LineBlocks blocks(N);
    LineTransforms T(N, blocks.M, lpi::FftPlanning::Measure);
    const Hamiltonian H(N);  // Euler's
    std::vector<double> w = field(N), transposed(w.size());
    const double factor = 1e-3 / (2.0 * (2.0 * std::acos(-1.0) / N));  // t = 1e-3
    double best[kParts], best_moves[3];
    std::fill(best, best + kParts, INFINITY);
    std::fill(best_moves, best_moves + 3, INFINITY);
    int layouts[3] = {0, 0, 0};
    for (const Direction &D : directions) ++layouts[D.layout];
    for (int pass = 0; pass < 3; ++pass) {
        double sum[kParts] = {}, moves[3] = {0.0, 0.0, 0.0};
        bool in_transposed = false;
        for (const Direction &D : directions) {
            // Where the model's flows move this direction's blocks.
            Clock::time_point clock = Clock::now();
            const Orientation wanted = orientation(D);
            if (wanted == Orientation::Transposed && !in_transposed)
                transpose_kept_half(N, w.data(), transposed.data()), in_transposed = true;
            if (wanted == Orientation::Modes && in_transposed)
                transpose_kept_half(N, transposed.data(), w.data()), in_transposed = false;
            sum[Transpose] += seconds_since(clock);
            double *modes = in_transposed ? transposed.data() : w.data();
            const Direction lines = in_transposed ? transposed_view(D) : D;
            line_stream(D, H, modes, in_transposed, T.spectrum());
            T.transform_spectrum();
            sum[Spectrum] += seconds_since(clock);
            for (int l = 0; l < N; ++l) write_phase(N, l, factor, T.spectrum(), T.phase());
            sum[Tables] += seconds_since(clock);
            for (int block = 0; block < blocks.count(); ++block) {
                const int d0 = blocks.first_line(block), count = blocks.lines(block);
                double *x = T.block(0);
                clock = Clock::now();
                kernels.gather(lines, N, d0, count, blocks.first_lane(block), modes, x);
                const double gather = seconds_since(clock);
                sum[Gather] += gather;
                moves[D.layout] += gather;
                T.forward(count, x);
                sum[Transforms] += seconds_since(clock);
                kernels.phase(N, d0, count, T.phase(), -D.sigma, x);
                sum[Phase] += seconds_since(clock);
                T.backward(count, x);
                sum[Transforms] += seconds_since(clock);
                kernels.scatter(lines, N, d0, count, blocks.first_lane(block), x, modes);
                const double scatter = seconds_since(clock);
                sum[Scatter] += scatter;
                moves[D.layout] += scatter;
            }
        }
        Clock::time_point clock = Clock::now();
        if (in_transposed) transpose_kept_half(N, transposed.data(), w.data());
        sum[Transpose] += seconds_since(clock);
        for (int p = 0; p < kParts; ++p) best[p] = std::min(best[p], sum[p]);
        for (int l = 0; l < 3; ++l) best_moves[l] = std::min(best_moves[l], moves[l]);
    }
    const double modes = static_cast<double>(directions.size()) * N * blocks.M, ns = 1e9 / modes;
    const double rest =
        best[Spectrum] + best[Tables] + best[Gather] + best[Phase] + best[Scatter] + best[Transpose];
    std::printf("%5d %5d %5d %5d %8.2f %8.2f %8.2f %8.2f %8.2f %8.2f %8.2f %8.2f %7.2f %7.2f %6.1f%%", N,
                layouts[0], layouts[1], layouts[2], ns * best[Transforms], ns * best[Spectrum],
                ns * best[Tables], ns * best[Gather], ns * best[Phase], ns * best[Scatter],
                ns * best[Transpose], ns * rest,
                rest / best[Transforms], (best[Gather] + best[Scatter]) / best[Transforms],
                100.0 * best[Spectrum] / (rest + best[Transforms]));
    for (int l = 0; l < 3; ++l) {  // per mode moved by that layout's directions
        const double layout_modes = static_cast<double>(layouts[l]) * N * blocks.M;
        if (layouts[l] > 0) std::printf(" %6.2f", 1e9 * best_moves[l] / layout_modes);
        else std::printf(" %6s", "-");
    }
    std::printf("\n");
    std::fflush(stdout);
}

void table(const Kernels &kernels) {
    std::printf("sine-Euler, one thread: a flow's parts in ns per mode moved, summed over every direction"
                " (%s kernels)\n", kernels.name);
    std::printf("%5s %5s %5s %5s %8s %8s %8s %8s %8s %8s %8s %8s %7s %7s %7s %20s\n", "N", "rows", "cols",
                "other", "FFTs", "spectrum", "sines", "gather", "phase", "scatter", "transp.", "rest", "rest/",
                "moves/", "serial", "moves by layout");
    std::printf("%5s %5s %5s %5s %8s %8s %8s %8s %8s %8s %8s %8s %7s %7s %7s %6s %6s %6s\n", "", "", "", "", "", "",
                "", "", "", "", "", "", "FFTs", "FFTs", "", "row", "column", "other");
    const std::vector<int> Ns = bench_quick() ? std::vector<int>{15, 27, 61}  // General, Column, Row
                                              : std::vector<int>{61, 125, 127, 243, 251, 375, 509, 625};
    for (int N : Ns) measure(N, kernels);
}

}  // namespace

int main() {
    const Kernels here = {kernel_instruction_set(), gather_block, scatter_block, apply_phase};
    table(here);
    if (std::strcmp(here.name, "baseline") != 0) {
        std::printf("\n");
        table({"baseline", baseline::gather_block, baseline::scatter_block, baseline::apply_phase});
    }
    return 0;
}
