// Matrix-form baselines for sine-Euler (see the header).
//
// Conventions: W = sum_m w_m J_m is Hermitian,
// eq. 5 is dW/dt = [B, W] with B = i c P, c = 1/(2 eps), eps = 2 pi/N and
// P = sum_{n != 0} (lambda_n w_n + f_n) J_n, the stream function of the
// model's Hamiltonian (Hermitian, so B is anti-Hermitian), read from the
// model at each advance. The transforms are sine_euler::MatrixForm's.
// Matrices are stored column-major, as BLAS wants them.
#include "sine_euler_matrix_methods.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <optional>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "../core/lapack.hpp"
#include "../models/sine_euler.hpp"
#include "../models/sine_euler/matrix_form.hpp"
#include "fixed_point.hpp"
#include "runge_kutta4.hpp"
#include "lpi_config.h"

namespace lpi {

namespace {

using cplx = std::complex<double>;

// ---- direct-eq5: RK4 on the modes with eq. 5 summed term by term ------------

class DirectEq5 final : public Integrator {
public:
    explicit DirectEq5(int N)
        : N_(N), sine_(N), size_(2 * static_cast<std::size_t>(N) * N), psi_(size_), stages_(size_) {
        const double two_pi = 2.0 * std::acos(-1.0), eps = two_pi / N;
        // sin(eps m x n) depends on m x n only mod N.
        for (int j = 0; j < N; ++j) sine_[j] = std::sin(two_pi * j / N) / eps;
    }

    // The stages of rk4 on the modes, so the two agree to round-off.
    std::int64_t advance(Model &model, double *x, double dt, std::int64_t n,
                         StepsInProgress &progress) override {
        const sine_euler::Hamiltonian H = static_cast<const SineEulerModel &>(model).hamiltonian();
        auto rate = [this, &H](const double *y, double *k) { this->rate(H, y, k); };
        return run_checked_steps(
            n, progress, [&](std::int64_t) { stages_.step(x, dt, rate); },
            [&] { return all_finite(x, size_); });
    }

    std::size_t evaluations_per_step() const override { return 4; }

private:
    // dw_m/dt = sum_{n != 0} sin(eps m x n) / eps w_{m+n} psi_{-n}  (eq. 5),
    // psi = lambda w + f (Euler: psi_{-n} = w_{-n} / |n|^2). Summed for one
    // of each pair m, -m; the other is written as its conjugate, so that the
    // rate, and with it every RK4 stage, is exactly Hermitian. Summed for
    // both, the pair's round-off differs, and the field's imaginary part (in
    // grid space) grew at the flow's instability rate: 0.4 at t = 120.
    void rate(const sine_euler::Hamiltonian &H, const double *modes, double *out) {
        // int indices: N <= kDirectEq5MaxN, so none exceeds N^2 = 961, and
        // the remainders of this O(N^4) loop are cheaper in 32 bits.
        const int N = N_;
        H.stream_function(modes, psi_.data());
        const cplx *w = reinterpret_cast<const cplx *>(modes);
        const cplx *psi = reinterpret_cast<const cplx *>(psi_.data());
        cplx *r = reinterpret_cast<cplx *>(out);
        for (int m1 = 0; m1 < N; ++m1)
            for (int m2 = 0; m2 < N; ++m2) {
                const int mirror = ((N - m1) % N) * N + (N - m2) % N;
                if (mirror < m1 * N + m2) {
                    r[m1 * N + m2] = std::conj(r[mirror]);
                    continue;
                }
                cplx sum = 0.0;
                for (int n1 = 0; n1 < N; ++n1) {
                    const int row = (m1 + n1) % N, minus1 = (N - n1) % N;
                    // cross = m1 n2 - m2 n1 (mod N), advanced by m1 with n2.
                    int cross = (N - (m2 * n1) % N) % N;
                    for (int n2 = 0; n2 < N; ++n2) {
                        sum += sine_[cross] * w[row * N + (m2 + n2) % N] * psi[minus1 * N + (N - n2) % N];
                        cross += m1;
                        if (cross >= N) cross -= N;
                    }
                }
                r[m1 * N + m2] = sum;
            }
    }

