// The matrix form of sine-Euler (Zeitlin's su(N) basis): with q = exp(4 pi i/N),
// g = diag(q^a), h e_a = e_{a-1}, J_m = exp(2 pi i m1 m2 / N) g^m1 h^m2, the entry
// (a, b) of J_m is exp(2 pi i m1 (a + b) / N) when b - a = m2 (mod N), else 0.
// So W = sum_m w_m J_m has W_{a,a+m2} = sum_m1 w_(m1,m2) exp(2 pi i m1 (2a + m2) / N),
// and w_m = tr(W J_m^dagger) / N inverts it (the transforms are
// sine_euler::MatrixForm's, by FFT). Eq. 5 is dW/dt = (i/(2 eps)) [P, W] with
// P = sum_{n != 0} (lambda_n w_n + f_n) J_n (Euler: w_n / |n|^2). These serve diagnostics and the baseline
// methods, never the splitting's hot path; like the model, they need FFTW3.
#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "../core/lapack.hpp"
#include "lpi_config.h"
#include "sine_euler.hpp"
#include "sine_euler/indexing.hpp"
#include "sine_euler/matrix_form.hpp"

#if LPI_HAVE_FFTW

namespace lpi {

namespace {

using cplx = std::complex<double>;

// Entry (a, b) of an N x N array; a N + b overflows an int past N = 46340.
std::size_t at(int a, int b, int N) { return static_cast<std::size_t>(a) * N + b; }

// C = A B for N x N row-major complex matrices.
void multiply(int N, const cplx *A, const cplx *B, cplx *C) {
    std::fill(C, C + at(N, 0, N), cplx(0.0));
    for (int i = 0; i < N; ++i)
        for (int k = 0; k < N; ++k) {
            const cplx a = A[at(i, k, N)];
            const cplx *b = B + at(k, 0, N);
            cplx *c = C + at(i, 0, N);
            for (int j = 0; j < N; ++j) c[j] += a * b[j];
        }
}

}  // namespace

void sine_euler_matrix_vector_field(const sine_euler::Hamiltonian &H, const double *modes,
                                    double *rate) {
    const int N = H.truncation();
    const std::size_t n2 = static_cast<std::size_t>(N) * N;
    std::vector<cplx> W(n2), P(n2), PW(n2), WP(n2);
    sine_euler::MatrixForm form(N, sine_euler::MatrixForm::RowMajor);
    form.to_matrix(modes, W.data());
    form.stream(H, W.data(), P.data());
    multiply(N, P.data(), W.data(), PW.data());
    multiply(N, W.data(), P.data(), WP.data());
    const double eps = 2.0 * std::acos(-1.0) / N;
    const cplx factor(0.0, 1.0 / (2.0 * eps));
    for (std::size_t i = 0; i < n2; ++i) PW[i] = factor * (PW[i] - WP[i]);
    form.to_modes(PW.data(), rate);
    // Round-off leaves the two halves slightly unequal, and that difference
    // grows in an integrator (the field is not tangent to the Hermitian modes
    // off them). The mirror half is set to the exact conjugate, so a linear
    // combination with real coefficients (rk4, the midpoint rule) keeps a
    // Hermitian state Hermitian to the bit; w_0 (J_0 = I) is inert.
    cplx *r = reinterpret_cast<cplx *>(rate);
    r[0] = 0.0;
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b) {
            const std::size_t m = at(a, b, N), minus = sine_euler::mirror_index(a, b, N);
            if (minus < m) r[m] = std::conj(r[minus]);
        }
}

std::vector<double> sine_euler_traces(int N, const double *modes, int kmax) {
    const std::size_t n2 = static_cast<std::size_t>(N) * N;
    std::vector<cplx> W(n2), power(n2), next(n2);
    sine_euler::MatrixForm(N, sine_euler::MatrixForm::RowMajor).to_matrix(modes, W.data());
    power = W;
    std::vector<double> traces;
    for (int k = 1; k <= kmax; ++k) {
        if (k > 1) {
            multiply(N, power.data(), W.data(), next.data());
            power.swap(next);
        }
        if (std::all_of(power.begin(), power.end(), [](const cplx &z) { return z == 0.0; })) break;
        double trace = 0.0;
        for (int i = 0; i < N; ++i) trace += power[at(i, i, N)].real();
        if (!std::isfinite(trace)) {  // the sum overflows, the mean need not (W = w_0 I, w_0 = 1e308)
            trace = 0.0;
            for (int i = 0; i < N; ++i) trace += power[at(i, i, N)].real() / N;
            traces.push_back(trace);
            if (!std::isfinite(trace)) break;
        } else {
            traces.push_back(trace / N);
        }
    }
    return traces;
}

#if LPI_HAVE_LAPACK
void sine_euler_spectrum(int N, const double *modes, double *out) {
    // Row-major W is column-major W^T = conj(W): the same real spectrum.
    std::vector<cplx> W(static_cast<std::size_t>(N) * N);
    sine_euler::MatrixForm(N, sine_euler::MatrixForm::RowMajor).to_matrix(modes, W.data());
    // zheevd on a matrix holding Inf or NaN returns garbage or never ends.
    for (std::size_t i = 0; i < W.size(); ++i)
        if (!std::isfinite(W[i].real()) || !std::isfinite(W[i].imag()))
            fail(LPI_ERR_OVERFLOW, "the matrix W of this state overflows a double at entry (" +
                                       std::to_string(i / N) + ", " + std::to_string(i % N) +
                                       "): its spectrum cannot be computed");
    const char jobz = 'N', uplo = 'U';
    int info = 0, lwork = -1, lrwork = -1, liwork = -1, iwork_query = 0;
    cplx work_query;
    double rwork_query = 0.0;
    lapack::zheevd(&jobz, &uplo, &N, W.data(), &N, out, &work_query, &lwork, &rwork_query, &lrwork,
            &iwork_query, &liwork, &info, 1, 1);
    if (info != 0) fail(LPI_ERR_INTERNAL, "zheevd workspace query failed, info = " + std::to_string(info));
    lwork = static_cast<int>(work_query.real());
    lrwork = static_cast<int>(rwork_query);
    liwork = iwork_query;
    std::vector<cplx> work(std::max(lwork, 1));
    std::vector<double> rwork(std::max(lrwork, 1));
    std::vector<int> iwork(std::max(liwork, 1));
    lapack::zheevd(&jobz, &uplo, &N, W.data(), &N, out, work.data(), &lwork, rwork.data(), &lrwork,
            iwork.data(), &liwork, &info, 1, 1);
    if (info != 0) fail(LPI_ERR_INTERNAL, "zheevd failed to converge, info = " + std::to_string(info));
}
#else
void sine_euler_spectrum(int, const double *, double *) {
    fail(LPI_ERR_UNSUPPORTED,
         "the Casimir spectrum needs LAPACK (zheevd); this build has none "
         "(use lpi_sine_euler_casimir_traces)");
}
#endif

}  // namespace lpi

#endif  // LPI_HAVE_FFTW
