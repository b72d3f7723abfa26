// The sine-Euler model: McLachlan's splitting (1993, section 3) with one
// piece per direction of the projective line over Z_N, glued from the
// geometry (projective_line), the transforms, the kernels and the
// coordinates.
//
// The line flow. For a direction k, the piece
// H_k = sum (1/2 lambda_sk |w_sk|^2 + conj(f_sk) w_sk) over the modes it owns
// (Euler: lambda = 1/|n|^2, f = 0) leaves the line sigma_k = {s k} fixed (its
// modes commute with one another: sk x s'k = 0) and moves each parallel line
// {d j + s k}, c = (d j) x k, by the circulant system
// dz_p/dt = sum_n a_n z_{p-n}, a_n = -sin(eps n c) / eps b_n with the stream
// function b_n = dH_k/dw_{-nk} = lambda_nk w_nk + f_nk on the owned modes
// (eq. 5 restricted to the piece); b is constant under the piece's own flow,
// so the coefficients are. With
// B_l = sum_n b_n exp(-2 pi i n l / N) (real, as b is Hermitian), the DFT
// eigenvalues on line c are
//     Lambda_l = (i / (2 eps)) (B_{l-c} - B_{l+c}),
// so exp(t Lambda_l) = u_{l-c} conj(u_{l+c}) with u_l = exp(i t B_l / (2 eps)).
// One FFT gives B; each line costs a forward and a backward FFT, and lines
// -c are the conjugates of lines c, so M = (N-1)/2 lines are integrated.
// Every flow is exactly unitary, and it is applied as an increment,
//     z <- z + F^-1 ((exp(t Lambda) - 1) F z) / N,
// added to the modes as they are scattered back. Round-off then has no bias:
// an FFTW forward/backward pair rescales what it transforms by some 1 + tau
// (a property of each plan: measured -6e-17 per round trip at N = 31, -1e-16
// at 61, +3.4e-16 at 127), and applied to the whole line it rescaled every
// mode by 1 + tau in every flow, a drift of the Casimirs linear in time. On
// the increment D = (U - I) z it changes |z|^2 by 2 tau Re<z + D, D> =
// tau |D|^2 only (U unitary: 2 Re<z, D> = -|D|^2), second order in t Lambda;
// what remains is the rounding of the final sum z + D, to nearest, of either
// sign: the Casimirs wander like the square root of the number of steps. The
// factors exp(i phi) - 1 come from v_l = u_l - 1 = (-2 sin^2(phi_l/2),
// sin phi_l) without cancellation, so the increment's own rounding scales
// with the angles, not with the field.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "../../core/error.hpp"
#include "../sine_euler.hpp"
#include "coordinates.hpp"
#include "indexing.hpp"
#include "kernels.hpp"
#include "line_flows.hpp"
#include "lpi_config.h"
#include "projective_line.hpp"
#include "transforms.hpp"

#if defined(__has_include)
#if __has_include(<unistd.h>)
#include <unistd.h>
#endif
#endif

namespace lpi {

#if !LPI_HAVE_FFTW

std::unique_ptr<Model> make_sine_euler(int) {
    fail(LPI_ERR_UNSUPPORTED, "sine-Euler needs FFTW3; this build has none "
                              "(configure with -DLPI_WITH_FFTW=ON and libfftw3-dev)");
}

#else

namespace {

using namespace sine_euler;

class SineEuler final : public SineEulerModel {
public:
    explicit SineEuler(int N)
        : N_(N), blocks_(N), eps_(2.0 * std::acos(-1.0) / N), dirs_(projective_line(N)),
          hamiltonian_(N) {
        for (const Direction &D : dirs_) views_.push_back(transposed_view(D));
        if (std::any_of(dirs_.begin(), dirs_.end(),
                        [](const Direction &D) { return orientation(D) == Orientation::Transposed; }))
            transposed_modes_.resize(2 * static_cast<std::size_t>(N) * N);
    }