    int N_;
    std::vector<double> sine_;
    std::size_t size_;
    std::vector<double> psi_;
    RungeKutta4Stages<double> stages_;
};

#if LPI_HAVE_FFTW && LPI_HAVE_LAPACK

// Keeps the mode array Hermitian (w_-m = conj(w_m)) after a matrix-form step,
// where round-off of the transforms breaks it slightly, and restores the
// inert mode w_0 exactly.
void symmetrise_modes(int order, const double *w0, double *modes) {
    const std::size_t N = static_cast<std::size_t>(order);
    cplx *w = reinterpret_cast<cplx *>(modes);
    for (std::size_t a = 0; a < N; ++a)
        for (std::size_t b = 0; b < N; ++b) {
            const std::size_t m = a * N + b, minus = ((N - a) % N) * N + (N - b) % N;
            if (minus <= m) continue;
            const cplx mean = 0.5 * (w[m] + std::conj(w[minus]));
            w[m] = mean;
            w[minus] = std::conj(mean);
        }
    modes[0] = w0[0];
    modes[1] = w0[1];
}

// C = A B for N x N column-major matrices.
void multiply(int N, const cplx *A, const cplx *B, cplx *C) {
    const char no = 'N';
    const cplx one = 1.0, zero = 0.0;
    lapack::zgemm(&no, &no, &N, &N, &N, &one, A, &N, B, &N, &zero, C, &N, 1, 1);
}

bool matrix_finite(const std::vector<cplx> &W) {
    return all_finite(reinterpret_cast<const double *>(W.data()), 2 * W.size());
}

// What both matrix-form methods share: the transforms, W, and the step
// between the mode array (the model's working layout) and W, done once per
// run so every step stays in matrix form.
class MatrixIntegrator : public Integrator {
public:
    std::int64_t advance(Model &model, double *state, double dt, std::int64_t n,
                         StepsInProgress &progress) override {
        return advance_through_run(model, state, dt, n, progress);
    }

    // W is kept across observations: the observer sees the modes of W, as a
    // run of that many steps leaves them, and the run goes on from W itself,
    // its step count running on, so observing changes no bit. (Running each
    // observed stretch as a run of its own rounded W through the modes at
    // every observation, and restarted isomp's first-step guess: 8e-13 in 100
    // steps.)
    RunOutcome run(Model &model, double *state, double dt, std::int64_t n, const StepObserver &observer,
                   StepsInProgress &progress) override {
        hamiltonian_.emplace(static_cast<const SineEulerModel &>(model).hamiltonian());
        begin_run();
        const double w0[2] = {state[0], state[1]};
        form_.to_matrix(state, W_.data());
        const std::int64_t chunk = observer.every > 0 ? observer.every : n;
        for (std::int64_t done = 0; done < n;) {
            const std::int64_t count = std::min(chunk, n - done);
            progress = {done + 1, done + count};
            const std::int64_t found = run_checked_steps(
                count, progress, [&](std::int64_t s) { step(dt, done + s); },
                [&] { return matrix_finite(W_); });
            done += count;
            end_stretch(done);
            if (found) return {RunOutcome::NonFinite, done - count + found};
            form_.to_modes(W_.data(), state);
            symmetrise_modes(N_, w0, state);
            if (!all_finite(state, 2 * size_)) return {RunOutcome::NonFinite, done};
            if (observer.every > 0 && done % observer.every == 0 && observer.observe(done))
                return {RunOutcome::Stopped, done};
        }
        return {RunOutcome::Done, n};
    }

protected:
    explicit MatrixIntegrator(int N)
        : N_(N), size_(static_cast<std::size_t>(N) * N), form_(N, sine_euler::MatrixForm::ColumnMajor), W_(size_), P_(size_),
          X_(size_), c_(N / (4.0 * std::acos(-1.0))) {}

    // One step of size dt on W_ (s: its index within the run).
    virtual void step(double dt, std::int64_t s) = 0;
    // Around a run: its start, and the steps done after each stretch.
    virtual void begin_run() {}
    virtual void end_stretch(std::int64_t) {}

    // Out = i c (X - X^dagger): the Hermitian [B, W] when X = P W, since
    // W P = (P W)^dagger for Hermitian P and W.
    void commutator(const cplx *X, cplx *out) const {
        const std::size_t N = static_cast<std::size_t>(N_);
        const cplx factor(0.0, c_);
        for (std::size_t j = 0; j < N; ++j)
            for (std::size_t i = 0; i < N; ++i)
                out[i + j * N] = factor * (X[i + j * N] - std::conj(X[j + i * N]));
    }

    int N_;
    std::size_t size_;
    sine_euler::MatrixForm form_;
    std::vector<cplx> W_, P_, X_;
    double c_;  // 1 / (2 eps) = N / (4 pi)
    std::optional<sine_euler::Hamiltonian> hamiltonian_;  // the model's, during a run
};

// Classical RK4 on dW/dt = [B(W), W]: one P(W) and one zgemm per stage.
class RungeKutta4Matrix final : public MatrixIntegrator {
public:
    explicit RungeKutta4Matrix(int N) : MatrixIntegrator(N), stages_(size_) {}

