// White-box: the hot loops of a sine-Euler line flow against independent
// computations. gather_block reads element s of line d at d j + s k and
// scatter_block adds the increments there and writes the conjugates at the
// mirror modes, touching nothing else, for every direction (Row, Column and
// General layouts) and block, full and remainder; apply_phase multiplies by
// the written-out complex arithmetic of (e - 1) / N to the bit (the tables'
// layout and the two-at-a-time evaluation change no operation), and that is
// (exp(t Lambda_l) - 1) / N computed from the angles with std::polar.
#include <algorithm>
#include <complex>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <numeric>
#include <vector>

#include "lpi_config.h"
#include "lpi_test.h"
#include "models/sine_euler/kernels.hpp"
#include "models/sine_euler/projective_line.hpp"

namespace {

using namespace lpi::sine_euler;

// Uniform in [-1, 1), reproducible.
struct Random {
    std::uint64_t state;
    double next() {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return static_cast<double>(state >> 11) / 4503599627370496.0 - 1.0;
    }
};

std::size_t mode_at(int a, int b, int N) {
    a %= N, b %= N;
    return static_cast<std::size_t>(a < 0 ? a + N : a) * N + (b < 0 ? b + N : b);
}

// A Hermitian field: w_{-m} = conj(w_m).
std::vector<double> hermitian_field(int N, Random &random) {
    std::vector<double> w(2 * static_cast<std::size_t>(N) * N);
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b) {
            const std::size_t m = mode_at(a, b, N), mirror = mode_at(-a, -b, N);
            if (mirror < m) continue;
            w[2 * m] = w[2 * mirror] = random.next();
            w[2 * m + 1] = m == mirror ? 0.0 : random.next();
            w[2 * mirror + 1] = -w[2 * m + 1];
        }
    return w;
}

const int kGatherSizes[] = {15, 25, 35, 49, 75};

// A block gathered into x (count lines), and what scattering increments
// into it must give.
struct Moves {
    std::vector<double> increment, expected;
    std::vector<char> moved;  // each mode once
    Moves(const std::vector<double> &w, const std::vector<double> &x, int N)
        : increment(x.size()), expected(w), moved(static_cast<std::size_t>(N) * N, 0) {}
    // Checks that x[s * count + i] holds element s of line d of D (the mode
    // at d j + s k) for every s, draws its increments, and records the sums
    // there and their conjugates at the mirror modes.
    void line(const Direction &D, int N, int d, int i, int count, const std::vector<double> &w,
              const std::vector<double> &x, Random &random) {
        for (int s = 0; s < N; ++s) {
            const std::size_t e = static_cast<std::size_t>(s) * count + i;
            const std::size_t m = mode_at(d * D.j1 + s * D.k1, d * D.j2 + s * D.k2, N);
            const std::size_t mirror = mode_at(-(d * D.j1 + s * D.k1), -(d * D.j2 + s * D.k2), N);
            assert_memory_equal(&x[2 * e], &w[2 * m], 2 * sizeof(double));
            increment[2 * e] = random.next();
            increment[2 * e + 1] = random.next();
            expected[2 * m] = w[2 * m] + increment[2 * e];
            expected[2 * m + 1] = w[2 * m + 1] + increment[2 * e + 1];
            expected[2 * mirror] = expected[2 * m];
            expected[2 * mirror + 1] = -expected[2 * m + 1];
            assert_int_equal(moved[m] + moved[mirror], 0);
            moved[m] = moved[mirror] = 1;
        }
    }
};

void test_gather_scatter_follow_the_lines(void **) {
    Random random{42};
    for (int N : kGatherSizes) {
        const LineBlocks blocks(N);
        int layouts[3] = {0, 0, 0};
        for (const Direction &D : projective_line(N)) {
            ++layouts[D.layout];
            for (int b = 0; b < blocks.count(); ++b) {
                const int d0 = blocks.first_line(b), count = blocks.lines(b);
                const std::vector<double> w = hermitian_field(N, random);
                std::vector<double> x(2 * static_cast<std::size_t>(N) * count);
                gather_block(D, N, d0, count, blocks.first_lane(b), w.data(), x.data());
                Moves moves(w, x, N);
                for (int i = 0; i < count; ++i) moves.line(D, N, d0 + i, i, count, w, x, random);
                std::vector<double> scattered = w;
                scatter_block(D, N, d0, count, blocks.first_lane(b), moves.increment.data(), scattered.data());
                assert_memory_equal(scattered.data(), moves.expected.data(), sizeof(double) * w.size());
            }
        }
        std::printf("N = %2d: %3d Row, %3d Column, %3d General directions, %d blocks each\n", N,
                    layouts[Direction::Row], layouts[Direction::Column], layouts[Direction::General],
                    blocks.count());
    }
}

