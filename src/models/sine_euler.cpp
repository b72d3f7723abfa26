// Sine-Euler (McLachlan 1993, section 3), with the faster line flow of the
// design notes. For a direction k, the piece H_k = 1/2 sum |w_sk|^2 / |sk|^2
// (over the modes it owns) leaves the line sigma_k = {s k} fixed and moves
// each parallel line {d j + s k}, c = (d j) x k, by the circulant system
// dz_p/dt = sum_n a_n z_{p-n}, a_n = -sin(eps n c) / (eps |nk|^2) w_nk.
// With b_n = w_nk / |nk|^2 and B_l = sum_n b_n exp(-2 pi i n l / N) (real, as
// b is Hermitian), the DFT eigenvalues on line c are
//     Lambda_l = (i / (2 eps)) (B_{l-c} - B_{l+c}),
// so exp(t Lambda_l) = u_{l-c} conj(u_{l+c}) with u_l = exp(i t B_l / (2 eps)).
// One FFT gives B; each line costs a forward and a backward FFT, and lines
// -c are the conjugates of lines c, so M = (N-1)/2 lines are integrated.
// Every flow is exactly unitary; what remains of the Casimir drift is FFTW's
// own round-trip norm bias (a property of each plan: measured -6e-17 per round
// trip at N = 31, -1e-16 at 61, +3.4e-16 at 127), accumulated over the
// (2P-2) M line round trips of a step.
#include "sine_euler.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numeric>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "lpi_config.h"

#if LPI_HAVE_FFTW
#include <fftw3.h>
#endif
#if LPI_HAVE_OPENMP
#include <omp.h>
#endif

namespace lpi {

std::mutex &fftw_planner_mutex() {
    static std::mutex mutex;
    return mutex;
}

#if !LPI_HAVE_FFTW

std::unique_ptr<Model> make_sine_euler(int) {
    fail(LPI_ERR_UNSUPPORTED, "sine-Euler needs FFTW3; this build has none "
                              "(configure with -DLPI_WITH_FFTW=ON and libfftw3-dev)");
}

#else

namespace {

// Lines of one direction are processed in blocks of this many. The block
// size is fixed (not derived from the thread count), so each block meets the
// same FFTW plan whichever thread runs it: results are identical to the bit
// for every thread count.
constexpr int kBlock = 16;

int gcd(int a, int b) { return std::gcd(a, b); }
int modulo(long a, int N) {
    const long r = a % N;
    return static_cast<int>(r < 0 ? r + N : r);
}
int rep(int a, int N) { return a > N / 2 ? a - N : a; }
// The inverse of a unit a mod N (setup only: a linear search is enough).
int inverse_mod(int a, int N) {
    int inverse = 1;
    while (modulo(static_cast<long>(inverse) * a, N) != 1) ++inverse;
    return inverse;
}

struct Direction {
    int k1, k2;  // the direction
    int j1 = 0, j2 = 0;  // offset between parallel lines: d j + s k, d = 1 .. M
    // Row: k = (1, k2), j = (0, 1): element s of line d is at row s, column
    //   s k2 + d, so a block's lines cross each row in one run.
    // Column: k = (k1, 1), j = (1, 0): row s k1 + d, column s (runs down the
    //   columns; all the other directions when N is a prime power).
    // General: any k, j with j x k = 1 (N with two or more prime factors).
    enum Layout { Row, Column, General } layout;
    // c = j x k of line d is sigma d: -d for Row directions, +d for the
    // others. With c = +-d, the phases of the lines of a block are read from
    // consecutive entries of u (see apply_phase).
    int sigma;
    std::vector<unsigned char> owned;  // owned[s]: this piece holds the energy of s k
};

// FFTW plans and aligned buffers, created on the first flow. Plan creation
// and destruction hold the planner lock.
struct Plans {
    fftw_plan b_forward = nullptr;
    fftw_plan forward[2] = {nullptr, nullptr};  // [0]: full block, [1]: remainder
    fftw_plan backward[2] = {nullptr, nullptr};
    fftw_complex *b = nullptr;     // N
    double *up = nullptr;    // 3N complex: up[i] = u_{i mod N}
    double *down = nullptr;  // 3N complex: down[i] = u_{-i mod N}
    std::vector<fftw_complex *> blocks;  // one N * kBlock buffer per thread