    std::size_t evaluations_per_step() const override { return 4; }

private:
    void rate(const cplx *W, cplx *out) {
        form_.stream(*hamiltonian_, W, P_.data());
        multiply(N_, P_.data(), W, X_.data());
        commutator(X_.data(), out);
    }

    void step(double dt, std::int64_t) override {
        stages_.step(W_.data(), dt, [this](const cplx *W, cplx *k) { rate(W, k); });
    }

    RungeKutta4Stages<cplx> stages_;
};

// The isospectral midpoint method for dW/dt = [B(W), W] (K. Modin and
// M. Viviani, "Lie-Poisson methods for isospectral flows", Found. Comput.
// Math. 20 (2020) 889; M. Viviani, "A minimal-variable symplectic method for
// isospectral flows", BIT 60 (2020) 741):
//   W_n     = (I - h/2 B(Wt)) Wt (I + h/2 B(Wt)),
//   W_{n+1} = (I + h/2 B(Wt)) Wt (I - h/2 B(Wt)).
// Expanding the first, Wt = W_n + h/2 [B, Wt] + h^2/4 B Wt B, solved by
// fixed-point iteration; subtracting, W_{n+1} = W_n + h [B, Wt]. W_{n+1} is
// then a Cayley-transform conjugate of W_n: isospectral up to the iteration's
// tolerance. Each iteration: one P(Wt), two zgemm (P Wt and P Wt P).
class IsospectralMidpoint final : public MatrixIntegrator {
public:
    IsospectralMidpoint(int N, ImplicitSettings settings)
        : MatrixIntegrator(N), settings_(settings), mid_(size_), next_(size_), C_(size_),
          Y_(size_) {}

    // P(W) evaluations (with two zgemm each) per step, averaged over the last run.
    std::size_t evaluations_per_step() const override {
        return static_cast<std::size_t>(std::ceil(std::max(1.0, average_iterations_)));
    }
    double average_iterations() const override { return average_iterations_; }
    void restore_average_iterations(double average) override { average_iterations_ = average; }

private:
    void begin_run() override { iterations_ = 0; }
    void end_stretch(std::int64_t steps) override {
        average_iterations_ = static_cast<double>(iterations_) / static_cast<double>(steps);
    }

    void step(double h, std::int64_t s) override {
        const int N = N_;
        cplx *W = W_.data(), *mid = mid_.data(), *next = next_.data();
        double largest = 0.0;
        for (std::size_t i = 0; i < size_; ++i)
            largest = std::max({largest, std::fabs(W[i].real()), std::fabs(W[i].imag())});
        // Start from the previous midpoint reflected through W_n (error
        // O(h^2), one iteration fewer than starting from W_n), except on the
        // first step of a run.
        if (s == 0)
            std::copy(W, W + size_, mid);
        else
            for (std::size_t i = 0; i < size_; ++i) mid[i] = 2.0 * W[i] - mid[i];
        // B Wt B = -c^2 P Wt P, symmetrised so Wt stays exactly Hermitian.
        const double quad = -0.25 * h * h * c_ * c_;
        const std::size_t n = static_cast<std::size_t>(N);
        // The iterate's products: h/2 times a commutator, quad times two
        // products of N terms.
        const FixedPointTest test(settings_, largest, (0.5 * std::fabs(h) + std::fabs(quad)) * N, "isomp");
        bool converged = false;
        for (int k = 0; k < settings_.max_iterations && !converged; ++k) {
            form_.stream(*hamiltonian_, mid, P_.data());
            multiply(N, P_.data(), mid, X_.data());
            multiply(N, X_.data(), P_.data(), Y_.data());
            commutator(X_.data(), C_.data());
            ++iterations_;
            double change = 0.0;
            for (std::size_t j = 0; j < n; ++j)
                for (std::size_t i = 0; i < n; ++i) {
                    const std::size_t e = i + j * n;
                    const cplx sym = 0.5 * (Y_[e] + std::conj(Y_[j + i * n]));
                    next[e] = W[e] + 0.5 * h * C_[e] + quad * sym;
                    const double d = std::max(std::fabs(next[e].real() - mid[e].real()),
                                              std::fabs(next[e].imag() - mid[e].imag()));
                    change = max_change(change, d);
                }
            converged = test.converged(change);
            std::swap(mid_, next_);
            mid = mid_.data();
            next = next_.data();
        }
        if (!converged) test.failed();
        // W_{n+1} = W_n + h [B(Wt), Wt] with the last iterate's commutator.
        for (std::size_t i = 0; i < size_; ++i) W[i] += h * C_[i];
    }

