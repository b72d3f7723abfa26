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
#include "sine_euler.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdint>
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
#if defined(__has_include)
#if __has_include(<unistd.h>)
#include <unistd.h>
#endif
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

// Index arithmetic: a mode (a, b) is entry a N + b of N^2, beyond int for
// large N, so every offset into the mode array is a std::size_t; products of
// two residues are formed in 64 bits before they are reduced.
int modulo(std::int64_t a, int N) {
    const std::int64_t r = a % N;
    return static_cast<int>(r < 0 ? r + N : r);
}
int rep(int a, int N) { return a > N / 2 ? a - N : a; }
std::size_t mode_index(int a, int b, int N) { return static_cast<std::size_t>(a) * N + b; }
std::size_t mirror_index(int a, int b, int N) { return mode_index(a ? N - a : 0, b ? N - b : 0, N); }
// The inverse of a unit a mod N (extended Euclid).
int inverse_mod(int a, int N) {
    std::int64_t r0 = N, r1 = a, t0 = 0, t1 = 1;
    while (r1 != 0) {
        const std::int64_t q = r0 / r1;
        std::int64_t r = r0 - q * r1, t = t0 - q * t1;
        r0 = r1, r1 = r, t0 = t1, t1 = t;
    }
    return modulo(t0, N);  // r0 = gcd(a, N) = 1
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
    double *up = nullptr;    // 3N complex: up[i] = v_{i mod N}, v_l = u_l - 1
    double *down = nullptr;  // 3N complex: down[i] = v_{-i mod N}
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
// The line moves below are inlined into the cloned gather_block and
// scatter_block: a function they call instead would be compiled for the
// baseline only.
#if defined(__GNUC__)
#define LPI_INLINE inline __attribute__((always_inline))
#else
#define LPI_INLINE inline
#endif

// Multiplies the transformed block x (N rows of `count` lines) by the line
// flows' increments (exp(t Lambda_l) - 1) / N. Line i of the block
// (d = d0 + i) has c = sigma d, so exp(t Lambda_l) = u_{l-c} conj(u_{l+c}) is
// e = u_{l+d} conj(u_{l-d}) for sigma = -1 and conj(e) for sigma = +1: `sign`
// = -sigma multiplies Im e, an exact negation. With p = v_{l+d}, q = v_{l-d}
// (v = u - 1), e - 1 = p + conj(q) + p conj(q): no cancellation, each term as
// small as the angles. With up = &up[N + d0], down = &down[N + d0], v_{l+d} =
// up[l + i] and v_{l-d} = down[i - l]: both run forwards along a row of x, so
// the loop vectorises. Dividing by N, not multiplying by a rounded 1/N, which
// would scale every increment by the same N fl(1/N) != 1.
LPI_SIMD_CLONES
void apply_phase(int N, int count, const double *up, const double *down, double sign, double *x) {
    const double n_real = N;
    for (int l = 0; l < N; ++l) {
        double *z = x + 2 * static_cast<std::size_t>(l) * count;
        const double *p = up + 2 * l;
        const double *q = down - 2 * l;
        for (int i = 0; i < count; ++i) {
            const double pr = p[2 * i], pi = p[2 * i + 1], qr = q[2 * i], qi = q[2 * i + 1];
            const double er = (pr + qr) + (pr * qr + pi * qi);
            const double ei = sign * ((pi - qi) + (pi * qr - pr * qi));
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
// The gather copies the lines out; the scatter adds the increments computed
// from them back in place and writes the conjugates of the sums to the
// mirror lines -d (which no block gathers), so every mode is written once.

// Count > 0: the block size, known at compile time (full blocks); 0: count.
template <bool Rows, int Count>
LPI_INLINE void gather_runs(int N, int slope, int d0, int count, int first_lane,
                        const double *__restrict w, double *__restrict x) {
    const std::size_t lane = Rows ? N : 1, step = Rows ? 1 : N;
    const int n = Count > 0 ? Count : count;
    int o = modulo(d0 + static_cast<std::int64_t>(first_lane) * slope, N);
    for (int k = 0, s = first_lane; k < N; ++k, s = s + 1 < N ? s + 1 : 0) {
        const double *src = w + 2 * lane * s;
        double *dst = x + 2 * static_cast<std::size_t>(s) * n;
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

// Adds n increments to positions p0 .. p0+n-1 (p0 + n <= N) of a lane and
// writes the conjugates of the sums at positions -(p0 + r) mod N of the
// mirror lane.
LPI_INLINE void put_run(int N, std::size_t step, int p0, int n, const double *__restrict increment,
                        double *lane, double *mirror) {
    if (n <= 0) return;
    double *z = lane + 2 * step * p0;
    int r0 = 0;
    if (p0 == 0) {  // position 0 is its own mirror position
        z[0] += increment[0];
        z[1] += increment[1];
        mirror[0] = z[0];
        mirror[1] = -z[1];
        r0 = 1;
    }
    // Position p0 + r and its mirror N - p0 - r, in one pass.
    for (int r = r0; r < n; ++r) {
        const double re = z[2 * step * r] + increment[2 * r];
        const double im = z[2 * step * r + 1] + increment[2 * r + 1];
        double *m = mirror + 2 * step * (N - p0 - r);
        z[2 * step * r] = re;
        z[2 * step * r + 1] = im;
        m[0] = re;
        m[1] = -im;
    }
}

template <bool Rows, int Count>
LPI_INLINE void scatter_runs(int N, int slope, int d0, int count, int first_lane,
                         const double *__restrict x, double *w) {
    const std::size_t lane = Rows ? N : 1, step = Rows ? 1 : N;
    const int n = Count > 0 ? Count : count;
    int o = modulo(d0 + static_cast<std::int64_t>(first_lane) * slope, N);
    for (int k = 0, s = first_lane; k < N; ++k, s = s + 1 < N ? s + 1 : 0) {
        const double *src = x + 2 * static_cast<std::size_t>(s) * n;
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
LPI_INLINE void gather_general(const Direction &D, int N, int d0, int count, const double *w, double *x) {
    int a0 = modulo(static_cast<std::int64_t>(d0) * D.j1, N), b0 = modulo(static_cast<std::int64_t>(d0) * D.j2, N);
    for (int s = 0; s < N; ++s) {
        int a = a0, b = b0;
        double *dst = x + 2 * static_cast<std::size_t>(s) * count;
        for (int i = 0; i < count; ++i) {
            const double *src = w + 2 * mode_index(a, b, N);
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

LPI_INLINE void scatter_general(const Direction &D, int N, int d0, int count, const double *x, double *w) {
    int a0 = modulo(static_cast<std::int64_t>(d0) * D.j1, N), b0 = modulo(static_cast<std::int64_t>(d0) * D.j2, N);
    for (int s = 0; s < N; ++s) {
        int a = a0, b = b0;
        const double *src = x + 2 * static_cast<std::size_t>(s) * count;
        for (int i = 0; i < count; ++i) {
            double *dst = w + 2 * mode_index(a, b, N);
            dst[0] += src[2 * i];
            dst[1] += src[2 * i + 1];
            double *mirror = w + 2 * mirror_index(a, b, N);
            mirror[0] = dst[0];
            mirror[1] = -dst[1];
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

// These move numbers, negate and add one increment per mode: every clone
// gives the same bits.
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
                const double norm2 = norm2_of(a, b);
                if (norm2 == 0) continue;
                const double *z = state + 2 * mode_index(a, b, N_);
                sum += (z[0] * z[0] + z[1] * z[1]) / norm2;
            }
        return 0.5 * sum;
    }
    double piece_energy(std::size_t piece, const double *state) const override {
        const Direction &D = dirs_.at(piece);
        double sum = 0.0;
        for (int s = 1; s < N_; ++s) {
            if (!D.owned[s]) continue;
            const int a = modulo(static_cast<std::int64_t>(s) * D.k1, N_);
            const int b = modulo(static_cast<std::int64_t>(s) * D.k2, N_);
            const double *z = state + 2 * mode_index(a, b, N_);
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
    // |m|^2 of the representative, exact (an int would overflow past N = 65535).
    double norm2_of(int a, int b) const {
        const std::int64_t ra = rep(a, N_), rb = rep(b, N_);
        return static_cast<double>(ra * ra + rb * rb);
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

// The odd primes dividing N, by trial division.
std::vector<int> prime_factors(int N) {
    std::vector<int> primes;
    for (int p = 3; static_cast<std::int64_t>(p) * p <= N; p += 2)
        if (N % p == 0) {
            primes.push_back(p);
            while (N % p == 0) N /= p;
        }
    if (N > 1) primes.push_back(N);
    return primes;
}

// The directions of the projective line over Z_N, in the paper's order for
// prime N ((0,1), then (1,m), m = 0..N-1), then, for composite N, the other
// classes in lexicographic order. A nonzero mode belongs to the first
// direction whose line through the origin contains it.
// Setup is O(N^2) in sequential passes, by these facts (g(x) = gcd(x, N)):
// - a mode p lies on (0,1) when p1 = 0, else on (1,m) when p2 = p1 m, which
//   has a solution when g(p1) divides p2, the least m < N / g(p1); so (1,m)
//   owns s (the mode (s, s m)) when m < N / g(s), and (0,1) owns its line;
// - a class k with a non-unit k1 is met first at k1 = g(k1) (the least
//   residue of that gcd), so only rows k1 = g, the divisors 1 < g < N of N,
//   hold new classes; in row g, k2 and u k2 are one class for the units
//   u = 1 mod N/g;
// - on a later class's line, s k is owned there when s is a unit (a primitive
//   mode lies on its own class only); for a non-unit s, by (0,1) or (1,m) as
//   above, or, when neither, by the first later class met (one byte per
//   mode, for these modes only: N with a squared prime factor).
void SineEuler::build_directions() {
    const int N = N_;
    std::vector<int> gcd_with_n(N);
    for (int x = 0; x < N; ++x) gcd_with_n[x] = std::gcd(x, N);
    auto unit = [&](int x) { return gcd_with_n[x] == 1; };
    std::vector<unsigned char> claimed;  // modes owned by a later class, allocated when needed

    auto add = [&](int k1, int k2) {
        // A class met with a unit k2 is scaled to k2 = 1 (the Column layout).
        if (!unit(k1) && unit(k2)) {
            k1 = modulo(static_cast<std::int64_t>(k1) * inverse_mod(k2, N), N);
            k2 = 1;
        }
        Direction D;
        D.k1 = k1;
        D.k2 = k2;
        D.owned.assign(N, 0);
        if (k1 == 0) {  // (0,1), the first
            std::fill(D.owned.begin() + 1, D.owned.end(), 1);
        } else if (k1 == 1) {  // (1,m)
            for (int s = 1; s < N; ++s) D.owned[s] = k2 < N / gcd_with_n[s];
        } else {
            for (int s = 1, a = k1, b = k2; s < N; ++s) {  // (a, b) = s k
                if (unit(s)) {
                    D.owned[s] = 1;
                } else if (a != 0 && b % gcd_with_n[a] != 0) {
                    if (claimed.empty()) claimed.assign(dim(), 0);
                    unsigned char &owner = claimed[mode_index(a, b, N)];
                    D.owned[s] = !owner;
                    owner = 1;
                }
                a += k1;
                if (a >= N) a -= N;
                b += k2;
                if (b >= N) b -= N;
            }
        }
        // Lines d j + s k, d in Z_N, tile Z_N^2 when j x k is a unit.
        if (k1 == 1) {
            D.j1 = 0, D.j2 = 1, D.layout = Direction::Row, D.sigma = -1;  // j x k = -1
        } else if (k2 == 1) {
            D.j1 = 1, D.j2 = 0, D.layout = Direction::Column, D.sigma = 1;
        } else {
            // k1 and k2 are both non-units here. j = (1, y): for each prime p
            // of N, j x k = k2 - y k1 vanishes mod p for at most one y mod p,
            // so the first unit comes after a few y.
            D.layout = Direction::General, D.sigma = 1;
            int cross = 0;
            for (int y = 0; y < N && !cross; ++y) {
                const int c = modulo(k2 - static_cast<std::int64_t>(y) * k1, N);
                if (unit(c)) D.j1 = 1, D.j2 = y, cross = c;
            }
            const int inverse = inverse_mod(cross, N);  // scale j so that j x k = 1
            D.j1 = modulo(static_cast<std::int64_t>(D.j1) * inverse, N);
            D.j2 = modulo(static_cast<std::int64_t>(D.j2) * inverse, N);
        }
        dirs_.push_back(std::move(D));
    };
    add(0, 1);
    for (int m = 0; m < N; ++m) add(1, m);
    std::vector<unsigned char> seen(N);  // row g: k2 whose class was met
    for (int g = 3; g < N; g += 2) {
        if (N % g != 0) continue;
        std::fill(seen.begin(), seen.end(), 0);
        for (int k2 = 0; k2 < N; ++k2) {
            if (seen[k2] || std::gcd(gcd_with_n[g], gcd_with_n[k2]) != 1) continue;  // met, or not primitive
            for (int u = 1; u < N; u += N / g)  // the units u = 1 mod N/g
                if (unit(u)) seen[modulo(static_cast<std::int64_t>(u) * k2, N)] = 1;
            add(g, k2);
        }
    }
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
            b[s][0] = w[2 * mode_index(a, c, N)] * scale;
            b[s][1] = w[2 * mode_index(a, c, N) + 1] * scale;
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

// v_l = u_l - 1 = exp(i phi_l) - 1 = (-2 sin^2(phi_l / 2), sin phi_l), phi_l =
// factor B_l with factor = t / (2 eps), stored three times over, forwards and
// backwards, so that v_{l-c} and v_{l+c} need no reduction mod N and run
// forwards along the lines of a block. Each l writes its own entries only, so
// threads may share the loop over l.
void SineEuler::line_phase(int l, double factor) {
    const std::size_t N = N_;
    double *up = plans_->up, *down = plans_->down;
    // One sincos of the half angle: sin phi = 2 sin(phi/2) cos(phi/2).
    const double half = 0.5 * factor * plans_->b[l][0];
    const double sh = std::sin(half), ch = std::cos(half);
    const double re = -2.0 * sh * sh, im = 2.0 * sh * ch;
    const std::size_t minus = l == 0 ? 0 : N - l;
    for (std::size_t copy = 0; copy < 3; ++copy) {
        up[2 * (l + copy * N)] = re;
        up[2 * (l + copy * N) + 1] = im;
        down[2 * (minus + copy * N)] = re;
        down[2 * (minus + copy * N) + 1] = im;
    }
}

// Lines d = d0 .. d0+count-1 of direction D: gather z_s = w_{d j + s k} into
// X[s * count + (d - d0)], transform along s, multiply by the line's
// (exp(t Lambda_l) - 1) / N, transform back, add the increments to the modes
// and write the conjugates of the sums to the lines -d.
void SineEuler::move_block(const Direction &D, int block, fftw_complex *X, double *w) const {
    const int d0 = 1 + block * kBlock;
    const int count = std::min(kBlock, M_ - block * kBlock);
    const int plan = count == kBlock ? 0 : 1;
    double *x = &X[0][0];
    // Blocks start at different lanes, so that threads working on different
    // blocks are not in the same lane of w at the same moment (the lanes meet
    // at the blocks' edges, in shared cache lines). Every mode is written
    // once per flow, so the order changes no bit.
    const int first_lane = static_cast<int>(static_cast<std::int64_t>(block) * N_ / block_count());
    gather_block(D, N_, d0, count, first_lane, w, x);
    fftw_execute_dft(plans_->forward[plan], X, X);
    const std::size_t phase0 = 2 * (static_cast<std::size_t>(N_) + d0);
    apply_phase(N_, count, plans_->up + phase0, plans_->down + phase0, -D.sigma, x);
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
    std::size_t i = 0;
    for (int b = 1; b <= M; ++b) f(i++, 0, b);
    for (int a = 1; a <= M; ++a)
        for (int b = -M; b <= M; ++b) f(i++, a, modulo(b, N));
}

void SineEuler::to_public(const double *state, double *x) const {
    const int N = N_;
    x[0] = state[0];
    for_half_plane(N, [&](std::size_t i, int a, int b) {
        x[1 + 2 * i] = state[2 * mode_index(a, b, N)];
        x[2 + 2 * i] = state[2 * mode_index(a, b, N) + 1];
    });
}

void SineEuler::from_public(const double *x, double *state) const {
    const int N = N_;
    for (std::size_t i = 0; i < dim(); ++i)
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

namespace {

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
// and the copy a failed step rolls back to), one byte per mode and direction
// to say which modes each piece owns, and for composite N one byte per mode
// while the directions are built. Refused before anything is allocated when
// that cannot be had: zero-filling vectors larger than the machine would
// bring the out-of-memory killer, not std::bad_alloc.
void require_memory(int N) {
    std::size_t classes = N;
    for (int p : prime_factors(N)) classes = classes / p * (p + 1);
    const bool prime = classes == static_cast<std::size_t>(N) + 1;
    const std::size_t n = N;
    std::size_t modes = 0, states = 0, tables = 0, bytes = 0;
    const bool fits = checked_multiply(n, n, modes) &&
                      checked_multiply(modes, 2 * 2 * sizeof(double), states) &&
                      checked_multiply(classes + (prime ? 0 : n), n, tables) &&
                      states <= SIZE_MAX - tables;
    const std::string what = "sine-Euler N = " + std::to_string(N) + " needs ";
    const std::string parts = " (two working states of 2 N^2 doubles and the direction tables)";
    if (!fits)
        fail(LPI_ERR_NO_MEMORY, what + "more than " + std::to_string(SIZE_MAX) + " bytes" + parts);
    bytes = states + tables;
    const std::size_t available = physical_memory();
    if (available != 0 && bytes > available)
        fail(LPI_ERR_NO_MEMORY, what + std::to_string(bytes) + " bytes (" + gib(bytes) + ")" + parts +
                                    "; this machine has " + std::to_string(available) + " bytes (" +
                                    gib(available) + ") of physical memory");
}

}  // namespace

std::unique_ptr<Model> make_sine_euler(int N) {
    if (N < 3 || N % 2 == 0)
        fail(LPI_ERR_INVALID, "N must be odd and >= 3 (Zeitlin's su(N) truncation), got " +
                                  std::to_string(N));
    require_memory(N);
    return std::make_unique<SineEuler>(N);
}

#endif  // LPI_HAVE_FFTW

}  // namespace lpi
