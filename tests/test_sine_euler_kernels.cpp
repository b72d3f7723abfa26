// White-box: the hot loops of a sine-Euler line flow against independent
// computations. The flows keep one half of the modes (rows 1 .. M, row 0 up
// to column M) and leave the other out of date: gather_block reads element s
// of line d, at d j + s k, from that half (a mode outside it as its mirror's
// conjugate), whatever the other half holds; scatter_block adds the
// increments in that half, touching nothing else; and write_conjugate_half
// then gives the Hermitian field of the sums, for every direction (Row,
// Column and General layouts) and block, full and remainder; apply_phase multiplies by
// the written-out complex arithmetic of (e - 1) / N to the bit (the tables'
// layout and the two-at-a-time evaluation change no operation), and that is
// (exp(t Lambda_l) - 1) / N computed from the angles with std::polar. Both
// for the kernels this CPU runs (AVX2 where it has it) and for the baseline
// ones, which every other CPU runs. The transposed modes the flows of
// composite N keep (transpose_kept_half) hold every line where its
// transposed_view says, and a gather, scatter and transpose back there gives
// the bits of the same gather and scatter in the modes themselves.
#include <algorithm>
#include <complex>
#include <cstdint>
#include <cstdio>
#include <cstring>
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

// The half of the modes the flows keep, by index: rows 1 .. M, row 0 up to
// column M.
bool kept(std::size_t m, int N) {
    const std::size_t a = m / N, b = m % N, M = (N - 1) / 2;
    return (a >= 1 && a <= M) || (a == 0 && b <= M);
}

// w with the other half overwritten by numbers no flow may read or write.
std::vector<double> out_of_date(const std::vector<double> &w, int N, Random &random) {
    std::vector<double> stale = w;
    for (std::size_t m = 0; m < w.size() / 2; ++m)
        if (!kept(m, N)) stale[2 * m] = 10.0 + random.next(), stale[2 * m + 1] = 10.0 + random.next();
    return stale;
}

// The kernels this CPU runs, and the baseline ones.
struct Kernels {
    const char *name;
    decltype(&gather_block) gather;
    decltype(&scatter_block) scatter;
    decltype(&apply_phase) phase;
};
const Kernels kKernels[] = {{kernel_instruction_set(), gather_block, scatter_block, apply_phase},
                            {"baseline", baseline::gather_block, baseline::scatter_block, baseline::apply_phase}};

const int kGatherSizes[] = {15, 25, 35, 49, 75};

void test_gather_scatter_follow_the_lines(void **) {
    Random random{42};
    for (const Kernels &kernels : kKernels)
        for (int N : kGatherSizes) {
            const LineBlocks blocks(N);
            int layouts[3] = {0, 0, 0};
            for (const Direction &D : projective_line(N)) {
                ++layouts[D.layout];
                for (int b = 0; b < blocks.count(); ++b) {
                    const int d0 = blocks.first_line(b), count = blocks.lines(b);
                    const std::vector<double> w = hermitian_field(N, random), stale = out_of_date(w, N, random);
                    std::vector<double> x(2 * static_cast<std::size_t>(N) * count);
                    kernels.gather(D, N, d0, count, blocks.first_lane(b), stale.data(), x.data());
                    std::vector<double> increment(x.size()), expected = w;
                    std::vector<char> moved(static_cast<std::size_t>(N) * N, 0);
                    for (int s = 0; s < N; ++s)
                        for (int i = 0; i < count; ++i) {
                            const int d = d0 + i;
                            const std::size_t e = static_cast<std::size_t>(s) * count + i;
                            const std::size_t m = mode_at(d * D.j1 + s * D.k1, d * D.j2 + s * D.k2, N);
                            const std::size_t mirror =
                                mode_at(-(d * D.j1 + s * D.k1), -(d * D.j2 + s * D.k2), N);
                            assert_memory_equal(&x[2 * e], &w[2 * m], 2 * sizeof(double));
                            increment[2 * e] = random.next();
                            increment[2 * e + 1] = random.next();
                            expected[2 * m] = w[2 * m] + increment[2 * e];
                            expected[2 * m + 1] = w[2 * m + 1] + increment[2 * e + 1];
                            expected[2 * mirror] = expected[2 * m];
                            expected[2 * mirror + 1] = -expected[2 * m + 1];
                            assert_int_equal(moved[m] + moved[mirror], 0);  // each mode once
                            moved[m] = moved[mirror] = 1;
                        }
                    std::vector<double> scattered = stale, expected_kept = expected;
                    for (std::size_t m = 0; m < w.size() / 2; ++m)
                        if (!kept(m, N)) expected_kept[2 * m] = stale[2 * m], expected_kept[2 * m + 1] = stale[2 * m + 1];
                    kernels.scatter(D, N, d0, count, blocks.first_lane(b), increment.data(), scattered.data());
                    assert_memory_equal(scattered.data(), expected_kept.data(), sizeof(double) * w.size());
                    write_conjugate_half(N, scattered.data());
                    assert_memory_equal(scattered.data(), expected.data(), sizeof(double) * w.size());
                }
            }
            std::printf("%-8s N = %2d: %3d Row, %3d Column, %3d General directions, %d blocks each\n",
                        kernels.name, N, layouts[Direction::Row], layouts[Direction::Column],
                        layouts[Direction::General], blocks.count());
        }
}