const int kPhaseSizes[] = {7, 35, 49, 125};

void test_phase_is_the_complex_arithmetic(void **) {
    Random random{7};
    for (int N : kPhaseSizes) {
        const LineBlocks blocks(N);
        // A line spectrum of angles up to about 1 radian (factor B_l).
        std::vector<double> spectrum(2 * static_cast<std::size_t>(N));
        for (double &b : spectrum) b = random.next();
        const double factor = 0.9;
        std::vector<double> tables(phase_table_doubles(N));
        for (int l = 0; l < N; ++l) write_phase(N, l, factor, spectrum.data(), tables.data());
        // v_j = exp(i phi_j) - 1 as write_phase forms it, and u_j = exp(i phi_j).
        std::vector<std::complex<double>> v(N), u(N);
        for (int j = 0; j < N; ++j) {
            const double phi = factor * spectrum[2 * j], half = std::sin(0.5 * phi);
            v[j] = {-2.0 * half * half, std::sin(phi)};
            u[j] = std::polar(1.0, phi);
        }
        double worst = 0.0;
        for (double sign : {-1.0, 1.0})
            for (int b = 0; b < blocks.count(); ++b) {
                const int d0 = blocks.first_line(b), count = blocks.lines(b);
                std::vector<double> x(2 * static_cast<std::size_t>(N) * count);
                for (double &z : x) z = random.next();
                std::vector<double> expected(x.size());
                for (int l = 0; l < N; ++l)
                    for (int i = 0; i < count; ++i) {
                        const int d = d0 + i;
                        const std::size_t e = 2 * (static_cast<std::size_t>(l) * count + i);
                        const std::complex<double> p = v[(l + d) % N], q = v[((l - d) % N + N) % N];
                        const double n = N, pr = p.real() / n, pi = p.imag() / n, Qr = q.real() / n,
                                     Qi = q.imag() / n, qr = q.real(), qi = q.imag();
                        const double er = (pr + Qr) + (pr * qr + pi * qi);
                        const double ei = sign * ((pi - Qi) + (pi * qr - pr * qi));
                        const double zr = x[e], zi = x[e + 1];
                        expected[e] = er * zr - ei * zi;
                        expected[e + 1] = er * zi + ei * zr;
                        // exp(t Lambda_l) = u_{l+d} conj(u_{l-d}), conjugated for sign = -1.
                        std::complex<double> exact = u[(l + d) % N] * std::conj(u[((l - d) % N + N) % N]);
                        if (sign < 0) exact = std::conj(exact);
                        const std::complex<double> reference =
                            (exact - 1.0) / n * std::complex<double>(zr, zi);
                        worst = std::max(
                            worst, std::abs(reference - std::complex<double>(expected[e], expected[e + 1])));
                    }
                apply_phase(N, d0, count, tables.data(), sign, x.data());
                assert_memory_equal(x.data(), expected.data(), sizeof(double) * x.size());
            }
        std::printf("N = %3d: phase to the bit; against exp(i phi) - 1: %.1e\n", N, worst);
        assert_true(worst < 1e-15);
    }
}

// Row runs: a direction's runs move each line d = 1 .. M once (run_line),
// the Row directions' runs are the LineBlocks, and the other directions have
// runs where their cycles of lines are long enough (L = N / gcd(k1, N) >=
// kMinRun). gather_run puts element s of line d = run_line(i) (the mode at
// d j + s k) at x[s * count + i], as gather_block does, so every line meets
// the transforms with the same values wherever it was read from, and
// scatter_run adds the increments there and writes the conjugates at the
// mirror modes, touching nothing else. Sizes with cycles L of 25 and 15
// (75), 35, 21 and 15 (105: General directions), 25 (125), and 15 and 5
// (135: Column blocks remain).
const int kRunSizes[] = {75, 105, 125, 135};

