// The Hamiltonians of the sine-bracket family: every H quadratic and diagonal
// in the modes plus a linear term,
//     H(w) = 1/2 sum_{n != 0} lambda_n |w_n|^2 + sum_{n != 0} conj(f_n) w_n,
// lambda real and symmetric (lambda_{-n} = lambda_n), f Hermitian
// (f_{-n} = conj(f_n)), both in the modes' layout (entry [a N + b] is mode
// (a, b) mod N). The flow is dW/dt = (i / (2 eps)) [P, W] with the stream
// function P = sum_{n != 0} psi_n J_n, psi_n = dH/dw_{-n} = lambda_n w_n + f_n.
// Euler is lambda = 1/|n|^2, f = 0 (the default). The zero mode is inert
// (J_0 = I commutes with everything): its lambda_0 and f_0 are stored as 0.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

namespace lpi {
namespace sine_euler {

// 1/2 lambda |z|^2 of a mode z (re, im), as (lambda / 2) (re^2 + im^2); where
// |z|^2 overflows but the term need not (|z| > 1.3e154, lambda / 2 < 1),
// multiplied by lambda / 2 before the squares are added.
inline double half_weighted_norm2(double lambda, const double *z) {
    const double norm2 = z[0] * z[0] + z[1] * z[1];
    if (std::isfinite(norm2)) return 0.5 * lambda * norm2;
    return 0.5 * lambda * z[0] * z[0] + 0.5 * lambda * z[1] * z[1];
}

class Hamiltonian {
public:
    // Euler: lambda_n = 1/|n|^2 (computed as 1.0 / |n|^2), f = 0.
    explicit Hamiltonian(int N);
    // Euler's lambda of mode (a, b): 1.0 / |n|^2, 0 for the zero mode.
    static double euler_weight(int a, int b, int N);
    // Validates and stores lambda (n_lambda = N^2) and f (n_f = 2 N^2
    // interleaved re, im; or f = nullptr with n_f = 0). LPI_ERR_SIZE for a
    // wrong length, LPI_ERR_NONFINITE for an entry that is not finite,
    // LPI_ERR_INVALID for lambda not symmetric or f not Hermitian beyond
    // 1e-10 times the largest entry (within it, the mean of the pair is
    // stored). The zero mode's entries are ignored.
    Hamiltonian(int N, const double *lambda, std::size_t n_lambda, const double *f,
                std::size_t n_f);

    int truncation() const { return N_; }
    // lambda in the modes' layout (N^2 entries, lambda_0 = 0).
    const double *weights() const { return lambda_.data(); }
    // f interleaved (2 N^2 doubles, f_0 = 0), or nullptr when f = 0.
    const double *forcing() const { return forcing_.empty() ? nullptr : forcing_.data(); }
    // Whether this is Euler's Hamiltonian to the bit (a checkpoint then
    // stores N only).
    bool is_default() const;

    // The term of H that mode `index` (0 .. N^2-1) carries:
    // 1/2 lambda |w|^2 + Re(conj(f) w). Summed over n != 0, H.
    double mode_energy(std::size_t index, const double *modes) const;
    double energy(const double *modes) const;
    // psi_n = lambda_n w_n + f_n (2 N^2 doubles, psi_0 = 0).
    void stream_function(const double *modes, double *psi) const;

    // What a checkpoint stores after N: lambda (N^2), then f (2 N^2, zeros
    // when f = 0).
    std::vector<double> parameters() const;

private:
    int N_;
    std::vector<double> lambda_;
    std::vector<double> forcing_;  // empty when f = 0
};

// The shells of the spectra: mode n (representative in -M..M) lies in shell
// k = floor(|n| + 1/2), k = 1 .. shell_count(N) = floor(M sqrt(2) + 1/2).
std::size_t shell_of(int a, int b, int N);
std::size_t shell_count(int N);
// Shell sums of the energy (mode_energy: they add up to H) and of the
// enstrophy 1/2 |w_n|^2 (they add up to the enstrophy less 1/2 w_0^2):
// energy[k-1] and enstrophy[k-1] for k = 1 .. shell_count(N).
void shell_spectra(const Hamiltonian &H, const double *modes, double *energy, double *enstrophy);

}  // namespace sine_euler
}  // namespace lpi
