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
// bench_sine_euler exceeds 1 by) and the serial part's share of the flow.
// Prints figures; asserts nothing.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>

#include "models/sine_euler/hamiltonian.hpp"
#include "models/sine_euler/indexing.hpp"
#include "models/sine_euler/kernels.hpp"
#include "models/sine_euler/projective_line.hpp"
#include "models/sine_euler/transforms.hpp"

namespace {

using namespace lpi::sine_euler;
using Clock = std::chrono::steady_clock;

enum Part { Spectrum, Tables, Gather, Transforms, Phase, Scatter, kParts };

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

void measure(int N) {
    const std::vector<Direction> directions = projective_line(N);
    const LineBlocks blocks(N);
    LineTransforms T(N, blocks.M, lpi::FftPlanning::Measure);
    const Hamiltonian H(N);  // Euler's
    std::vector<double> w = field(N);
    const double factor = 1e-3 / (2.0 * (2.0 * std::acos(-1.0) / N));  // t = 1e-3
    double best[kParts];
    std::fill(best, best + kParts, INFINITY);
    int layouts[3] = {0, 0, 0};
    for (const Direction &D : directions) ++layouts[D.layout];
    for (int pass = 0; pass < 3; ++pass) {
        double sum[kParts] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
        for (const Direction &D : directions) {
            Clock::time_point clock = Clock::now();
            line_stream(D, H, w.data(), T.spectrum());
            T.transform_spectrum();
            sum[Spectrum] += seconds_since(clock);
            for (int l = 0; l < N; ++l) write_phase(N, l, factor, T.spectrum(), T.phase());
            sum[Tables] += seconds_since(clock);
            for (int block = 0; block < blocks.count(); ++block) {
                const int d0 = blocks.first_line(block), count = blocks.lines(block);
                double *x = T.block(0);
                clock = Clock::now();
                gather_block(D, N, d0, count, blocks.first_lane(block), w.data(), x);
                sum[Gather] += seconds_since(clock);
                T.forward(count, x);
                sum[Transforms] += seconds_since(clock);
                apply_phase(N, d0, count, T.phase(), -D.sigma, x);
                sum[Phase] += seconds_since(clock);
                T.backward(count, x);
                sum[Transforms] += seconds_since(clock);
                scatter_block(D, N, d0, count, blocks.first_lane(block), x, w.data());
                sum[Scatter] += seconds_since(clock);
            }
        }
        for (int p = 0; p < kParts; ++p) best[p] = std::min(best[p], sum[p]);
    }
    const double modes = static_cast<double>(directions.size()) * N * blocks.M, ns = 1e9 / modes;
    const double rest = best[Spectrum] + best[Tables] + best[Gather] + best[Phase] + best[Scatter];
    std::printf("%5d %5d %5d %5d %8.2f %8.2f %8.2f %8.2f %8.2f %8.2f %8.2f %7.2f %7.2f %6.1f%%\n", N,
                layouts[0], layouts[1], layouts[2], ns * best[Transforms], ns * best[Spectrum],
                ns * best[Tables], ns * best[Gather], ns * best[Phase], ns * best[Scatter], ns * rest,
                rest / best[Transforms], (best[Gather] + best[Scatter]) / best[Transforms],
                100.0 * best[Spectrum] / (rest + best[Transforms]));
    std::fflush(stdout);
}

}  // namespace

int main() {
    std::printf("sine-Euler, one thread: a flow's parts in ns per mode moved, summed over every direction\n");
    std::printf("%5s %5s %5s %5s %8s %8s %8s %8s %8s %8s %8s %7s %7s %7s\n", "N", "rows", "cols", "other",
                "FFTs", "spectrum", "sines", "gather", "phase", "scatter", "rest", "rest/", "moves/", "serial");
    std::printf("%5s %5s %5s %5s %8s %8s %8s %8s %8s %8s %8s %7s %7s %7s\n", "", "", "", "", "", "", "", "", "",
                "", "", "FFTs", "FFTs", "");
    const int Ns[] = {61, 125, 127, 243, 251, 375, 509, 625};
    for (int N : Ns) measure(N);
    return 0;
}