    ~Plans() {
        std::lock_guard<std::mutex> lock(fftw_planner_mutex());
        for (fftw_plan p : {b_forward, forward[0], forward[1], backward[0], backward[1]})
            if (p) fftw_destroy_plan(p);
        fftw_free(b);
        fftw_free(up);
        fftw_free(down);
        for (fftw_complex *x : blocks) fftw_free(x);
    }
};

// The hot loops are compiled twice on x86-64 with GCC, for AVX2 and for the
// baseline, and the loader picks one for the CPU (FFTW does the same for its
// own codelets). AVX2 without FMA: the same IEEE operations, the same bits.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && defined(__linux__) && \
    !defined(LPI_NO_SIMD_CLONES)
#define LPI_SIMD_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define LPI_SIMD_CLONES
#endif

// Multiplies the transformed block x (N rows of `count` lines) by the line
// flows exp(t Lambda_l) / N. Line i of the block (d = d0 + i) has c = sigma d,
// so its phase u_{l-c} conj(u_{l+c}) is e = u_{l+d} conj(u_{l-d}) for
// sigma = -1 and conj(e) for sigma = +1: `sign` = -sigma multiplies Im e, an
// exact negation. With up = &up[N + d0], down = &down[N + d0], u_{l+d} =
// up[l + i] and u_{l-d} = down[i - l]: both run forwards along a row of x,
// so the loop vectorises. Dividing by N, not multiplying by a rounded 1/N:
// t * fl(1/N) would scale every mode by the same N fl(1/N) != 1 in every flow,
// a drift of the Casimirs linear in time (measured: 3e-15 per step at N = 31,
// against 1.5e-15 with the division).
LPI_SIMD_CLONES
void apply_phase(int N, int count, const double *up, const double *down, double sign, double *x) {
    const double n_real = N;
    for (int l = 0; l < N; ++l) {
        double *z = x + 2 * l * count;
        const double *p = up + 2 * l;
        const double *q = down - 2 * l;
        for (int i = 0; i < count; ++i) {
            const double er = p[2 * i] * q[2 * i] + p[2 * i + 1] * q[2 * i + 1];
            const double ei = sign * (p[2 * i + 1] * q[2 * i] - p[2 * i] * q[2 * i + 1]);
            const double zr = z[2 * i], zi = z[2 * i + 1];
            z[2 * i] = (er * zr - ei * zi) / n_real;
            z[2 * i + 1] = (er * zi + ei * zr) / n_real;
        }
    }
}

// ---- moving a block of lines between the modes and a transform buffer -----
// A Row or Column direction's lines cross each lane (row s, or column s) in a
// run: element s of line d0 + i is at position (o + i) mod N of lane s, with
// o = s m + d0 (slope m = k2, or k1), and its conjugate mirror at position
// -(o + i) mod N of lane -s. Rows: lane s starts at s N and positions step by
// 1; columns: lane s starts at s and positions step by N.

// Count > 0: the block size, known at compile time (full blocks); 0: count.
template <bool Rows, int Count>
inline void gather_runs(int N, int slope, int d0, int count, int first_lane,
                        const double *__restrict w, double *__restrict x) {
    const std::size_t lane = Rows ? N : 1, step = Rows ? 1 : N;
    const int n = Count > 0 ? Count : count;
    int o = static_cast<int>((d0 + static_cast<long>(first_lane) * slope) % N);
    for (int k = 0, s = first_lane; k < N; ++k, s = s + 1 < N ? s + 1 : 0) {
        const double *src = w + 2 * lane * s;
        double *dst = x + 2 * s * n;
        const int first = o <= N - n ? n : N - o;  // the run wraps at most once
        for (int i = 0; i < first; ++i) {
            dst[2 * i] = src[2 * step * (o + i)];
            dst[2 * i + 1] = src[2 * step * (o + i) + 1];
        }
        for (int i = first; i < n; ++i) {
            dst[2 * i] = src[2 * step * (o + i - N)];
            dst[2 * i + 1] = src[2 * step * (o + i - N) + 1];
        }
        o += slope;
        if (o >= N) o -= N;
    }
}

// Writes n values at positions p0 .. p0+n-1 (p0 + n <= N) of a lane and their
// conjugates at positions -(p0 + r) mod N of the mirror lane.
inline void put_run(int N, std::size_t step, int p0, int n, const double *__restrict src, double *lane,
                    double *mirror) {
    if (n <= 0) return;
    for (int r = 0; r < n; ++r) {
        lane[2 * step * (p0 + r)] = src[2 * r];
        lane[2 * step * (p0 + r) + 1] = src[2 * r + 1];
    }
    int r0 = 0;
    if (p0 == 0) {  // position 0 is its own mirror position
        mirror[0] = src[0];
        mirror[1] = -src[1];
        r0 = 1;
    }
    // Upwards through the mirror lane: position N - p0 - r, r = n-1 .. r0.
    double *m = mirror + 2 * step * (N - p0 - (n - 1));
    const double *z = src + 2 * (n - 1);
    for (int q = 0; q < n - r0; ++q) {
        m[2 * step * q] = z[-2 * q];
        m[2 * step * q + 1] = -z[-2 * q + 1];
    }
}

template <bool Rows, int Count>
inline void scatter_runs(int N, int slope, int d0, int count, int first_lane,
                         const double *__restrict x, double *w) {
    const std::size_t lane = Rows ? N : 1, step = Rows ? 1 : N;
    const int n = Count > 0 ? Count : count;
    int o = static_cast<int>((d0 + static_cast<long>(first_lane) * slope) % N);
    for (int k = 0, s = first_lane; k < N; ++k, s = s + 1 < N ? s + 1 : 0) {
        const double *src = x + 2 * s * n;
        double *dst = w + 2 * lane * s, *mirror = w + 2 * lane * (s == 0 ? 0 : N - s);
        if (o >= 1 && o <= N - n) {  // most lanes: one run, away from position 0
            put_run(N, step, o, n, src, dst, mirror);
        } else {
            const int first = std::min(n, N - o);
            put_run(N, step, o, first, src, dst, mirror);
            put_run(N, step, 0, n - first, src + 2 * first, dst, mirror);
        }
        o += slope;
        if (o >= N) o -= N;
    }
}

// Any direction, one mode at a time: element s of line d0 + i is at
// (d0 + i) j + s k.
inline void gather_general(const Direction &D, int N, int d0, int count, const double *w, double *x) {
    int a0 = modulo(static_cast<long>(d0) * D.j1, N), b0 = modulo(static_cast<long>(d0) * D.j2, N);
    for (int s = 0; s < N; ++s) {
        int a = a0, b = b0;
        double *dst = x + 2 * s * count;
        for (int i = 0; i < count; ++i) {
            const double *src = w + 2 * (static_cast<std::size_t>(a) * N + b);
            dst[2 * i] = src[0];
            dst[2 * i + 1] = src[1];
            a += D.j1;
            if (a >= N) a -= N;
            b += D.j2;
            if (b >= N) b -= N;
        }
        a0 += D.k1;
        if (a0 >= N) a0 -= N;
        b0 += D.k2;
        if (b0 >= N) b0 -= N;
    }
}

inline void scatter_general(const Direction &D, int N, int d0, int count, const double *x, double *w) {
    int a0 = modulo(static_cast<long>(d0) * D.j1, N), b0 = modulo(static_cast<long>(d0) * D.j2, N);
    for (int s = 0; s < N; ++s) {
        int a = a0, b = b0;
        const double *src = x + 2 * s * count;
        for (int i = 0; i < count; ++i) {
            double *dst = w + 2 * (static_cast<std::size_t>(a) * N + b);
            dst[0] = src[2 * i];
            dst[1] = src[2 * i + 1];
            double *mirror = w + 2 * (static_cast<std::size_t>(a ? N - a : 0) * N + (b ? N - b : 0));
            mirror[0] = src[2 * i];
            mirror[1] = -src[2 * i + 1];
            a += D.j1;
            if (a >= N) a -= N;
            b += D.j2;
            if (b >= N) b -= N;
        }
        a0 += D.k1;
        if (a0 >= N) a0 -= N;
        b0 += D.k2;
        if (b0 >= N) b0 -= N;
    }
}

// These only move numbers (and negate): every clone gives the same bits.
LPI_SIMD_CLONES
void gather_block(const Direction &D, int N, int d0, int count, int first_lane, const double *w,
                  double *x) {
    switch (D.layout) {
        case Direction::Row:
            if (count == kBlock) gather_runs<true, kBlock>(N, D.k2, d0, count, first_lane, w, x);
            else gather_runs<true, 0>(N, D.k2, d0, count, first_lane, w, x);
            break;
        case Direction::Column:
            if (count == kBlock) gather_runs<false, kBlock>(N, D.k1, d0, count, first_lane, w, x);
            else gather_runs<false, 0>(N, D.k1, d0, count, first_lane, w, x);
            break;
        case Direction::General: gather_general(D, N, d0, count, w, x); break;
    }
}

LPI_SIMD_CLONES
void scatter_block(const Direction &D, int N, int d0, int count, int first_lane, const double *x,
                   double *w) {
    switch (D.layout) {
        case Direction::Row:
            if (count == kBlock) scatter_runs<true, kBlock>(N, D.k2, d0, count, first_lane, x, w);
            else scatter_runs<true, 0>(N, D.k2, d0, count, first_lane, x, w);
            break;
        case Direction::Column:
            if (count == kBlock) scatter_runs<false, kBlock>(N, D.k1, d0, count, first_lane, x, w);
            else scatter_runs<false, 0>(N, D.k1, d0, count, first_lane, x, w);
            break;
        case Direction::General: scatter_general(D, N, d0, count, x, w); break;
    }
}

class SineEuler final : public SineEulerModel {
public:
    explicit SineEuler(int N) : N_(N), M_((N - 1) / 2), eps_(2.0 * std::acos(-1.0) / N) {
        build_directions();
    }