    ImplicitSettings settings_;
    std::vector<cplx> mid_, next_, C_, Y_;
    std::int64_t iterations_ = 0;
    double average_iterations_ = 0.0;
};

#endif  // LPI_HAVE_FFTW && LPI_HAVE_LAPACK

}  // namespace

namespace {

// The order N of the sine-Euler model, or LPI_ERR_UNSUPPORTED: these methods
// integrate sine-Euler (its matrix form, or eq. 5 summed term by term) and
// apply to no other system.
int sine_euler_order(const Method &method, const Model &model) {
    const auto *sine_euler = dynamic_cast<const SineEulerModel *>(&model);
    if (!sine_euler)
        refuse_system("method '" + method.name + "' integrates sine-Euler (" +
                      (method.name == "direct-eq5" ? "eq. 5 summed term by term" : "its matrix form") +
                      ") and applies to sine-Euler systems only (this system is " + model.kind() + ")");
    return sine_euler->truncation();
}

std::unique_ptr<Integrator> make_direct_eq5(const Method &method, const Model &model,
                                            const ImplicitSettings &) {
    const int N = sine_euler_order(method, model);
    if (N > kDirectEq5MaxN)
        refuse_system("method 'direct-eq5' sums eq. 5 term by term (O(N^4) per evaluation) as a "
                      "correctness check and accepts N <= " + std::to_string(kDirectEq5MaxN) +
                      " only, this system has N = " + std::to_string(N) +
                      " (use rk4, rk4-matrix or a splitting method)");
    return std::make_unique<DirectEq5>(N);
}

#if LPI_HAVE_FFTW && LPI_HAVE_LAPACK
std::unique_ptr<Integrator> make_isospectral_midpoint(const Method &method, const Model &model,
                                                      const ImplicitSettings &implicit) {
    return std::make_unique<IsospectralMidpoint>(sine_euler_order(method, model), implicit);
}

std::unique_ptr<Integrator> make_runge_kutta4_matrix(const Method &method, const Model &model,
                                                     const ImplicitSettings &) {
    return std::make_unique<RungeKutta4Matrix>(sine_euler_order(method, model));
}
#else
// This build lacks what the matrix form needs: refused for every system.
std::unique_ptr<Integrator> refuse_matrix_form(const Method &method, const Model &model,
                                               const ImplicitSettings &) {
    sine_euler_order(method, model);
    fail(LPI_ERR_UNSUPPORTED, "method '" + method.name + "' needs BLAS (zgemm, e.g. "
                              "OpenBLAS) and FFTW3; this build lacks " +
                              std::string(LPI_HAVE_LAPACK ? "FFTW3" : "BLAS/LAPACK"));
}
const IntegratorFactory make_isospectral_midpoint = refuse_matrix_form;
const IntegratorFactory make_runge_kutta4_matrix = refuse_matrix_form;
#endif

}  // namespace

std::vector<Method> sine_euler_matrix_methods() {
    // isomp is a Lie-Poisson integrator in exact arithmetic, but solved by
    // fixed-point iteration it keeps the Casimirs only to the iteration's
    // tolerance, not to round-off: a baseline here.
    return {
        baseline_method(
            "isomp", 2,
            "isospectral midpoint method on the matrix form of sine-Euler, fixed-point "
            "iteration, BLAS-3 (K. Modin and M. Viviani, Found. Comput. Math. 20 (2020) 889; "
            "M. Viviani, BIT Numer. Math. 60 (2020) 741); Casimirs kept to the iteration "
            "tolerance; sine-Euler only",
            make_isospectral_midpoint),
        baseline_method(
            "rk4-matrix", 4,
            "classical Runge-Kutta on the matrix form dW/dt = (i/(2 eps)) [P, W] of sine-Euler "
            "(V. Zeitlin, Physica D 49 (1991) 353), BLAS-3; not a Poisson map; sine-Euler only",
            make_runge_kutta4_matrix),
        baseline_method(
            "direct-eq5", 4,
            "classical Runge-Kutta on McLachlan 1993 eq. (5) summed term by term, O(N^4) per "
            "evaluation: a correctness check; sine-Euler with N <= 31 only",
            make_direct_eq5),
    };
}

}  // namespace lpi
