#include "fields.hpp"

#include <cmath>

#include "common.hpp"

namespace lpi_cli {

namespace {

// Representative of a mod N in -M..M.
int centred(int a, int N) { return a > N / 2 ? a - N : a; }

}  // namespace

std::vector<double> smooth_random_field(int N, double k0, std::uint64_t seed) {
    std::vector<double> w(2 * static_cast<std::size_t>(N) * N, 0.0);
    double norm = 0.0;
    for (int a = 0; a < N; ++a) {
        for (int b = 0; b < N; ++b) {
            const int m1 = centred(a, N), m2 = centred(b, N);
            // Draw each pair +-m once, from its member in the upper half plane.
            if (!(m1 > 0 || (m1 == 0 && m2 > 0))) continue;
            const double amplitude = std::exp(-(m1 * m1 + m2 * m2) / (2.0 * k0 * k0)) *
                                     (0.5 + uniform_random(seed));
            const double phase = 2.0 * kPi * uniform_random(seed);
            const std::size_t i = static_cast<std::size_t>(a) * N + b;
            const std::size_t j = static_cast<std::size_t>((N - a) % N) * N + (N - b) % N;
            w[2 * i] = amplitude * std::cos(phase);
            w[2 * i + 1] = amplitude * std::sin(phase);
            w[2 * j] = w[2 * i];
            w[2 * j + 1] = -w[2 * i + 1];
            norm += 2.0 * amplitude * amplitude;
        }
    }
    for (double &v : w) v /= std::sqrt(norm);
    return w;
}

std::vector<double> smooth_field(int N) { return smooth_random_field(N, 3.0, 7); }

std::vector<double> figure2_field() {
    const int N = 7;
    std::vector<double> w = smooth_random_field(N, 10.0, 1993);  // nearly flat spectrum
    // Split the half-plane norm and energy into |m| = 1 and the rest.
    double low_norm = 0.0, high_norm = 0.0, high_energy = 0.0;
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b) {
            const int n2 = centred(a, N) * centred(a, N) + centred(b, N) * centred(b, N);
            const std::size_t i = static_cast<std::size_t>(a) * N + b;
            const double p = 0.5 * (w[2 * i] * w[2 * i] + w[2 * i + 1] * w[2 * i + 1]);
            if (n2 == 1)
                low_norm += p;
            else if (n2 > 0)
                high_norm += p, high_energy += p / n2;
        }
    // H = 1/2 sum |w|^2/|m|^2 = (half plane) alpha^2 + beta^2 e_high with
    // alpha^2 + beta^2 = 1: solve for H = 0.75.
    const double e_high = high_energy / high_norm;
    const double alpha2 = (0.75 - e_high) / (1.0 - e_high);
    const double alpha = std::sqrt(alpha2 / low_norm), beta = std::sqrt((1.0 - alpha2) / high_norm);
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b) {
            const int n2 = centred(a, N) * centred(a, N) + centred(b, N) * centred(b, N);
            const std::size_t i = static_cast<std::size_t>(a) * N + b;
            const double f = n2 == 1 ? alpha : beta;
            w[2 * i] *= f;
            w[2 * i + 1] *= f;
        }
    return w;
}

std::vector<double> uniform_random_field(int N, unsigned seed, const std::function<bool(int, int)> &keep) {
    std::vector<double> w(2 * static_cast<std::size_t>(N) * N, 0.0);
    unsigned state = seed;
    auto draw = [&] {
        state = state * 1664525u + 1013904223u;
        return static_cast<double>(state >> 8) / 16777216.0 - 0.5;
    };
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b) {
            const int ma = (N - a) % N, mb = (N - b) % N;
            if (a * N + b >= ma * N + mb) continue;  // set each pair once
            if (!keep(centred(a, N), centred(b, N))) continue;
            const double re = draw(), im = draw();
            w[2 * (a * N + b)] = re, w[2 * (a * N + b) + 1] = im;
            w[2 * (ma * N + mb)] = re, w[2 * (ma * N + mb) + 1] = -im;
        }
    return w;
}

}  // namespace lpi_cli
