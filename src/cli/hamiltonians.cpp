#include "hamiltonians.hpp"

#include <cmath>
#include <functional>
#include <vector>

#include "fields.hpp"
#include "systems.hpp"

namespace lpi_cli {

namespace {

// |n|^2 of mode (a, b) (representatives in -M..M), in the modes' FFT order.
double norm2(int a, int b, int N) {
    const double ra = a > N / 2 ? a - N : a, rb = b > N / 2 ? b - N : b;
    return ra * ra + rb * rb;
}

// lambda_n = weight(|n|^2) for n != 0 (the zero mode's entry is ignored).
template <class Weight>
std::vector<double> lambda_of(int N, Weight weight) {
    std::vector<double> lambda(static_cast<std::size_t>(N) * N, 0.0);
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b)
            if (a || b) lambda[static_cast<std::size_t>(a) * N + b] = weight(norm2(a, b, N));
    return lambda;
}

// The topography h's modes (sum |h_n|^2 = 1).
std::vector<double> topography_modes(int N) { return smooth_random_field(N, 2.0, 11); }

// The scenes' field with lambda_n = weight(|n|^2) and, with `topography`,
// over the smooth random topography h (f = -lambda h). lambda and f are made
// once the system exists: the library refuses an N too large for memory
// before lpi allocates N^2 of them.
Handle with_hamiltonian(int N, const std::function<double(double)> &weight, bool topography) {
    Handle h = sine_euler(N, smooth_field);
    const std::vector<double> lambda = lambda_of(N, weight);
    std::vector<double> f;
    if (topography) {
        f = topography_modes(N);
        for (std::size_t i = 0; i < lambda.size(); ++i) {
            f[2 * i] *= -lambda[i];
            f[2 * i + 1] *= -lambda[i];
        }
    }
    check(lpi_sine_euler_set_hamiltonian(h.get(), lambda.data(), lambda.size(), f.empty() ? nullptr : f.data(),
                                         f.size()),
          h.get(), "set Hamiltonian");
    return h;
}

}  // namespace

Handle sqg_system(int N) {
    return with_hamiltonian(N, [](double m2) { return 1.0 / std::sqrt(m2); }, false);
}

Handle qg_system(int N, double kd) {
    return with_hamiltonian(N, [kd](double m2) { return 1.0 / (m2 + kd * kd); }, false);
}

Handle topography_system(int N) {
    return with_hamiltonian(N, [](double m2) { return 1.0 / m2; }, true);
}

std::vector<double> topography_grid(int N) {
    Handle h = sine_euler(N, topography_modes);  // spread as the run's system is
    std::vector<double> grid(static_cast<std::size_t>(N) * N);
    check(lpi_sine_euler_get_grid(h.get(), grid.data(), grid.size()), h.get(), "topography grid");
    return grid;
}

}  // namespace lpi_cli