    const char *kind() const override { return "sine-euler"; }
    int truncation() const override { return N_; }
    std::size_t dim() const override { return static_cast<std::size_t>(N_) * N_; }
    std::size_t state_size() const override { return 2 * dim(); }

    std::vector<std::string> split_names() const override { return split_.names(); }
    void set_split(const std::string &name) override { split_.select(name, kind()); }
    std::string split() const override { return split_.current(); }
    std::size_t piece_count() const override { return dirs_.size(); }
    // The thread count is a runtime setting (results are identical for every
    // count): N, and lambda and f when they are not Euler's (so that the
    // checkpoints of Euler keep their bytes; sine_euler_checkpoint.cpp).
    std::vector<double> checkpoint_parameters() const override {
        std::vector<double> p{double(N_)};
        if (!hamiltonian_.is_default()) {
            const std::vector<double> lambda_f = hamiltonian_.parameters();
            p.insert(p.end(), lambda_f.begin(), lambda_f.end());
        }
        return p;
    }
    Hamiltonian hamiltonian() const override { return hamiltonian_; }
    void set_hamiltonian(Hamiltonian H) override {
        if (H.truncation() != N_)
            fail(LPI_ERR_INTERNAL, "a Hamiltonian of N = " + std::to_string(H.truncation()) +
                                       " given to a system of N = " + std::to_string(N_));
        hamiltonian_ = std::move(H);
    }

    void set_threads(int n) override {
        if (n < 1) fail(LPI_ERR_INVALID, "thread count must be >= 1, got " + std::to_string(n));
#if !LPI_HAVE_OPENMP
        if (n > 1)
            fail(LPI_ERR_UNSUPPORTED, "threads need OpenMP; this build has none (one thread only)");
#endif
        threads_ = n;
    }

    void to_public(const double *state, double *x) const override { public_from_state(N_, state, x); }
    void from_public(const double *x, double *state) const override { state_from_public(N_, x, state); }
    void public_from_modes(const double *modes, double *x) const override {
        sine_euler::public_from_modes(N_, modes, x);
    }
    void public_from_grid(const double *grid, double *x) const override {
        sine_euler::public_from_grid(N_, grid, x);
    }
    void grid(const double *state, double *out) const override { grid_from_modes(N_, state, out); }

    // Room for what FFTW's executions allocate (the plans are made by the
    // first flow, which a baseline method never calls). And the transposed
    // modes of a step that failed half-way are dropped: the state it started
    // from was restored.
    void prepare_step() override {
        require_fftw_execution_headroom(N_, threads_);
        transposed_ = false;
    }
    void flow(std::size_t piece, double t, double *state) override;
    void settle(double *state) override {
        oriented_modes(Orientation::Modes, state);
        write_conjugate_half(N_, state);
    }

    double energy(const double *state) const override { return hamiltonian_.energy(state); }
    double enstrophy(const double *state) const override {
        double sum = 0.0;
        // Halved term by term, as the energy (Hamiltonian::energy).
        for (std::size_t i = 0; i < 2 * dim(); ++i) sum += 0.5 * state[i] * state[i];
        return sum;
    }
    std::size_t casimir_count() const override { return static_cast<std::size_t>(N_); }
    void casimirs(const double *state, double *out) const override {
        sine_euler_spectrum(N_, state, out);
    }
    std::vector<double> casimir_traces(const double *state, int kmax) const override {
        return sine_euler_traces(N_, state, kmax);
    }
    void vector_field(const double *state, double *rate) const override {
        sine_euler_matrix_vector_field(hamiltonian_, state, rate);
    }

    TransformTiming time_transforms(std::size_t flows_per_step, std::int64_t steps) override;