// N = 105 has General directions whose j1 and j2 differ (k = (3, 10): j =
// (1, 2) / 4), where those of 15, 35 and 75 have j1 = j2.
const int kTransposedSizes[] = {15, 105};

void test_transposed_modes_hold_the_lines(void **) {
    Random random{3};
    for (const Kernels &kernels : kKernels)
        for (int N : kTransposedSizes) {
            const std::size_t doubles = 2 * static_cast<std::size_t>(N) * N;
            const LineBlocks blocks(N);
            for (const Direction &D : projective_line(N)) {
                const Direction view = transposed_view(D);
                for (int b = 0; b < blocks.count(); ++b) {
                    const int d0 = blocks.first_line(b), count = blocks.lines(b), lane = blocks.first_lane(b);
                    const std::vector<double> w = hermitian_field(N, random), stale = out_of_date(w, N, random);
                    // Its kept half from the modes' kept half alone, the rest
                    // of it left as it was (numbers no flow may read).
                    std::vector<double> t = out_of_date(w, N, random), t_stale = t;
                    transpose_kept_half(N, stale.data(), t.data());
                    for (std::size_t m = 0; m < doubles / 2; ++m) {
                        const std::size_t r = m / N, c = m % N, at = c * N + r;  // t's (r, c) is mode (c, r)
                        if (kept(m, N))
                            assert_memory_equal(&t[2 * m], &w[2 * at], 2 * sizeof(double));
                        else
                            assert_memory_equal(&t[2 * m], &t_stale[2 * m], 2 * sizeof(double));
                    }
                    std::vector<double> x(2 * static_cast<std::size_t>(N) * count), y(x.size());
                    kernels.gather(D, N, d0, count, lane, stale.data(), x.data());
                    kernels.gather(view, N, d0, count, lane, t.data(), y.data());
                    assert_memory_equal(x.data(), y.data(), sizeof(double) * x.size());
                    for (double &z : x) z = random.next();
                    std::vector<double> direct = stale, back = stale;
                    kernels.scatter(D, N, d0, count, lane, x.data(), direct.data());
                    kernels.scatter(view, N, d0, count, lane, x.data(), t.data());
                    transpose_kept_half(N, t.data(), back.data());
                    assert_memory_equal(direct.data(), back.data(), sizeof(double) * doubles);
                }
            }
        }
}

const int kPhaseSizes[] = {7, 35, 49, 125};

void test_phase_is_the_complex_arithmetic(void **) {
    Random random{7};
    for (const Kernels &kernels : kKernels)
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
                            const std::complex<double> computed(expected[e], expected[e + 1]);
                            worst = std::max(worst, std::abs(reference - computed));
                        }
                    kernels.phase(N, d0, count, tables.data(), sign, x.data());
                    assert_memory_equal(x.data(), expected.data(), sizeof(double) * x.size());
                }
            std::printf("%-8s N = %3d: phase to the bit; against exp(i phi) - 1: %.1e\n", kernels.name, N, worst);
            assert_true(worst < 1e-15);
        }
}

}  // namespace

int main() {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gather_scatter_follow_the_lines),
        cmocka_unit_test(test_phase_is_the_complex_arithmetic),
        cmocka_unit_test(test_transposed_modes_hold_the_lines),
    };
    return lpi_run_tests(tests);
}
