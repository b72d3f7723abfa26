// Modes <-> matrix transforms of sine-Euler by FFTW (see the header).
#include "matrix_form.hpp"

#include <mutex>

#include "../../core/error.hpp"
#include "../sine_euler.hpp"
#include "lpi_config.h"

#if LPI_HAVE_FFTW
#include <fftw3.h>

namespace lpi {
namespace sine_euler {

struct MatrixForm::Plans {
    fftw_plan forward = nullptr, backward = nullptr;
};

MatrixForm::MatrixForm(int N, Layout layout)
    : N_(N), index_(static_cast<std::size_t>(N) * N) {
    const std::size_t n = static_cast<std::size_t>(N);
    const std::size_t half = (n + 1) / 2;  // the inverse of 2 mod N (N odd)
    for (std::size_t m2 = 0; m2 < n; ++m2)
        for (std::size_t k = 0; k < n; ++k) {
            const std::size_t a = (k + n - m2) * half % n, b = (a + m2) % n;
            index_[m2 * n + k] = layout == ColumnMajor ? a + b * n : a * n + b;
        }
    require_fftw_headroom(fftw_planning_headroom(N),
                          "the matrix form's plans of length " + std::to_string(N));
    std::lock_guard<FftwPlannerLock> lock(fftw_planner_lock());
    plans_ = new Plans;
    fftw_complex *buffer = fftw_alloc_complex(index_.size());
    buffer_ = reinterpret_cast<cplx *>(buffer);
    if (!buffer) {
        release();
        fail(LPI_ERR_NO_MEMORY, "cannot allocate the matrix-form FFT buffer");
    }
    // N transforms of length N over the rows of the buffer (one per diagonal).
    plans_->forward = fftw_plan_many_dft(1, &N_, N_, buffer, nullptr, 1, N_, buffer, nullptr, 1, N_,
                                         FFTW_FORWARD, FFTW_ESTIMATE);
    plans_->backward = fftw_plan_many_dft(1, &N_, N_, buffer, nullptr, 1, N_, buffer, nullptr, 1, N_,
                                          FFTW_BACKWARD, FFTW_ESTIMATE);
    if (!plans_->forward || !plans_->backward) {
        release();
        fail(LPI_ERR_INTERNAL, "FFTW could not plan the matrix-form transforms");
    }
}

MatrixForm::~MatrixForm() {
    std::lock_guard<FftwPlannerLock> lock(fftw_planner_lock());
    release();
}

// Called with the planner lock held.
void MatrixForm::release() {
    if (plans_) {
        if (plans_->forward) fftw_destroy_plan(plans_->forward);
        if (plans_->backward) fftw_destroy_plan(plans_->backward);
        delete plans_;
        plans_ = nullptr;
    }
    if (buffer_) fftw_free(buffer_);
    buffer_ = nullptr;
}

void MatrixForm::to_matrix(const double *modes, cplx *W) {
    const std::size_t N = static_cast<std::size_t>(N_);
    const cplx *w = reinterpret_cast<const cplx *>(modes);
    for (std::size_t m1 = 0; m1 < N; ++m1)
        for (std::size_t m2 = 0; m2 < N; ++m2) buffer_[m2 * N + m1] = w[m1 * N + m2];
    fftw_execute(plans_->backward);
    scatter(W);
}

void MatrixForm::to_modes(const cplx *W, double *modes) {
    const std::size_t N = static_cast<std::size_t>(N_);
    gather(W);
    fftw_execute(plans_->forward);
    cplx *w = reinterpret_cast<cplx *>(modes);
    const double scale = 1.0 / N_;
    for (std::size_t m1 = 0; m1 < N; ++m1)
        for (std::size_t m2 = 0; m2 < N; ++m2) w[m1 * N + m2] = scale * buffer_[m2 * N + m1];
}

void MatrixForm::stream(const Hamiltonian &H, const cplx *W, cplx *P) {
    const std::size_t N = static_cast<std::size_t>(N_);
    gather(W);
    fftw_execute(plans_->forward);
    // The buffer holds N w_m at [m2 N + m1]; lambda_0 = f_0 = 0 drop the inert mode.
    const double *lambda = H.weights();
    const cplx *f = reinterpret_cast<const cplx *>(H.forcing());
    const double inverse_n = 1.0 / N_;
    for (std::size_t m2 = 0; m2 < N; ++m2)
        for (std::size_t m1 = 0; m1 < N; ++m1) {
            cplx &psi = buffer_[m2 * N + m1];
            psi *= lambda[m1 * N + m2] * inverse_n;
            if (f) psi += f[m1 * N + m2];
        }
    fftw_execute(plans_->backward);
    scatter(P);
}

void MatrixForm::gather(const cplx *W) {
    for (std::size_t i = 0; i < index_.size(); ++i) buffer_[i] = W[index_[i]];
}

void MatrixForm::scatter(cplx *W) const {
    for (std::size_t i = 0; i < index_.size(); ++i) W[index_[i]] = buffer_[i];
}

}  // namespace sine_euler
}  // namespace lpi

#endif  // LPI_HAVE_FFTW
