// Gather, phase and scatter of a block of lines (see the header).
#include "kernels.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "indexing.hpp"

namespace lpi {
namespace sine_euler {

namespace {

// The AVX2 variants are compiled with the target attribute and chosen at run
// time (x86-64 with GCC or Clang; elsewhere the baseline alone).
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define LPI_AVX2_KERNELS 1
#else
#define LPI_AVX2_KERNELS 0
#endif
// Every helper is inlined into the function of its instruction set: one not
// inlined would be compiled for the baseline alone.
#define LPI_KERNEL inline __attribute__((always_inline))

// One complex number (Complex1) or two (Complex2), interleaved (GCC's and
// Clang's vector extensions). Complex2 is used in the AVX2 variants only: GCC
// builds a 256-bit vector's shuffles element by element where the target has
// no such vectors (the baseline's phase took 9 ns a mode at N = 125 with it,
// 1 with Complex1). Every function taking them is inlined, so the warning
// that their passing differs with and without AVX does not apply; they are
// passed by reference all the same, as GCC notes values regardless.
#if defined(__GNUC__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
typedef double Complex1 __attribute__((vector_size(16)));
typedef double Complex2 __attribute__((vector_size(32)));
#if defined(__clang__)
#define LPI_SHUFFLE(v, ...) __builtin_shufflevector(v, v, __VA_ARGS__)
#define LPI_SHUFFLE2(a, b, ...) __builtin_shufflevector(a, b, __VA_ARGS__)
#define LPI_SHUFFLE1(a, b, ...) __builtin_shufflevector(a, b, __VA_ARGS__)
#else
typedef std::int64_t Mask1 __attribute__((vector_size(16)));
typedef std::int64_t Mask2 __attribute__((vector_size(32)));
#define LPI_SHUFFLE(v, ...) __builtin_shuffle(v, Mask2{__VA_ARGS__})
#define LPI_SHUFFLE2(a, b, ...) __builtin_shuffle(a, b, Mask2{__VA_ARGS__})
#define LPI_SHUFFLE1(a, b, ...) __builtin_shuffle(a, b, Mask1{__VA_ARGS__})
#endif

LPI_KERNEL Complex2 reversed(const Complex2 &v) { return LPI_SHUFFLE(v, 2, 3, 0, 1); }
// (a0, b0) and (a1, b1): the real and the imaginary parts of a and b, and back.
LPI_KERNEL Complex1 even_parts(const Complex1 &a, const Complex1 &b) { return LPI_SHUFFLE1(a, b, 0, 2); }
LPI_KERNEL Complex1 odd_parts(const Complex1 &a, const Complex1 &b) { return LPI_SHUFFLE1(a, b, 1, 3); }
#if LPI_AVX2_KERNELS
// (a0, b0, a2, b2) and (a1, b1, a3, b3): with a = (z0, z2) and b = (z1, z3)
// the real and the imaginary parts of z0 .. z3, and back.
LPI_KERNEL Complex2 even_parts(const Complex2 &a, const Complex2 &b) { return LPI_SHUFFLE2(a, b, 0, 4, 2, 6); }
LPI_KERNEL Complex2 odd_parts(const Complex2 &a, const Complex2 &b) { return LPI_SHUFFLE2(a, b, 1, 5, 3, 7); }
#endif
#undef LPI_SHUFFLE1
#undef LPI_SHUFFLE2
#undef LPI_SHUFFLE

template <class V>
LPI_KERNEL V load(const double *p) {
    V v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
template <class V>
LPI_KERNEL void store(double *p, const V &v) {
    std::memcpy(p, &v, sizeof v);
}
#if LPI_AVX2_KERNELS
// Two complex numbers from (to) two places. GCC before 12 has no
// __builtin_shufflevector; built element by element the pair is the same.
LPI_KERNEL Complex2 load_pair(const double *low, const double *high) {
    const Complex1 a = load<Complex1>(low), b = load<Complex1>(high);
#if defined(__clang__) || (defined(__GNUC__) && __GNUC__ >= 12)
    return __builtin_shufflevector(a, b, 0, 1, 2, 3);
#else
    return Complex2{a[0], a[1], b[0], b[1]};
#endif
}
LPI_KERNEL void store_pair(double *low, double *high, const Complex2 &v) {
    std::memcpy(low, &v, sizeof(Complex1));
    std::memcpy(high, reinterpret_cast<const char *>(&v) + sizeof(Complex1), sizeof(Complex1));
}
#endif

// ---- Row and Column directions: runs along lanes --------------------------
// A Row or Column direction's lines cross each lane (row s, or column s) in a
// run: element s of line d0 + i is at position (o + i) mod N of lane s, with
// o = s m + d0 (slope m = k2, or k1), and its conjugate mirror at position
// -(o + i) mod N of lane -s. Rows: lane s starts at s N and positions step by
// 1; columns: lane s starts at s and positions step by N.
// Calls f(s, o) for the N lanes, from first_lane on, cyclically.
template <class F>
LPI_KERNEL void for_each_lane(int N, int slope, int d0, int first_lane, F &&f) {
    int o = modulo(d0 + static_cast<std::int64_t>(first_lane) * slope, N);
    for (int k = 0, s = first_lane; k < N; ++k, s = s + 1 < N ? s + 1 : 0) {
        f(s, o);
        o += slope;
        if (o >= N) o -= N;
    }
}

// The half of the modes the flows keep (kept_mode, indexing.hpp): every
// other mode is the conjugate of its mirror, which the flows read and write
// in its place; write_conjugate_half (SineEuler::settle) writes the
// conjugates once the flows are done. The two are exact conjugates (a
// negated imaginary part), so a sum formed from either has the same bits.
LPI_KERNEL Complex1 conjugate(const Complex1 &z) { return z * Complex1{1.0, -1.0}; }
// What z is multiplied by to conjugate it, or not (exact either way).
LPI_KERNEL Complex1 conjugating(bool yes) { return Complex1{1.0, yes ? -1.0 : 1.0}; }

// Positions p0 .. p0+n-1 (p0 + n <= N) of a row kept as its mirror: the
// conjugates of the mirror row's positions -(p0 + r) mod N.
// Wide: two at once, the pair N - p - 1, N - p reversed.
template <bool Wide>
LPI_KERNEL void copy_mirrored_run(int N, int p0, int n, const double *__restrict mirror, double *__restrict dst) {
    if (n <= 0) return;
    int r = 0;
    if (p0 == 0) store(dst, conjugate(load<Complex1>(mirror))), r = 1;
    if (Wide)
        for (; r + 2 <= n; r += 2)
            store(dst + 2 * r, reversed(load<Complex2>(mirror + 2 * (N - p0 - r - 1))) * Complex2{1.0, -1.0, 1.0, -1.0});
    for (; r < n; ++r) store(dst + 2 * r, conjugate(load<Complex1>(mirror + 2 * (N - p0 - r))));
}

// Count > 0: the block size, known at compile time (full blocks); 0: count.
template <bool Rows, int Count, bool Wide>
LPI_KERNEL void gather_runs(int N, int slope, int d0, int count, int first_lane,
                            const double *__restrict w, double *__restrict x) {
    const std::size_t lane = Rows ? N : 1, step = Rows ? 1 : N;
    const int n = Count > 0 ? Count : count, M = (N - 1) / 2;
    for_each_lane(N, slope, d0, first_lane, [&](int s, int o) {
        const double *src = w + 2 * lane * s;
        double *dst = x + 2 * static_cast<std::size_t>(s) * n;
        // Position p of lane s is (s, p) in a row, (p, s) in a column; the
        // mirror is at position -p of lane -s.
        const double *mirror = w + 2 * lane * negated_residue(s, N);
        const int first = o <= N - n ? n : N - o;  // the run wraps at most once
        if (Rows && s >= 1 && s <= M) {  // a kept row
            for (int i = 0; i < first; ++i) {
                dst[2 * i] = src[2 * step * (o + i)];
                dst[2 * i + 1] = src[2 * step * (o + i) + 1];
            }
            for (int i = first; i < n; ++i) {
                dst[2 * i] = src[2 * step * (o + i - N)];
                dst[2 * i + 1] = src[2 * step * (o + i - N) + 1];
            }
            return;
        }
        if (Rows && s > M) {  // a row kept as its mirror
            copy_mirrored_run<Wide>(N, o, first, mirror, dst);
            copy_mirrored_run<Wide>(N, 0, n - first, mirror, dst + 2 * first);
            return;
        }
        for (int i = 0, p = o; i < n; ++i, p = p + 1 < N ? p + 1 : 0) {
            const bool kept = Rows ? kept_mode(s, p, N) : kept_mode(p, s, N);
            const double *z = kept ? src + 2 * step * p : mirror + 2 * step * negated_residue(p, N);
            store(dst + 2 * i, load<Complex1>(z) * conjugating(!kept));
        }
    });
}

// Adds n increments to positions p0 .. p0+n-1 (p0 + n <= N) of a kept row.
// Wide: two at once.
template <bool Wide>
LPI_KERNEL void add_run(int p0, int n, const double *__restrict increment, double *lane) {
    int r = 0;
    if (n <= 0) return;
    if (Wide)
        for (; r + 2 <= n; r += 2) {
            double *z = lane + 2 * (p0 + r);
            store(z, load<Complex2>(z) + load<Complex2>(increment + 2 * r));
        }
    for (; r < n; ++r) {
        double *z = lane + 2 * (p0 + r);
        store(z, load<Complex1>(z) + load<Complex1>(increment + 2 * r));
    }
}

// The same where the row's modes are kept as their mirrors, at positions
// -(p0 + r) mod N of the mirror row: each sum is formed from the mirror's
// conjugate and stored conjugated there. The mirrors of positions p, p + 1
// are the pair N - p - 1, N - p: two at once, reversed (Wide).
template <bool Wide>
LPI_KERNEL void add_mirrored_run(int N, int p0, int n, const double *__restrict increment, double *mirror) {
    int r = 0;
    if (n <= 0) return;
    if (p0 == 0) {  // position 0 is its own mirror position
        const Complex1 sum = conjugate(load<Complex1>(mirror)) + load<Complex1>(increment);
        store(mirror, conjugate(sum));
        r = 1;
    }
    if (Wide)
        for (; r + 2 <= n; r += 2) {
            double *m = mirror + 2 * (N - p0 - r - 1);
            const Complex2 flip{1.0, -1.0, 1.0, -1.0};
            const Complex2 sum = reversed(load<Complex2>(m)) * flip + load<Complex2>(increment + 2 * r);
            store(m, reversed(sum) * flip);
        }
    for (; r < n; ++r) {
        double *m = mirror + 2 * (N - p0 - r);
        const Complex1 sum = conjugate(load<Complex1>(m)) + load<Complex1>(increment + 2 * r);
        store(m, conjugate(sum));
    }
}

template <bool Rows, int Count, bool Wide>
LPI_KERNEL void scatter_runs(int N, int slope, int d0, int count, int first_lane,
                             const double *__restrict x, double *w) {
    const std::size_t lane = Rows ? N : 1, step = Rows ? 1 : N;
    const int n = Count > 0 ? Count : count, M = (N - 1) / 2;
    for_each_lane(N, slope, d0, first_lane, [&](int s, int o) {
        const double *src = x + 2 * static_cast<std::size_t>(s) * n;
        double *dst = w + 2 * lane * s, *mirror = w + 2 * lane * negated_residue(s, N);
        if (Rows && s != 0) {  // a whole row kept, or a whole row mirrored
            const int first = std::min(n, N - o);  // the run wraps at most once
            if (s <= M) {
                add_run<Wide>(o, first, src, dst);
                add_run<Wide>(0, n - first, src + 2 * first, dst);
            } else {
                add_mirrored_run<Wide>(N, o, first, src, mirror);
                add_mirrored_run<Wide>(N, 0, n - first, src + 2 * first, mirror);
            }
            return;
        }
        for (int i = 0, p = o; i < n; ++i, p = p + 1 < N ? p + 1 : 0) {
            const bool kept = Rows ? kept_mode(s, p, N) : kept_mode(p, s, N);
            double *z = kept ? dst + 2 * step * p : mirror + 2 * step * negated_residue(p, N);
            const Complex1 sign = conjugating(!kept);
            store(z, (load<Complex1>(z) * sign + load<Complex1>(src + 2 * i)) * sign);
        }
    });
}

// ---- General directions: one mode at a time -------------------------------
// Calls f(x_entry, mode, mirror, kept) for element s of line d0 + i, at
// (d0 + i) j + s k: x_entry = s count + i, mode and mirror the indices of
// that mode and of its conjugate in the mode array, kept whether the flows
// keep the mode itself (kept_mode). Along a row of the block the mode moves
// by j: its index by j1 N + j2, less N^2 where a wraps and N where b does;
// the mirror's, -(a, b), is N^2 + N - mode, less N^2 where a = 0 and N where
// b = 0.
template <class F>
LPI_KERNEL void for_each_block_mode(const Direction &D, int N, int d0, int count, F &&f) {
    const std::size_t n = N, square = n * n, stride = D.j1 * n + D.j2;
    int a0 = modulo(static_cast<std::int64_t>(d0) * D.j1, N), b0 = modulo(static_cast<std::int64_t>(d0) * D.j2, N);
    for (int s = 0; s < N; ++s) {
        int a = a0, b = b0;
        std::size_t mode = mode_index(a, b, N);
        const std::size_t row = static_cast<std::size_t>(s) * count;
        for (int i = 0; i < count; ++i) {
            const std::size_t mirror = square + n - mode - (a == 0 ? square : 0) - (b == 0 ? n : 0);
            f(row + i, mode, mirror, kept_mode(a, b, N));
            mode += stride;
            a += D.j1;
            if (a >= N) a -= N, mode -= square;
            b += D.j2;
            if (b >= N) b -= N, mode -= n;
        }
        a0 += D.k1;
        if (a0 >= N) a0 -= N;
        b0 += D.k2;
        if (b0 >= N) b0 -= N;
    }
}

LPI_KERNEL void gather_general(const Direction &D, int N, int d0, int count, const double *w, double *x) {
    for_each_block_mode(D, N, d0, count, [&](std::size_t e, std::size_t mode, std::size_t mirror, bool kept) {
        store(x + 2 * e, load<Complex1>(w + 2 * (kept ? mode : mirror)) * conjugating(!kept));
    });
}

LPI_KERNEL void scatter_general(const Direction &D, int N, int d0, int count, const double *x, double *w) {
    for_each_block_mode(D, N, d0, count, [&](std::size_t e, std::size_t mode, std::size_t mirror, bool kept) {
        double *z = w + 2 * (kept ? mode : mirror);
        const Complex1 sign = conjugating(!kept);
        store(z, (load<Complex1>(z) * sign + load<Complex1>(x + 2 * e)) * sign);
    });
}

// A block's moves: numbers copied, negated and added one increment per mode,
// so every instruction set gives the same bits. Wide: two at once in the
// runs along rows (AVX2).
template <bool Wide>
LPI_KERNEL void gather_lines(const Direction &D, int N, int d0, int count, int first_lane, const double *w,
                             double *x) {
    switch (D.layout) {
        case Direction::Row:
            if (count == kBlock) gather_runs<true, kBlock, Wide>(N, D.k2, d0, count, first_lane, w, x);
            else gather_runs<true, 0, Wide>(N, D.k2, d0, count, first_lane, w, x);
            break;
        case Direction::Column:
            if (count == kBlock) gather_runs<false, kBlock, Wide>(N, D.k1, d0, count, first_lane, w, x);
            else gather_runs<false, 0, Wide>(N, D.k1, d0, count, first_lane, w, x);
            break;
        case Direction::General: gather_general(D, N, d0, count, w, x); break;
    }
}

template <bool Wide>
LPI_KERNEL void scatter_lines(const Direction &D, int N, int d0, int count, int first_lane, const double *x,
                              double *w) {
    switch (D.layout) {
        case Direction::Row:
            if (count == kBlock) scatter_runs<true, kBlock, Wide>(N, D.k2, d0, count, first_lane, x, w);
            else scatter_runs<true, 0, Wide>(N, D.k2, d0, count, first_lane, x, w);
            break;
        case Direction::Column:
            if (count == kBlock) scatter_runs<false, kBlock, Wide>(N, D.k1, d0, count, first_lane, x, w);
            else scatter_runs<false, 0, Wide>(N, D.k1, d0, count, first_lane, x, w);
            break;
        case Direction::General: scatter_general(D, N, d0, count, x, w); break;
    }
}

// Line i of the block (d = d0 + i) has c = sigma d, so exp(t Lambda_l) =
// u_{l-c} conj(u_{l+c}) is e = u_{l+d} conj(u_{l-d}) for sigma = -1 and
// conj(e) for sigma = +1: `sign` = -sigma multiplies Im e, an exact negation.
// With p = v_{l+d}, q = v_{l-d} (v = u - 1), e - 1 = p + conj(q) + p conj(q):
// no cancellation, each term as small as the angles. The tables hold P = p / N
// and Q = q / N, each divided once per flow, so that (e - 1) / N =
// (P + conj(Q)) + P conj(q) needs no division here (dividing, not
// multiplying by a rounded 1/N, which would scale every increment by the same
// N fl(1/N) != 1). Every sum and product is the one the complex arithmetic
// written out would form, in the same order. P_{l+d} is entry d + l of its
// arrays, (Q, q)_{l-d} entry N + d - l of theirs: both run forwards along a
// row of x, four lines at a time (two in the baseline), with the parts of x
// split into vectors of their own on the way in and joined on the way out.

// Parts of (e - 1) / N for the lines at table entries up and down onward,
// and their product with z = (zr, zi): 1 line (double), 2 (Complex1) or 4
// (Complex2).
template <class V>
LPI_KERNEL void phase_product(const double *const arrays[kPhaseArrays], std::size_t up, std::size_t down,
                              double sign, V &zr, V &zi) {
    const V Pr = load<V>(arrays[0] + up), Pi = load<V>(arrays[1] + up);
    const V Qr = load<V>(arrays[2] + down), Qi = load<V>(arrays[3] + down);
    const V qr = load<V>(arrays[4] + down), qi = load<V>(arrays[5] + down);
    const V er = (Pr + Qr) + (Pr * qr + Pi * qi);
    const V ei = ((Pi - Qi) + (Pi * qr - Pr * qi)) * sign;
    const V real = zr * er - zi * ei, imaginary = zi * er + zr * ei;
    zr = real;
    zi = imaginary;
}

// Lines i .. i + lanes - 1 of a row of x as vectors of their real and of
// their imaginary parts (lanes = 4, in the AVX2 variant, or 2), and back.
#if LPI_AVX2_KERNELS
LPI_KERNEL void split(const double *z, Complex2 &re, Complex2 &im) {
    const Complex2 z02 = load_pair(z, z + 4), z13 = load_pair(z + 2, z + 6);
    re = even_parts(z02, z13), im = odd_parts(z02, z13);
}
LPI_KERNEL void join(double *z, const Complex2 &re, const Complex2 &im) {
    store_pair(z, z + 4, even_parts(re, im));
    store_pair(z + 2, z + 6, odd_parts(re, im));
}
#endif
LPI_KERNEL void split(const double *z, Complex1 &re, Complex1 &im) {
    const Complex1 z0 = load<Complex1>(z), z1 = load<Complex1>(z + 2);
    re = even_parts(z0, z1), im = odd_parts(z0, z1);
}
LPI_KERNEL void join(double *z, const Complex1 &re, const Complex1 &im) {
    store(z, even_parts(re, im));
    store(z + 2, odd_parts(re, im));
}

// Count > 0: the block size, known at compile time (full blocks); 0: count.
// V: Complex2 (four lines at a time) or Complex1 (two).
template <int Count, class V>
LPI_KERNEL void phase_rows(int N, int d0, int count, const double *const arrays[kPhaseArrays], double sign,
                           double *x) {
    constexpr std::size_t lanes = sizeof(V) / sizeof(double);
    const std::size_t n = Count > 0 ? Count : count, vectors = n / lanes * lanes;
    for (std::size_t l = 0; l < static_cast<std::size_t>(N); ++l) {
        double *z = x + 2 * l * n;
        const std::size_t up = d0 + l, down = N + d0 - l;
        for (std::size_t i = 0; i < vectors; i += lanes) {
            V zr, zi;
            split(z + 2 * i, zr, zi);
            phase_product(arrays, up + i, down + i, sign, zr, zi);
            join(z + 2 * i, zr, zi);
        }
        if (Count > 0 && Count % lanes == 0) continue;
        for (std::size_t i = vectors; i < n; ++i) {
            double zr = z[2 * i], zi = z[2 * i + 1];
            phase_product(arrays, up + i, down + i, sign, zr, zi);
            z[2 * i] = zr;
            z[2 * i + 1] = zi;
        }
    }
}

template <class V>
LPI_KERNEL void phase_lines(int N, int d0, int count, const double *tables, double sign, double *x) {
    const std::size_t array = 2 * static_cast<std::size_t>(N);
    const double *const arrays[kPhaseArrays] = {tables,             tables + array,     tables + 2 * array,
                                                tables + 3 * array, tables + 4 * array, tables + 5 * array};
    if (count == kBlock) phase_rows<kBlock, V>(N, d0, count, arrays, sign, x);
    else phase_rows<0, V>(N, d0, count, arrays, sign, x);
}

#if LPI_AVX2_KERNELS
// The same templates compiled for AVX2 (without FMA: the same operations).
__attribute__((target("avx2"))) void gather_avx2(const Direction &D, int N, int d0, int count, int first_lane,
                                                 const double *w, double *x) {
    gather_lines<true>(D, N, d0, count, first_lane, w, x);
}
__attribute__((target("avx2"))) void scatter_avx2(const Direction &D, int N, int d0, int count, int first_lane,
                                                  const double *x, double *w) {
    scatter_lines<true>(D, N, d0, count, first_lane, x, w);
}
__attribute__((target("avx2"))) void phase_avx2(int N, int d0, int count, const double *tables, double sign,
                                                double *x) {
    phase_lines<Complex2>(N, d0, count, tables, sign, x);
}

bool cpu_has_avx2() {
    static const bool avx2 = __builtin_cpu_supports("avx2");
    return avx2;
}
#endif

}  // namespace

namespace baseline {
void gather_block(const Direction &D, int N, int d0, int count, int first_lane, const double *w, double *x) {
    gather_lines<false>(D, N, d0, count, first_lane, w, x);
}
void scatter_block(const Direction &D, int N, int d0, int count, int first_lane, const double *x, double *w) {
    scatter_lines<false>(D, N, d0, count, first_lane, x, w);
}
void apply_phase(int N, int d0, int count, const double *tables, double sign, double *x) {
    phase_lines<Complex1>(N, d0, count, tables, sign, x);
}
}  // namespace baseline

void write_conjugate_half(int N, double *w) {
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b)
            if (!kept_mode(a, b, N))
                store(w + 2 * mode_index(a, b, N), conjugate(load<Complex1>(w + 2 * mirror_index(a, b, N))));
}

void transpose_kept_half(int N, const double *__restrict src, double *__restrict dst) {
    const int M = (N - 1) / 2;
    constexpr int kTile = 16;  // 16 rows of src read a cache line each, used by 4 rows of dst
    for (int r0 = 0; r0 <= M; r0 += kTile)
        for (int c0 = 0; c0 < N; c0 += kTile)
            for (int r = r0; r < std::min(r0 + kTile, M + 1); ++r)
                for (int c = c0, end = std::min(c0 + kTile, r == 0 ? M + 1 : N); c < end; ++c) {
                    const bool kept = kept_mode(c, r, N);
                    const double *z = src + 2 * (kept ? mode_index(c, r, N) : mirror_index(c, r, N));
                    store(dst + 2 * mode_index(r, c, N), load<Complex1>(z) * conjugating(!kept));
                }
}

const char *kernel_instruction_set() {
#if LPI_AVX2_KERNELS
    if (cpu_has_avx2()) return "avx2";
#endif
    return "baseline";
}

void gather_block(const Direction &D, int N, int d0, int count, int first_lane, const double *w, double *x) {
#if LPI_AVX2_KERNELS
    if (cpu_has_avx2()) return gather_avx2(D, N, d0, count, first_lane, w, x);
#endif
    baseline::gather_block(D, N, d0, count, first_lane, w, x);
}

void scatter_block(const Direction &D, int N, int d0, int count, int first_lane, const double *x, double *w) {
#if LPI_AVX2_KERNELS
    if (cpu_has_avx2()) return scatter_avx2(D, N, d0, count, first_lane, x, w);
#endif
    baseline::scatter_block(D, N, d0, count, first_lane, x, w);
}

void apply_phase(int N, int d0, int count, const double *tables, double sign, double *x) {
#if LPI_AVX2_KERNELS
    if (cpu_has_avx2()) return phase_avx2(N, d0, count, tables, sign, x);
#endif
    baseline::apply_phase(N, d0, count, tables, sign, x);
}

}  // namespace sine_euler
}  // namespace lpi
