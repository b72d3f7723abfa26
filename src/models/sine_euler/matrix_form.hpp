// The transforms between the sine-Euler modes and the matrix W = sum_m w_m J_m
// (J_m = exp(2 pi i m1 m2 / N) g^m1 h^m2, g = diag(q^a), q = exp(4 pi i / N),
// h e_a = e_{a-1}), and W -> P(W) = sum_{n != 0} (lambda_n w_n + f_n) J_n, the
// stream function of a Hamiltonian (hamiltonian.hpp; Euler: w_n / |n|^2).
// Entry (a, a + m2) of W is sum_m1 w_(m1,m2) exp(2 pi i m1 k / N) with
// k = 2a + m2 (mod N): each cyclic diagonal m2 of W, indexed by k, is a DFT of
// the modes with that m2. So modes <-> matrix is 2N FFTs of length N, and
// P(W) is, diagonal by diagonal, a DFT, psi = lambda w + f and a DFT back.
// Needs FFTW3 (as the sine-Euler model does).
#pragma once

#include <complex>
#include <cstddef>
#include <vector>

#include "hamiltonian.hpp"

namespace lpi {
namespace sine_euler {

class MatrixForm {
public:
    using cplx = std::complex<double>;
    enum Layout { RowMajor, ColumnMajor };
    MatrixForm(int N, Layout layout);
    ~MatrixForm();
    MatrixForm(const MatrixForm &) = delete;
    MatrixForm &operator=(const MatrixForm &) = delete;

    void to_matrix(const double *modes, cplx *W);
    void to_modes(const cplx *W, double *modes);
    // P = sum_{n != 0} (lambda_n w_n + f_n) J_n for W = sum_n w_n J_n.
    void stream(const Hamiltonian &H, const cplx *W, cplx *P);

private:
    void gather(const cplx *W);
    void scatter(cplx *W) const;
    void release();

    int N_;
    std::vector<std::size_t> index_;        // [m2 * N + k] -> entry (a, a + m2) of W
    struct Plans;
    Plans *plans_ = nullptr;
    cplx *buffer_ = nullptr;
};

}  // namespace sine_euler
}  // namespace lpi