void test_row_runs_follow_the_lines(void **) {
    Random random{11};
    for (int N : kRunSizes) {
        const LineBlocks blocks(N);
        int streamed = 0, kept = 0;
        for (const Direction &D : projective_line(N)) {
            const std::vector<RowRun> runs = row_runs(D, N);
            if (runs.empty()) {
                ++kept;
                assert_true(N / std::gcd(D.k1, N) < kMinRun);
                continue;
            }
            if (D.k1 == 1) {
                assert_int_equal(runs.size(), blocks.count());
                for (int b = 0; b < blocks.count(); ++b) {
                    assert_int_equal(runs[b].row, 0);
                    assert_int_equal(runs[b].column, blocks.first_line(b));
                    assert_int_equal(runs[b].count, blocks.lines(b));
                }
            } else {
                ++streamed;
            }
            std::vector<char> line_seen(N, 0);
            const std::vector<double> w = hermitian_field(N, random);
            for (std::size_t r = 0; r < runs.size(); ++r) {
                const RowRun &run = runs[r];
                assert_true(run.count >= 1 && run.count <= kBlock);
                const int first_lane = static_cast<int>(r * N / runs.size());
                std::vector<double> x(2 * static_cast<std::size_t>(N) * run.count);
                gather_run(run, D.k2, N, first_lane, w.data(), x.data());
                Moves moves(w, x, N);
                for (int i = 0; i < run.count; ++i) {
                    const int d = run_line(D, run, i, N);
                    assert_true(d >= 1 && d <= blocks.M);
                    assert_int_equal(line_seen[d], 0);
                    line_seen[d] = 1;
                    moves.line(D, N, d, i, run.count, w, x, random);
                }
                std::vector<double> scattered = w;
                scatter_run(run, D.k2, N, first_lane, moves.increment.data(), scattered.data());
                assert_memory_equal(scattered.data(), moves.expected.data(), sizeof(double) * w.size());
            }
            int lines = 0;
            for (char seen : line_seen) lines += seen;
            assert_int_equal(lines, blocks.M);
        }
        std::printf("N = %3d: %3d directions in row runs besides the Row ones, %2d in Column or General "
                    "blocks\n",
                    N, streamed, kept);
        assert_true(streamed > 0);
    }
}

// apply_phase_lines gives line i what apply_phase gives line d = lines[i],
// for lines in any order: the same bits, from tables written in order of l.
void test_phase_lines_as_phase_rows(void **) {
    Random random{5};
    for (int N : kPhaseSizes) {
        const LineBlocks blocks(N);
        std::vector<double> spectrum(2 * static_cast<std::size_t>(N));
        for (double &b : spectrum) b = random.next();
        const double factor = 0.9;
        std::vector<double> mirrored(phase_table_doubles(N)), in_order(phase_table_doubles(N));
        for (int l = 0; l < N; ++l) {
            write_phase(N, l, factor, spectrum.data(), mirrored.data());
            write_phase(N, l, factor, spectrum.data(), in_order.data(), false);
        }
        for (double sign : {-1.0, 1.0})
            for (int b = 0; b < blocks.count(); ++b) {
                const int d0 = blocks.first_line(b), count = blocks.lines(b);
                std::vector<double> x(2 * static_cast<std::size_t>(N) * count);
                for (double &z : x) z = random.next();
                std::vector<double> expected = x;
                apply_phase(N, d0, count, mirrored.data(), sign, expected.data());
                // The block's lines taken one at a time, in reverse order.
                for (int i = 0; i < count; ++i) {
                    const int k = count - 1 - i, line = d0 + k;
                    std::vector<double> column(2 * static_cast<std::size_t>(N));
                    for (int l = 0; l < N; ++l) {
                        column[2 * l] = x[2 * (static_cast<std::size_t>(l) * count + k)];
                        column[2 * l + 1] = x[2 * (static_cast<std::size_t>(l) * count + k) + 1];
                    }
                    apply_phase_lines(N, &line, 1, in_order.data(), sign, column.data());
                    for (int l = 0; l < N; ++l) {
                        const std::size_t e = 2 * (static_cast<std::size_t>(l) * count + k);
                        assert_memory_equal(&column[2 * l], &expected[e], 2 * sizeof(double));
                    }
                }
                std::vector<int> reversed(count);
                std::vector<double> y(x.size());
                for (int i = 0; i < count; ++i) {
                    reversed[i] = d0 + count - 1 - i;
                    for (int l = 0; l < N; ++l)
                        for (int part = 0; part < 2; ++part)
                            y[2 * (static_cast<std::size_t>(l) * count + i) + part] =
                                x[2 * (static_cast<std::size_t>(l) * count + count - 1 - i) + part];
                }
                apply_phase_lines(N, reversed.data(), count, in_order.data(), sign, y.data());
                for (int i = 0; i < count; ++i)
                    for (int l = 0; l < N; ++l) {
                        const std::size_t row = static_cast<std::size_t>(l) * count;
                        assert_memory_equal(&y[2 * (row + i)], &expected[2 * (row + count - 1 - i)],
                                            2 * sizeof(double));
                    }
            }
        std::printf("N = %3d: line by line, in any order, the bits of apply_phase\n", N);
    }
}

}  // namespace

int main() {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gather_scatter_follow_the_lines),
        cmocka_unit_test(test_phase_is_the_complex_arithmetic),
        cmocka_unit_test(test_row_runs_follow_the_lines),
        cmocka_unit_test(test_phase_lines_as_phase_rows),
    };
    return lpi_run_tests(tests);
}
