// White-box: for prime and composite N, the pieces (directions of the
// projective line over Z_N) own every nonzero mode exactly once, so their
// energies sum to H; their number is N prod_{p | N} (1 + 1/p). Small N
// mode by mode, larger N (prime powers, large factors) by the sum.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "lpi_config.h"
#include "lpi_test.h"
#include "models/sine_euler.hpp"
#include "models/sine_euler/projective_line.hpp"

namespace {

const int kSizes[] = {3, 7, 9, 15, 25, 27, 45, 49};

#if LPI_HAVE_FFTW
lpi::sine_euler::Hamiltonian hamiltonian_of(const lpi::Model &model) {
    return static_cast<const lpi::SineEulerModel &>(model).hamiltonian();
}
#endif

#if LPI_HAVE_FFTW
std::size_t projective_line_size(int N) {
    double count = N;
    int n = N;
    for (int p = 2; p <= n; ++p)
        if (n % p == 0) {
            count *= 1.0 + 1.0 / p;
            while (n % p == 0) n /= p;
        }
    return static_cast<std::size_t>(std::lround(count));
}
#endif

void test_piece_count(void **) {
#if !LPI_HAVE_FFTW
    LPI_SKIP("built without FFTW: no sine-Euler model");
#else
    for (int N : kSizes) {
        auto model = lpi::make_sine_euler(N);
        assert_int_equal(model->piece_count(), projective_line_size(N));
    }
#endif
}

// Every nonzero mode alone: exactly one piece carries its energy.
void test_each_mode_has_one_owner(void **) {
#if !LPI_HAVE_FFTW
    LPI_SKIP("built without FFTW: no sine-Euler model");
#else
    for (int N : kSizes) {
        auto model = lpi::make_sine_euler(N);
        const auto line = lpi::sine_euler::projective_line(N);
        const auto H = hamiltonian_of(*model);
        std::vector<double> state(2 * N * N, 0.0);
        for (int i = 1; i < N * N; ++i) {
            const int a = i / N, b = i % N;
            const int minus = ((N - a) % N) * N + (N - b) % N;
            std::fill(state.begin(), state.end(), 0.0);
            state[2 * i] = 1.0;
            state[2 * minus] = 1.0;
            int owners = 0;
            for (std::size_t k = 0; k < model->piece_count(); ++k)
                owners += lpi::sine_euler::piece_energy(line.at(k), H, state.data()) != 0.0;
            if (owners != 1) fail_msg("N = %d, mode %d: %d pieces own it", N, i, owners);
        }
    }
#endif
}

// A full field: the pieces' energies sum to H.
void test_piece_energies_sum_to_h(void **) {
#if !LPI_HAVE_FFTW
    LPI_SKIP("built without FFTW: no sine-Euler model");
#else
    for (int N : kSizes) {
        auto model = lpi::make_sine_euler(N);
        const auto line = lpi::sine_euler::projective_line(N);
        std::vector<double> state(2 * N * N);
        unsigned seed = 1;
        for (int i = 0; i < 2 * N * N; ++i) {
            seed = seed * 1103515245u + 12345u;
            state[i] = (seed >> 8) / 16777216.0 - 0.5;
        }
        std::vector<double> x(N * N);
        model->to_public(state.data(), x.data());
        model->from_public(x.data(), state.data());  // make it Hermitian
        // Euler's H, then a general one: random symmetric lambda of both
        // signs and Hermitian f (the linear term of H).
        for (bool general : {false, true}) {
            if (general) {
                std::vector<double> lambda(N * N), f(2 * N * N), fx(N * N);
                for (int i = 0; i < N * N; ++i) {
                    const int a = i / N, b = i % N, minus = ((N - a) % N) * N + (N - b) % N;
                    lambda[i] = lambda[minus] = std::cos(3.0 * std::min(i, minus)) + 0.5;
                    seed = seed * 1103515245u + 12345u;
                    fx[i] = (seed >> 8) / 16777216.0 - 0.5;
                }
                model->from_public(fx.data(), f.data());  // Hermitian
                static_cast<lpi::SineEulerModel &>(*model).set_hamiltonian(lpi::sine_euler::Hamiltonian(
                    N, lambda.data(), lambda.size(), f.data(), f.size()));
            }
            double sum = 0.0, terms = 0.0;
            const auto hamiltonian = hamiltonian_of(*model);
            for (std::size_t k = 0; k < model->piece_count(); ++k) {
                const double piece = lpi::sine_euler::piece_energy(line.at(k), hamiltonian, state.data());
                sum += piece;
                terms += std::fabs(piece);
            }
            const double H = model->energy(state.data());
            std::printf("N = %2d, %s H: %3zu pieces, sum of piece energies - H = %.1e\n", N,
                        general ? "general" : "Euler's", model->piece_count(), sum - H);
            assert_true(std::fabs(sum - H) <= 1e-13 * terms);
            assert_true(H != 0.0);
        }
    }
    // Larger N, composite with large or repeated factors (4097 = 17 x 241):
    // every energy term |w_m|^2 / |m|^2 is set to a random value in [1/4, 1],
    // so a mode owned twice or by no piece moves the sum by at least 1/4.
    for (int N : {81, 121, 135, 147, 243, 343, 1155, 4097}) {
        auto model = lpi::make_sine_euler(N);
        const auto line = lpi::sine_euler::projective_line(N);
        assert_true(model->piece_count() == projective_line_size(N));
        std::vector<double> x(static_cast<std::size_t>(N) * N), state(2 * x.size());
        unsigned seed = 7;
        x[0] = 0.0;
        for (std::size_t i = 1; i < x.size(); i += 2) {
            seed = seed * 1103515245u + 12345u;
            const double angle = seed / 4294967296.0 * 6.283185307179586;
            seed = seed * 1103515245u + 12345u;
            const double amplitude = std::sqrt(0.25 + 0.75 * (seed / 4294967296.0));
            x[i] = amplitude * std::cos(angle);
            x[i + 1] = amplitude * std::sin(angle);
        }
        model->from_public(x.data(), state.data());
        // Scale each mode by |m| (representatives -M .. M).
        for (int a = 0; a < N; ++a)
            for (int b = 0; b < N; ++b) {
                const double ra = a > N / 2 ? a - N : a, rb = b > N / 2 ? b - N : b;
                const double norm = std::sqrt(ra * ra + rb * rb);
                state[2 * (static_cast<std::size_t>(a) * N + b)] *= norm;
                state[2 * (static_cast<std::size_t>(a) * N + b) + 1] *= norm;
            }
        double sum = 0.0;
        const auto hamiltonian = hamiltonian_of(*model);
        for (std::size_t k = 0; k < model->piece_count(); ++k) sum += lpi::sine_euler::piece_energy(line.at(k), hamiltonian, state.data());
        const double H = model->energy(state.data());
        assert_true(std::fabs(sum - H) < 0.1);
        assert_true(H > 0.25 * 0.5 * (static_cast<double>(N) * N - 1));
        std::printf("N = %4d: %4zu pieces, H = %.6g, sum of piece energies - H = %.1e\n", N,
                    model->piece_count(), H, sum - H);
    }
#endif
}

}  // namespace

int main() {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_piece_count),
        cmocka_unit_test(test_each_mode_has_one_owner),
        cmocka_unit_test(test_piece_energies_sum_to_h),
    };
    return lpi_run_tests(tests);
}
