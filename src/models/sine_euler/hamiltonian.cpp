// The quadratic-plus-linear Hamiltonians of sine-Euler (see the header).
#include "hamiltonian.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "../../core/error.hpp"
#include "../../core/system.hpp"
#include "indexing.hpp"

namespace lpi {
namespace sine_euler {

namespace {

std::size_t squared(int N) { return static_cast<std::size_t>(N) * static_cast<std::size_t>(N); }

std::string mode_name(std::size_t i, int N) {
    return "(" + std::to_string(i / static_cast<std::size_t>(N)) + ", " +
           std::to_string(i % static_cast<std::size_t>(N)) + ")";
}

// Every entry, the zero mode's too: ignored, they must still be numbers (a
// NaN there was taken silently).
void require_finite(const double *values, std::size_t n, std::size_t per_mode, const char *what,
                    int N) {
    for (std::size_t i = 0; i < n; ++i)
        if (!std::isfinite(values[i]))
            fail(LPI_ERR_NONFINITE, std::string(what) + " of mode " + mode_name(i / per_mode, N) +
                                        " at index " + std::to_string(i) + " is not finite");
}

double largest_magnitude(const double *values, std::size_t n) {
    double largest = 0.0;
    for (std::size_t i = 0; i < n; ++i) largest = std::max(largest, std::fabs(values[i]));
    return largest;
}

}  // namespace

double Hamiltonian::euler_weight(int a, int b, int N) {
    const double m2 = norm2(a, b, N);
    return m2 != 0 ? 1.0 / m2 : 0.0;
}

Hamiltonian::Hamiltonian(int N) : N_(N), lambda_(squared(N)) {
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b) lambda_[mode_index(a, b, N)] = euler_weight(a, b, N);
}

Hamiltonian::Hamiltonian(int N, const double *lambda, std::size_t n_lambda, const double *f,
                         std::size_t n_f)
    : N_(N) {
    const std::size_t modes = squared(N);
    if (!lambda) fail(LPI_ERR_NULL, "lambda is NULL");
    require_length("lambda", n_lambda, modes);
    if (f) {
        require_length("f", n_f, 2 * modes);
    } else if (n_f != 0) {
        fail(LPI_ERR_NULL, "f is NULL but n_f = " + std::to_string(n_f) + " (give NULL and 0 for f = 0)");
    }
    require_finite(lambda, modes, 1, "lambda", N);
    if (f) require_finite(f, 2 * modes, 2, "f", N);
    lambda_.assign(lambda, lambda + modes);
    lambda_[0] = 0.0;
    const double lambda_tolerance = 1e-10 * largest_magnitude(lambda_.data(), modes);
    bool forced = false;
    if (f) {
        forcing_.assign(f, f + 2 * modes);
        forcing_[0] = forcing_[1] = 0.0;
        forced = largest_magnitude(forcing_.data(), 2 * modes) != 0.0;
    }
    const double f_tolerance = forced ? 1e-10 * largest_magnitude(forcing_.data(), 2 * modes) : 0.0;
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b) {
            const std::size_t m = mode_index(a, b, N), minus = mirror_index(a, b, N);
            if (minus <= m) continue;
            if (std::fabs(lambda_[m] - lambda_[minus]) > lambda_tolerance) {
                char text[200];
                std::snprintf(text, sizeof text,
                              "lambda is not symmetric: lambda(%d,%d) = %.17g but lambda(%d,%d) = "
                              "%.17g (tolerance %.3g)",
                              a, b, lambda_[m], a ? N - a : 0, b ? N - b : 0, lambda_[minus],
                              lambda_tolerance);
                fail(LPI_ERR_INVALID, text);
            }
            lambda_[m] = lambda_[minus] = mirror_mean(lambda_[m], lambda_[minus]);
            if (!forced) continue;
            double *z = &forcing_[2 * m], *y = &forcing_[2 * minus];
            if (std::hypot(z[0] - y[0], z[1] + y[1]) > f_tolerance) {
                char text[256];
                std::snprintf(text, sizeof text,
                              "f is not Hermitian: f(%d,%d) = %.17g%+.17gi but f(%d,%d) = "
                              "%.17g%+.17gi is not its conjugate (tolerance %.3g)",
                              a, b, z[0], z[1], a ? N - a : 0, b ? N - b : 0, y[0], y[1],
                              f_tolerance);
                fail(LPI_ERR_INVALID, text);
            }
            z[0] = y[0] = mirror_mean(z[0], y[0]);
            z[1] = mirror_mean(z[1], -y[1]);
            y[1] = -z[1];
        }
    if (!forced) forcing_.clear();
}

bool Hamiltonian::is_default() const {
    return !forcing() && lambda_ == Hamiltonian(N_).lambda_;
}

double Hamiltonian::mode_energy(std::size_t index, const double *modes) const {
    const double *z = modes + 2 * index;
    double e = half_weighted_norm2(lambda_[index], z);
    if (const double *f = forcing()) e += f[2 * index] * z[0] + f[2 * index + 1] * z[1];
    return e;
}

double Hamiltonian::energy(const double *modes) const {
    double quadratic = 0.0, linear = 0.0;
    const std::size_t n = squared(N_);
    for (std::size_t i = 1; i < n; ++i) {
        const double *z = modes + 2 * i;
        // Halved term by term (the same bits as halving the sum): a sum
        // beyond DBL_MAX whose half is not is no overflow of the energy.
        quadratic += half_weighted_norm2(lambda_[i], z);
    }
    if (const double *f = forcing())
        for (std::size_t i = 2; i < 2 * n; ++i) linear += f[i] * modes[i];
    return quadratic + linear;
}

void Hamiltonian::stream_function(const double *modes, double *psi) const {
    const std::size_t n = squared(N_);
    const double *f = forcing();
    for (std::size_t i = 0; i < n; ++i)
        for (int part = 0; part < 2; ++part)
            psi[2 * i + part] = lambda_[i] * modes[2 * i + part] + (f ? f[2 * i + part] : 0.0);
}

std::vector<double> Hamiltonian::parameters() const {
    std::vector<double> p(lambda_);
    if (forcing_.empty())
        p.resize(3 * squared(N_), 0.0);
    else
        p.insert(p.end(), forcing_.begin(), forcing_.end());
    return p;
}

std::size_t shell_of(int a, int b, int N) {
    // k = floor(|n| + 1/2) = floor((floor(2 |n|) + 1) / 2), with floor(2|n|)
    // the integer square root of 4 |n|^2 (exact: |n|^2 < 2^53).
    const double four_m2 = 4.0 * norm2(a, b, N);
    auto root = static_cast<std::size_t>(std::sqrt(four_m2));
    while (static_cast<double>(root) * root > four_m2) --root;
    while (static_cast<double>(root + 1) * (root + 1) <= four_m2) ++root;
    return (root + 1) / 2;
}

std::size_t shell_count(int N) {
    const int M = (N - 1) / 2;
    return shell_of(M, M, N);
}

void shell_spectra(const Hamiltonian &H, const double *modes, double *energy, double *enstrophy) {
    const int N = H.truncation();
    const std::size_t shells = shell_count(N);
    std::fill(energy, energy + shells, 0.0);
    std::fill(enstrophy, enstrophy + shells, 0.0);
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b) {
            const std::size_t k = shell_of(a, b, N), i = mode_index(a, b, N);
            if (k == 0) continue;
            const double *z = modes + 2 * i;
            energy[k - 1] += H.mode_energy(i, modes);
            enstrophy[k - 1] += 0.5 * z[0] * z[0] + 0.5 * z[1] * z[1];
        }
}

}  // namespace sine_euler
}  // namespace lpi