    void set_planning(FftPlanning planning) override {
        auto planned = std::make_unique<LineTransforms>(N_, blocks_.M, planning);
        planned->reserve_threads(static_cast<std::size_t>(threads_));
        transforms_ = std::move(planned);
        planning_ = planning;
    }
    FftPlanning planning() const override { return planning_; }

private:
    // Column directions move their blocks fastest in the transposed modes
    // (orientation, projective_line.hpp). Composite N have many, and the
    // splitting meets all but (0,1) one after another (projective_line's
    // order: a leapfrog step runs them, and the General ones among them, as
    // one stretch). So the first of them transposes the kept half into
    // transposed_modes_, the flows stay there, Column and General alike,
    // and the next Row direction (or settle) transposes it back: two passes
    // over half the modes for a stretch of flows. Every value is copied or
    // conjugated exactly and every line keeps its elements' order: the same
    // bits. The modes the flows work on, state or transposed_modes_, moved
    // to where `wanted` says first.
    double *oriented_modes(Orientation wanted, double *state);
    LineTransforms &transforms();
    bool line_spectrum(const Direction &D, const double *w);

    int N_;
    LineBlocks blocks_;
    double eps_;
    std::vector<Direction> dirs_;
    std::vector<Direction> views_;           // dirs_ as the transposed modes hold their lines
    std::vector<double> transposed_modes_;  // the kept half, transposed (composite N only)
    bool transposed_ = false;               // whether the flows' modes are there now
    Hamiltonian hamiltonian_;
    SplitChoice split_{{"directions"}};
    int threads_ = 1;
    FftPlanning planning_ = FftPlanning::Estimate;
    std::unique_ptr<LineTransforms> transforms_;  // planned on the first flow
};

LineTransforms &SineEuler::transforms() {
    if (!transforms_) transforms_ = std::make_unique<LineTransforms>(N_, blocks_.M, planning_);
    transforms_->reserve_threads(static_cast<std::size_t>(threads_));
    return *transforms_;
}

// B = FFT(b) of D's line stream b (line_stream; real). Returns false when
// every b_s is zero.
bool SineEuler::line_spectrum(const Direction &D, const double *w) {
    if (!line_stream(D, hamiltonian_, w, transposed_, transforms_->spectrum())) return false;
    transforms_->transform_spectrum();
    return true;
}

double *SineEuler::oriented_modes(Orientation wanted, double *state) {
    if (wanted == Orientation::Transposed && !transposed_) {
        transpose_kept_half(N_, state, transposed_modes_.data());
        transposed_ = true;
    } else if (wanted == Orientation::Modes && transposed_) {
        transpose_kept_half(N_, transposed_modes_.data(), state);
        transposed_ = false;
    }
    return transposed_ ? transposed_modes_.data() : state;
}

void SineEuler::flow(std::size_t piece, double t, double *state) {
    transforms();
    const Direction &D = dirs_[piece];
    double *w = oriented_modes(orientation(D), state);
    const Direction &lines = transposed_ ? views_[piece] : D;
    // A piece whose stream function is zero on its line moves nothing: its flow is the identity
    // (taken exactly, not through a round trip of FFTs).
    if (!line_spectrum(D, w)) return;
    // Block b, lines d = d0 .. d0+count-1 of D: gather z_s = w_{d j + s k}
    // into x[s * count + (d - d0)], transform along s, multiply by the line's
    // (exp(t Lambda_l) - 1) / N, transform back, add the increments to the
    // modes, in the half of them the flows keep (kernels.hpp; settle writes
    // the other).
    run_line_flows(
        *transforms_, N_, blocks_.M, threads_, t / (2.0 * eps_),
        [&](int b, double *x) {
            gather_block(lines, N_, blocks_.first_line(b), blocks_.lines(b), blocks_.first_lane(b), w, x);
        },
        [&](int b, double *x) {
            flow_block(*transforms_, N_, blocks_.first_line(b), blocks_.lines(b), -D.sigma, x);
        },
        [&](int b, double *x) {
            scatter_block(lines, N_, blocks_.first_line(b), blocks_.lines(b), blocks_.first_lane(b), x, w);
        });
}

// The transforms of `flows_per_step * steps` flows alone, on the model's own
// plans, buffers and threads, on zeros: what the splitting costs in FFTW.
TransformTiming SineEuler::time_transforms(std::size_t flows_per_step, std::int64_t steps) {
    const std::size_t flows = flow_count(flows_per_step, steps);
    const double seconds = time_line_transforms(transforms(), N_, blocks_.M, threads_, flows);
    const double per_step = static_cast<double>(steps);
    return {seconds / per_step, static_cast<double>(flows) * (1.0 + 2.0 * blocks_.M) / per_step};
}

// a * b, or false when it does not fit a std::size_t.
bool checked_multiply(std::size_t a, std::size_t b, std::size_t &product) {
    if (b != 0 && a > SIZE_MAX / b) return false;
    product = a * b;
    return true;
}

// Bytes of physical memory, 0 when the system does not say.
std::size_t physical_memory() {
#if defined(_SC_PHYS_PAGES) && defined(_SC_PAGESIZE)
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    std::size_t bytes = 0;
    if (pages > 0 && page > 0 && checked_multiply(pages, page, bytes)) return bytes;
#endif
    return 0;
}

std::string gib(double bytes) {
    char text[64];
    std::snprintf(text, sizeof text, "%.3g GiB", bytes / (1024.0 * 1024.0 * 1024.0));
    return text;
}

// A sine-Euler system holds two working states of 2 N^2 doubles (the state
// and the copy a failed step rolls back to), for composite N a third (the
// flows' transposed modes), the N^2 doubles of lambda (the
// Hamiltonian's f, 2 N^2 more, is allocated when set), one byte per mode and direction
// to say which modes each piece owns, and for composite N one byte per mode
// while the directions are built. Refused before anything is allocated when
// that cannot be had: zero-filling vectors larger than the machine would
// bring the out-of-memory killer, not std::bad_alloc.
void require_memory(int N) {
    std::size_t classes = N;
    for (int p : prime_factors(N)) classes = classes / p * (static_cast<std::size_t>(p) + 1);
    const bool prime = classes == static_cast<std::size_t>(N) + 1;
    const std::size_t n = N;
    const std::size_t arrays = prime ? 2 : 3;  // of 2 N^2 doubles
    std::size_t modes = 0, states = 0, tables = 0, bytes = 0;
    const bool fits = checked_multiply(n, n, modes) &&
                      checked_multiply(modes, (arrays * 2 + 1) * sizeof(double), states) &&
                      checked_multiply(classes + (prime ? 0 : n), n, tables) &&
                      states <= SIZE_MAX - tables;
    const std::string what = "sine-Euler N = " + std::to_string(N) + " needs ";
    const std::string parts = std::string(" (") + (prime ? "two" : "three") +
                              " working states of 2 N^2 doubles, lambda and the direction tables)";
    if (!fits) {  // the same count in floating point, to say how far beyond
        const double estimate = (arrays * 2 + 1) * sizeof(double) * static_cast<double>(n) * static_cast<double>(n) +
                                static_cast<double>(classes + (prime ? 0 : n)) * static_cast<double>(n);
        char text[32];
        std::snprintf(text, sizeof text, "%.3g", estimate);
        fail(LPI_ERR_NO_MEMORY, what + "about " + text + " bytes (" + gib(estimate) + ")" + parts +
                                    ", more than an address space holds");
    }
    bytes = states + tables;
    require_physical_memory(static_cast<double>(bytes), what + std::to_string(bytes) + " bytes (" +
                                                            gib(static_cast<double>(bytes)) + ")" + parts);
}

}  // namespace

void require_physical_memory(double bytes, const std::string &what) {
    const std::size_t available = physical_memory();
    if (available != 0 && bytes > static_cast<double>(available))
        fail(LPI_ERR_NO_MEMORY, what + "; this machine has " + std::to_string(available) + " bytes (" +
                                    gib(static_cast<double>(available)) + ") of physical memory");
}

std::unique_ptr<Model> make_sine_euler(int N) {
    if (N < 3 || N % 2 == 0)
        fail(LPI_ERR_INVALID, "N must be odd and >= 3 (Zeitlin's su(N) truncation), got " +
                                  std::to_string(N));
    require_memory(N);
    return std::make_unique<SineEuler>(N);
}

#endif  // LPI_HAVE_FFTW

}  // namespace lpi