    const char *kind() const override { return "sine-euler"; }
    int order() const override { return N_; }
    std::size_t dim() const override { return static_cast<std::size_t>(N_) * N_; }
    std::size_t state_size() const override { return 2 * dim(); }

    std::vector<std::string> split_names() const override { return split_.names(); }
    void set_split(const std::string &name) override { split_.select(name, kind()); }
    std::string split() const override { return split_.current(); }
    std::size_t piece_count() const override { return dirs_.size(); }
    // The thread count is a runtime setting (results are identical for every
    // count), so N is all a checkpoint needs.
    std::vector<double> checkpoint_parameters() const override { return {double(N_)}; }

    void set_threads(int n) override {
        if (n < 1) fail(LPI_ERR_INVALID, "thread count must be >= 1, got " + std::to_string(n));
#if !LPI_HAVE_OPENMP
        if (n > 1)
            fail(LPI_ERR_UNSUPPORTED, "threads need OpenMP; this build has none (one thread only)");
#endif
        threads_ = n;
    }

    void to_public(const double *state, double *x) const override;
    void from_public(const double *x, double *state) const override;
    void public_from_modes(const double *re_im, double *x) const override;
    void public_from_grid(const double *grid, double *x) const override;
    void grid(const double *state, double *out) const override;

    void flow(std::size_t piece, double t, double *state) override;

