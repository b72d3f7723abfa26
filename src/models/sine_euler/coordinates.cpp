// Public coordinates, modes and grid of sine-Euler (see the header).
#include "coordinates.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "../../core/error.hpp"
#include "../../core/text.hpp"
#include "indexing.hpp"
#include "transforms.hpp"

namespace lpi {
namespace sine_euler {

namespace {

// Calls f(i, a, b) for the half-plane modes in public order, i = 0 .. (N^2-3)/2.
template <class F>
void for_half_plane(int N, F &&f) {
    const int M = (N - 1) / 2;
    std::size_t i = 0;
    for (int b = 1; b <= M; ++b) f(i++, 0, b);
    for (int a = 1; a <= M; ++a)
        for (int b = -M; b <= M; ++b) f(i++, a, modulo(b, N));
}

}  // namespace

void public_from_state(int N, const double *state, double *x) {
    x[0] = state[0];
    for_half_plane(N, [&](std::size_t i, int a, int b) {
        x[1 + 2 * i] = state[2 * mode_index(a, b, N)];
        x[2 + 2 * i] = state[2 * mode_index(a, b, N) + 1];
    });
}

void state_from_public(int N, const double *x, double *state) {
    const std::size_t dim = static_cast<std::size_t>(N) * N;
    for (std::size_t i = 0; i < dim; ++i)
        if (!std::isfinite(x[i]))
            fail(LPI_ERR_NONFINITE, "state entry " + std::to_string(i) + " is not finite");
    state[0] = x[0];
    state[1] = 0.0;
    for_half_plane(N, [&](std::size_t i, int a, int b) {
        const std::size_t m = mode_index(a, b, N), minus = mirror_index(a, b, N);
        state[2 * m] = x[1 + 2 * i];
        state[2 * m + 1] = x[2 + 2 * i];
        state[2 * minus] = x[1 + 2 * i];
        state[2 * minus + 1] = -x[2 + 2 * i];
    });
}

void public_from_modes(int N, const double *w, double *x) {
    const std::size_t size = 2 * static_cast<std::size_t>(N) * N;
    for (std::size_t i = 0; i < size; ++i)
        if (!std::isfinite(w[i]))
            fail(LPI_ERR_NONFINITE, "mode (" + std::to_string(i / 2 / N) + ", " +
                                        std::to_string(i / 2 % N) + ") at index " +
                                        std::to_string(i) + " is not finite");
    // 1e-10 max |w_m|, the moduli scaled first so that none overflows.
    double tolerance = 0.0;
    for (std::size_t i = 0; i < size; i += 2)
        tolerance = std::max(tolerance, std::hypot(1e-10 * w[i], 1e-10 * w[i + 1]));
    if (std::fabs(w[1]) > tolerance)
        fail(LPI_ERR_INVALID, "modes are not Hermitian: w(0,0) must be real, its imaginary part is " +
                                  number_text(w[1]) + " (tolerance " + number_text(tolerance, 3) + ")");
    x[0] = w[0];
    for_half_plane(N, [&](std::size_t i, int a, int b) {
        const std::size_t m = mode_index(a, b, N), minus = mirror_index(a, b, N);
        const double dr = w[2 * m] - w[2 * minus], di = w[2 * m + 1] + w[2 * minus + 1];
        if (std::hypot(dr, di) > tolerance) {
            char text[256];
            std::snprintf(text, sizeof text,
                          "modes are not Hermitian: w(%d,%d) = %.17g%+.17gi but w(%d,%d) = "
                          "%.17g%+.17gi is not its conjugate (tolerance %.3g)",
                          a, b, w[2 * m], w[2 * m + 1], a ? N - a : 0, b ? N - b : 0,
                          w[2 * minus], w[2 * minus + 1], tolerance);
            fail(LPI_ERR_INVALID, text);
        }
        x[1 + 2 * i] = mirror_mean(w[2 * m], w[2 * minus]);
        x[2 + 2 * i] = mirror_mean(w[2 * m + 1], -w[2 * minus + 1]);
    });
}

void public_from_grid(int N, const double *values, double *x) {
    const std::size_t n = static_cast<std::size_t>(N) * N;
    for (std::size_t i = 0; i < n; ++i)
        if (!std::isfinite(values[i]))
            fail(LPI_ERR_NONFINITE, "grid value (" + std::to_string(i / N) + ", " +
                                        std::to_string(i % N) + ") is not finite");
    std::vector<double> modes(2 * n);
    modes_from_grid(N, values, modes.data());
    // The grid was finite: a mode that is not has overflowed in the transform.
    for (std::size_t i = 0; i < 2 * n; ++i)
        if (!std::isfinite(modes[i]))
            fail(LPI_ERR_OVERFLOW, "the Fourier transform of this grid overflows a double at mode (" +
                                       std::to_string(i / 2 / N) + ", " +
                                       std::to_string(i / 2 % N) +
                                       "): the grid values are too large");
    modes[1] = 0.0;  // the mean of a real grid is real; drop its round-off
    public_from_modes(N, modes.data(), x);
}

}  // namespace sine_euler
}  // namespace lpi
