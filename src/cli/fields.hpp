// Initial vorticity fields for the sine-Euler scenes, as N x N complex modes
// in the library's FFT order (entry a*N + b holds mode (a, b) mod N).
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

namespace lpi_cli {

// A smooth field with random phases and amplitudes exp(-|m|^2 / (2 k0^2)),
// Hermitian (w_{-m} = conj w_m), w_0 = 0, scaled so that sum |w_m|^2 = 1.
std::vector<double> smooth_random_field(int N, double k0, std::uint64_t seed);

// The sine-Euler scenes' field: smooth_random_field(N, 3, 7).
std::vector<double> smooth_field(int N);

// The paper's Figure 2 field (N = 7): |w| = 1 over one mode of each pair +-m
// (sum over all modes = 2) and H(0) = 0.75 exactly, by mixing the |m| = 1
// modes of a random field with the others in the right proportion.
std::vector<double> figure2_field();

// A rough field for the stress cases: the modes m = (m1, m2) (centred, in
// -N/2..N/2) with keep(m1, m2) get real and imaginary parts uniform in
// [-0.5, 0.5) from a linear congruential generator seeded with `seed`,
// Hermitian, w_0 = 0; the others are 0.
std::vector<double> uniform_random_field(int N, unsigned seed, const std::function<bool(int, int)> &keep);

}  // namespace lpi_cli