    double energy(const double *state) const override {
        double sum = 0.0;
        for (int a = 0; a < N_; ++a)
            for (int b = 0; b < N_; ++b) {
                const int norm2 = norm2_of(a, b);
                if (norm2 == 0) continue;
                const double *z = state + 2 * (a * N_ + b);
                sum += (z[0] * z[0] + z[1] * z[1]) / norm2;
            }
        return 0.5 * sum;
    }
    double piece_energy(std::size_t piece, const double *state) const override {
        const Direction &D = dirs_.at(piece);
        double sum = 0.0;
        for (int s = 1; s < N_; ++s) {
            if (!D.owned[s]) continue;
            const int a = modulo(static_cast<long>(s) * D.k1, N_);
            const int b = modulo(static_cast<long>(s) * D.k2, N_);
            const double *z = state + 2 * (a * N_ + b);
            sum += (z[0] * z[0] + z[1] * z[1]) / norm2_of(a, b);
        }
        return 0.5 * sum;
    }
    double enstrophy(const double *state) const override {
        double sum = 0.0;
        for (std::size_t i = 0; i < 2 * dim(); ++i) sum += state[i] * state[i];
        return 0.5 * sum;
    }
    std::size_t casimir_count() const override { return static_cast<std::size_t>(N_); }
    void casimirs(const double *state, double *out) const override {
        sine_euler_spectrum(N_, state, out);
    }
    void casimir_traces(const double *state, int kmax, double *out) const override {
        sine_euler_traces(N_, state, kmax, out);
    }
    void vector_field(const double *state, double *rate) const override {
        sine_euler_matrix_vector_field(N_, state, rate);
    }

