// Sine-Euler on one thread: where a flow's time goes. The parts of a flow
// (SineEuler::flow in model.cpp) timed one by one, on the library's own
// kernels and plans (FFTW "measure", as in bench_sine_euler): the line
// spectrum (the direction's own line and its FFT: what stays serial when
// threads share a flow), the phase tables (two sines per entry), and for each
// block of lines the gather, the forward and backward FFTs, the phase and the
// scatter, each direction's blocks as the model cuts them (its row runs, or
// the Column or General blocks where it has none). Summed over every
// direction of the projective line, so that the layouts weigh as they do in
// a step; per part the least of three passes. The columns rows, runs and
// other count the Row directions, the other directions laid in row runs,
// and those laid in Column or General blocks. Prints ns per mode moved, the
// parts beside the FFTs
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
    // Layout 1: the model's (row runs where row_runs gives them); layout 0,
    // for comparison where they differ: row runs for the Row directions only,
    // Column and General blocks for the rest.
    std::vector<std::vector<RowRun>> layout_runs[2];
    std::vector<int> counts;
    bool differ = false;
    for (const Direction &D : directions) {
        layout_runs[1].push_back(row_runs(D, N));
        for (const RowRun &run : layout_runs[1].back()) counts.push_back(run.count);
        layout_runs[0].push_back(D.k1 == 1 ? layout_runs[1].back() : std::vector<RowRun>{});
        differ = differ || layout_runs[0].back().size() != layout_runs[1].back().size();
    }
    LineTransforms T(N, blocks.M, lpi::FftPlanning::Measure, counts);
    const Hamiltonian H(N);  // Euler's
    std::vector<double> w = field(N);
    const double factor = 1e-3 / (2.0 * (2.0 * std::acos(-1.0) / N));  // t = 1e-3
    double best_of[2][kParts];
    for (auto &best : best_of) std::fill(best, best + kParts, INFINITY);
    for (int pass = 0; pass < 6; ++pass) {  // the layouts in turn, three passes each
        const int layout = differ ? pass % 2 : 1;
        const std::vector<std::vector<RowRun>> &runs = layout_runs[layout];
        double *best = best_of[layout];
        double sum[kParts] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
        for (std::size_t k = 0; k < directions.size(); ++k) {
            const Direction &D = directions[k];
            const std::vector<RowRun> &row_run = runs[k];
            Clock::time_point clock = Clock::now();
            line_stream(D, H, w.data(), T.spectrum());
            T.transform_spectrum();
            sum[Spectrum] += seconds_since(clock);
            const bool mirrored = row_run.empty() || D.k1 == 1;
            for (int l = 0; l < N; ++l) write_phase(N, l, factor, T.spectrum(), T.phase(), mirrored);
            sum[Tables] += seconds_since(clock);
            const int count_of_blocks = row_run.empty() ? blocks.count() : static_cast<int>(row_run.size());
            for (int block = 0; block < count_of_blocks; ++block) {
                double *x = T.block(0);
                const RowRun *run = row_run.empty() ? nullptr : &row_run[static_cast<std::size_t>(block)];
                const int count = run ? run->count : blocks.lines(block);
                const int d0 = blocks.first_line(block);
                const int first_lane = run ? block * N / count_of_blocks : blocks.first_lane(block);
                int lines[kBlock];  // the lines of a row run, as the model forms them
                if (run)
                    for (int i = 0; i < count; ++i) lines[i] = run_line(D, *run, i, N);
                clock = Clock::now();
                if (run)
                    gather_run(*run, D.k2, N, first_lane, w.data(), x);
                else
                    gather_block(D, N, d0, count, first_lane, w.data(), x);
                sum[Gather] += seconds_since(clock);
                T.forward(count, x);
                sum[Transforms] += seconds_since(clock);
                if (!run)
                    apply_phase(N, d0, count, T.phase(), -D.sigma, x);
                else if (D.k1 == 1)
                    apply_phase(N, run->column, count, T.phase(), 1.0, x);
                else
                    apply_phase_lines(N, lines, count, T.phase(), -D.sigma, x);
                sum[Phase] += seconds_since(clock);
                T.backward(count, x);
                sum[Transforms] += seconds_since(clock);
                if (run)
                    scatter_run(*run, D.k2, N, first_lane, x, w.data());
                else
                    scatter_block(D, N, d0, count, first_lane, x, w.data());
                sum[Scatter] += seconds_since(clock);
            }
        }
        for (int p = 0; p < kParts; ++p) best[p] = std::min(best[p], sum[p]);
    }
    for (int layout = differ ? 0 : 1; layout < 2; ++layout) {
        const std::vector<std::vector<RowRun>> &runs = layout_runs[layout];
        const double *best = best_of[layout];
        int layouts[3] = {0, 0, 0};  // Row, other row runs, Column or General blocks
        for (std::size_t k = 0; k < directions.size(); ++k)
            ++layouts[runs[k].empty() ? 2 : directions[k].k1 == 1 ? 0 : 1];
        const double modes = static_cast<double>(directions.size()) * N * blocks.M, ns = 1e9 / modes;
        const double rest = best[Spectrum] + best[Tables] + best[Gather] + best[Phase] + best[Scatter];
        std::printf(
            "%5d %5d %5d %5d %8.2f %8.2f %8.2f %8.2f %8.2f %8.2f %8.2f "
            "%7.2f %7.2f %6.1f%%\n",
            N, layouts[0], layouts[1], layouts[2], ns * best[Transforms], ns * best[Spectrum],
            ns * best[Tables], ns * best[Gather], ns * best[Phase], ns * best[Scatter], ns * rest,
            rest / best[Transforms], (best[Gather] + best[Scatter]) / best[Transforms],
            100.0 * best[Spectrum] / (rest + best[Transforms]));
    }
    std::fflush(stdout);
}

}  // namespace

int main() {
    std::printf(
        "sine-Euler, one thread: a flow's parts in ns per mode moved, "
        "summed over every direction\n");
    std::printf("%5s %5s %5s %5s %8s %8s %8s %8s %8s %8s %8s %7s %7s %7s\n", "N", "rows", "runs", "other",
                "FFTs", "spectrum", "sines", "gather", "phase", "scatter", "rest", "rest/", "moves/",
                "serial");
    std::printf("%5s %5s %5s %5s %8s %8s %8s %8s %8s %8s %8s %7s %7s %7s\n", "", "", "", "", "", "", "", "",
                "", "", "", "FFTs", "FFTs", "");
    const int Ns[] = {61, 125, 127, 243, 251, 375, 509, 625};
    for (int N : Ns) measure(N);
    return 0;
}