    double run_fft_floor(std::size_t flows) override;

private:
    int norm2_of(int a, int b) const {
        const int ra = rep(a, N_), rb = rep(b, N_);
        return ra * ra + rb * rb;
    }
    int block_count() const { return (M_ + kBlock - 1) / kBlock; }
    void build_directions();
    void ensure_plans();
    bool line_spectrum(const Direction &D, const double *w);
    void line_phase(int l, double factor);
    void move_block(const Direction &D, int block, fftw_complex *X, double *w) const;

    int N_, M_;
    double eps_;
    std::vector<Direction> dirs_;
    SplitChoice split_{{"directions"}};
    int threads_ = 1;
    std::unique_ptr<Plans> plans_;
};

// The directions of the projective line over Z_N, in the paper's order for
// prime N ((0,1), then (1,m), m = 0..N-1), then, for composite N, the other
// classes in lexicographic order. A nonzero mode belongs to the first
// direction whose line through the origin contains it.
void SineEuler::build_directions() {
    const int N = N_;
    std::vector<unsigned char> seen(static_cast<std::size_t>(N) * N, 0);
    std::vector<int> owner(static_cast<std::size_t>(N) * N, -1);
    auto consider = [&](int k1, int k2) {
        if (gcd(gcd(k1, k2), N) != 1 || seen[k1 * N + k2]) return;
        // The class of k is first met as (1, m) when k1 is a unit; scale it
        // to k2 = 1 when k2 is a unit (the Column layout).
        if (gcd(k1, N) != 1 && gcd(k2, N) == 1) {
            k1 = modulo(static_cast<long>(k1) * inverse_mod(k2, N), N);
            k2 = 1;
        }
        Direction D;
        D.k1 = k1;
        D.k2 = k2;
        const int index = static_cast<int>(dirs_.size());
        D.owned.assign(N, 0);
        for (int s = 1; s < N; ++s) {
            const int a = modulo(static_cast<long>(s) * k1, N), b = modulo(static_cast<long>(s) * k2, N);
            if (gcd(s, N) == 1) seen[a * N + b] = 1;  // unit multiples: the same direction
            if (owner[a * N + b] < 0) {
                owner[a * N + b] = index;
                D.owned[s] = 1;
            }
        }
        // Lines d j + s k, d in Z_N, tile Z_N^2 when j x k is a unit.
        if (k1 == 1) {
            D.j1 = 0, D.j2 = 1, D.layout = Direction::Row, D.sigma = -1;  // j x k = -1
        } else if (k2 == 1) {
            D.j1 = 1, D.j2 = 0, D.layout = Direction::Column, D.sigma = 1;
        } else {
            D.layout = Direction::General, D.sigma = 1;
            int cross = 0;
            for (int x = 0; x < N && !cross; ++x)
                for (int y = 0; y < N && !cross; ++y) {
                    const int c = modulo(static_cast<long>(x) * k2 - static_cast<long>(y) * k1, N);
                    if (c != 0 && gcd(c, N) == 1) D.j1 = x, D.j2 = y, cross = c;
                }
            const int inverse = inverse_mod(cross, N);  // scale j so that j x k = 1
            D.j1 = modulo(static_cast<long>(D.j1) * inverse, N);
            D.j2 = modulo(static_cast<long>(D.j2) * inverse, N);
        }
        dirs_.push_back(std::move(D));
    };
    consider(0, 1);
    for (int m = 0; m < N; ++m) consider(1, m);
    for (int k1 = 0; k1 < N; ++k1)
        for (int k2 = 0; k2 < N; ++k2) consider(k1, k2);
}

void SineEuler::ensure_plans() {
    const std::size_t want = static_cast<std::size_t>(threads_);
    if (plans_ && plans_->blocks.size() >= want) return;
    const int N = N_;
    if (!plans_) {
        auto p = std::make_unique<Plans>();
        p->b = fftw_alloc_complex(N);
        p->up = static_cast<double *>(fftw_malloc(sizeof(double) * 6 * N));
        p->down = static_cast<double *>(fftw_malloc(sizeof(double) * 6 * N));
        if (!p->b || !p->up || !p->down) throw std::bad_alloc();
        std::vector<fftw_complex *> scratch(1, fftw_alloc_complex(static_cast<std::size_t>(N) * kBlock));
        if (!scratch[0]) throw std::bad_alloc();
        p->blocks.push_back(scratch[0]);
        {
            std::lock_guard<std::mutex> lock(fftw_planner_mutex());
            const unsigned flags = FFTW_MEASURE;
            p->b_forward = fftw_plan_dft_1d(N, p->b, p->b, FFTW_FORWARD, flags);
            const int sizes[2] = {M_ >= kBlock ? kBlock : 0, M_ % kBlock};
            for (int i = 0; i < 2; ++i) {
                const int howmany = sizes[i];
                if (howmany == 0) continue;
                // Transform along s (stride howmany); the lines of a block are
                // adjacent, as gathered from a row.
                p->forward[i] = fftw_plan_many_dft(1, &N, howmany, p->blocks[0], nullptr, howmany, 1,
                                                   p->blocks[0], nullptr, howmany, 1, FFTW_FORWARD, flags);
                p->backward[i] = fftw_plan_many_dft(1, &N, howmany, p->blocks[0], nullptr, howmany, 1,
                                                    p->blocks[0], nullptr, howmany, 1, FFTW_BACKWARD, flags);
                if (!p->forward[i] || !p->backward[i]) break;
            }
        }
        if (!p->b_forward || (M_ >= kBlock && !p->forward[0]) || (M_ % kBlock && !p->forward[1]))
            fail(LPI_ERR_INTERNAL, "FFTW could not create a plan for N = " + std::to_string(N));
        plans_ = std::move(p);
    }
    while (plans_->blocks.size() < want) {
        fftw_complex *x = fftw_alloc_complex(static_cast<std::size_t>(N) * kBlock);
        if (!x) throw std::bad_alloc();
        plans_->blocks.push_back(x);
    }
}

// b_s = w_sk / |sk|^2 on the owned modes, B = FFT(b) (real). Returns false
// when every b_s is zero.
bool SineEuler::line_spectrum(const Direction &D, const double *w) {
    const int N = N_;
    fftw_complex *b = plans_->b;
    int a = 0, c = 0;
    bool active = false;
    for (int s = 0; s < N; ++s) {
        if (D.owned[s]) {
            const double scale = 1.0 / norm2_of(a, c);
            b[s][0] = w[2 * (a * N + c)] * scale;
            b[s][1] = w[2 * (a * N + c) + 1] * scale;
            active = active || b[s][0] != 0.0 || b[s][1] != 0.0;
        } else {
            b[s][0] = b[s][1] = 0.0;
        }
        a += D.k1;
        if (a >= N) a -= N;
        c += D.k2;
        if (c >= N) c -= N;
    }
    if (!active) return false;
    fftw_execute_dft(plans_->b_forward, b, b);
    return true;
}

// u_l = exp(i t B_l / (2 eps)) with factor = t / (2 eps), stored three times
// over, forwards and backwards, so that u_{l-c} and u_{l+c} need no reduction
// mod N and run forwards along the lines of a block. Each l writes its own
// entries only, so threads may share the loop over l.
void SineEuler::line_phase(int l, double factor) {
    const int N = N_;
    double *up = plans_->up, *down = plans_->down;
    const double angle = factor * plans_->b[l][0];
    const double cs = std::cos(angle), sn = std::sin(angle);
    const int minus = l == 0 ? 0 : N - l;
    for (int copy = 0; copy < 3; ++copy) {
        up[2 * (l + copy * N)] = cs;
        up[2 * (l + copy * N) + 1] = sn;
        down[2 * (minus + copy * N)] = cs;
        down[2 * (minus + copy * N) + 1] = sn;
    }
}

// Lines d = d0 .. d0+count-1 of direction D: gather z_s = w_{d j + s k} into
// X[s * count + (d - d0)], transform along s, multiply by the line's
// exp(t Lambda_l) / N, transform back, scatter, and write the conjugates to
// the lines -d.
void SineEuler::move_block(const Direction &D, int block, fftw_complex *X, double *w) const {
    const int d0 = 1 + block * kBlock;
    const int count = std::min(kBlock, M_ - block * kBlock);
    const int plan = count == kBlock ? 0 : 1;
    double *x = &X[0][0];
    // Blocks start at different lanes, so that threads working on different
    // blocks are not in the same lane of w at the same moment (the lanes meet
    // at the blocks' edges, in shared cache lines). Every mode is written
    // once per flow, so the order changes no bit.
    const int first_lane = static_cast<int>(static_cast<long>(block) * N_ / block_count());
    gather_block(D, N_, d0, count, first_lane, w, x);
    fftw_execute_dft(plans_->forward[plan], X, X);
    apply_phase(N_, count, plans_->up + 2 * (N_ + d0), plans_->down + 2 * (N_ + d0), -D.sigma, x);
    fftw_execute_dft(plans_->backward[plan], X, X);
    scatter_block(D, N_, d0, count, first_lane, x, w);
}

void SineEuler::flow(std::size_t piece, double t, double *state) {
    ensure_plans();
    const Direction &D = dirs_[piece];
    // A piece whose modes are all zero has H_k = 0: its flow is the identity
    // (taken exactly, not through a round trip of FFTs).
    if (!line_spectrum(D, state)) return;
    const int blocks = block_count();
    const double factor = t / (2.0 * eps_);
    // One parallel region per flow: the phases, then the blocks of lines (the
    // implicit barrier between the two loops orders them).
#if LPI_HAVE_OPENMP
#pragma omp parallel num_threads(threads_) if (threads_ > 1 && blocks > 1)
#endif
    {
#if LPI_HAVE_OPENMP
#pragma omp for schedule(static)
#endif
        for (int l = 0; l < N_; ++l) line_phase(l, factor);
#if LPI_HAVE_OPENMP
#pragma omp for schedule(static)
#endif
        for (int blk = 0; blk < blocks; ++blk) {
#if LPI_HAVE_OPENMP
            fftw_complex *X = plans_->blocks[omp_get_thread_num()];
#else
            fftw_complex *X = plans_->blocks[0];
#endif
            move_block(D, blk, X, state);
        }
    }
}

double SineEuler::run_fft_floor(std::size_t flows) {
    ensure_plans();
    const int blocks = block_count();
    std::memset(plans_->b, 0, sizeof(fftw_complex) * N_);
    for (fftw_complex *x : plans_->blocks) std::memset(x, 0, sizeof(fftw_complex) * N_ * kBlock);
    for (std::size_t f = 0; f < flows; ++f) {
        fftw_execute_dft(plans_->b_forward, plans_->b, plans_->b);
#if LPI_HAVE_OPENMP
#pragma omp parallel for num_threads(threads_) schedule(static) if (threads_ > 1 && blocks > 1)
#endif
        for (int blk = 0; blk < blocks; ++blk) {
#if LPI_HAVE_OPENMP
            fftw_complex *X = plans_->blocks[omp_get_thread_num()];
#else
            fftw_complex *X = plans_->blocks[0];
#endif
            const int plan = std::min(kBlock, M_ - blk * kBlock) == kBlock ? 0 : 1;
            fftw_execute_dft(plans_->forward[plan], X, X);
            fftw_execute_dft(plans_->backward[plan], X, X);
        }
    }
    return static_cast<double>(flows) * (1.0 + 2.0 * M_);
}

// ---- public coordinates, modes and grid ------------------------------------

// Calls f(i, a, b) for the half-plane modes in public order, i = 0 .. (N^2-3)/2.
template <class F>
void for_half_plane(int N, F &&f) {
    const int M = (N - 1) / 2;
    int i = 0;
    for (int b = 1; b <= M; ++b) f(i++, 0, b);
    for (int a = 1; a <= M; ++a)
        for (int b = -M; b <= M; ++b) f(i++, a, modulo(b, N));
}

void SineEuler::to_public(const double *state, double *x) const {
    const int N = N_;
    x[0] = state[0];
    for_half_plane(N, [&](int i, int a, int b) {
        x[1 + 2 * i] = state[2 * (a * N + b)];
        x[2 + 2 * i] = state[2 * (a * N + b) + 1];
    });
}

void SineEuler::from_public(const double *x, double *state) const {
    const int N = N_;
    for (std::size_t i = 0; i < dim(); ++i)
        if (!std::isfinite(x[i]))
            fail(LPI_ERR_NONFINITE, "state entry " + std::to_string(i) + " is not finite");
    state[0] = x[0];
    state[1] = 0.0;
    for_half_plane(N, [&](int i, int a, int b) {
        const std::size_t m = a * N + b, minus = (a ? N - a : 0) * N + (b ? N - b : 0);
        state[2 * m] = x[1 + 2 * i];
        state[2 * m + 1] = x[2 + 2 * i];
        state[2 * minus] = x[1 + 2 * i];
        state[2 * minus + 1] = -x[2 + 2 * i];
    });
}

void SineEuler::public_from_modes(const double *w, double *x) const {
    const int N = N_;
    double largest = 0.0;
    for (std::size_t i = 0; i < 2 * dim(); ++i) {
        if (!std::isfinite(w[i]))
            fail(LPI_ERR_NONFINITE, "mode (" + std::to_string(i / 2 / N) + ", " +
                                        std::to_string(i / 2 % N) + ") at index " +
                                        std::to_string(i) + " is not finite");
        largest = std::max(largest, std::fabs(w[i]));
    }
    const double tolerance = 1e-10 * largest;
    if (std::fabs(w[1]) > tolerance)
        fail(LPI_ERR_INVALID, "modes are not Hermitian: w(0,0) must be real, its imaginary part is " +
                                  std::to_string(w[1]));
    x[0] = w[0];
    for_half_plane(N, [&](int i, int a, int b) {
        const std::size_t m = a * N + b, minus = (a ? N - a : 0) * N + (b ? N - b : 0);
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
        x[1 + 2 * i] = 0.5 * (w[2 * m] + w[2 * minus]);
        x[2 + 2 * i] = 0.5 * (w[2 * m + 1] - w[2 * minus + 1]);
    });
}

// grid[a*N+b] = sum_m w_m exp(2 pi i (m1 a + m2 b) / N): a 2D backward DFT.
void SineEuler::grid(const double *state, double *out) const {
    const std::size_t n = dim();
    fftw_complex *buffer = fftw_alloc_complex(n);
    if (!buffer) throw std::bad_alloc();
    fftw_plan plan;
    {
        std::lock_guard<std::mutex> lock(fftw_planner_mutex());
        plan = fftw_plan_dft_2d(N_, N_, buffer, buffer, FFTW_BACKWARD, FFTW_ESTIMATE);
    }
    std::memcpy(buffer, state, sizeof(fftw_complex) * n);
    fftw_execute(plan);
    for (std::size_t i = 0; i < n; ++i) out[i] = buffer[i][0];
    {
        std::lock_guard<std::mutex> lock(fftw_planner_mutex());
        fftw_destroy_plan(plan);
    }
    fftw_free(buffer);
}

void SineEuler::public_from_grid(const double *values, double *x) const {
    const std::size_t n = dim();
    for (std::size_t i = 0; i < n; ++i)
        if (!std::isfinite(values[i]))
            fail(LPI_ERR_NONFINITE, "grid value (" + std::to_string(i / N_) + ", " +
                                        std::to_string(i % N_) + ") is not finite");
    std::vector<double> modes(2 * n);
    fftw_complex *buffer = fftw_alloc_complex(n);
    if (!buffer) throw std::bad_alloc();
    fftw_plan plan;
    {
        std::lock_guard<std::mutex> lock(fftw_planner_mutex());
        plan = fftw_plan_dft_2d(N_, N_, buffer, buffer, FFTW_FORWARD, FFTW_ESTIMATE);
    }
    for (std::size_t i = 0; i < n; ++i) buffer[i][0] = values[i], buffer[i][1] = 0.0;
    fftw_execute(plan);
    const double scale = 1.0 / static_cast<double>(n);
    for (std::size_t i = 0; i < n; ++i) {
        modes[2 * i] = buffer[i][0] * scale;
        modes[2 * i + 1] = buffer[i][1] * scale;
    }
    {
        std::lock_guard<std::mutex> lock(fftw_planner_mutex());
        fftw_destroy_plan(plan);
    }
    fftw_free(buffer);
    modes[1] = 0.0;  // the mean of a real grid is real; drop its round-off
    public_from_modes(modes.data(), x);
}

}  // namespace

std::unique_ptr<Model> make_sine_euler(int N) {
    if (N < 3 || N % 2 == 0)
        fail(LPI_ERR_INVALID, "N must be odd and >= 3 (Zeitlin's su(N) truncation), got " +
                                  std::to_string(N));
    if (N > 46339)  // N^2 must fit an int index
        fail(LPI_ERR_INVALID, "N = " + std::to_string(N) + " is too large");
    return std::make_unique<SineEuler>(N);
}

#endif  // LPI_HAVE_FFTW

}  // namespace lpi
