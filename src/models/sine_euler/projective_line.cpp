// The directions of the projective line over Z_N and the modes they own.
#include "projective_line.hpp"

#include <algorithm>
#include <cstdint>
#include <numeric>

#include "indexing.hpp"

namespace lpi {
namespace sine_euler {

namespace {

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

}  // namespace

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

// A nonzero mode belongs to the first direction whose line through the
// origin contains it. Setup is O(N^2) in sequential passes, by these facts
// (g(x) = gcd(x, N)):
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
//   mode, for these modes only: N with a squared prime factor; `claims` may
//   keep those bytes for the modes its caller tracks).
void for_each_direction(int N, const std::function<void(Direction &&)> &visit,
                        const std::function<unsigned char *(int a, int b)> &claims) {
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
                    unsigned char *owner = nullptr;
                    if (claims) {
                        owner = claims(a, b);
                    } else {
                        if (claimed.empty()) claimed.assign(static_cast<std::size_t>(N) * N, 0);
                        owner = &claimed[mode_index(a, b, N)];
                    }
                    D.owned[s] = owner && !*owner;
                    if (owner) *owner = 1;
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
        visit(std::move(D));
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

Direction transposed_view(const Direction &D) {
    Direction view;
    view.k1 = D.k2, view.k2 = D.k1, view.j1 = D.j2, view.j2 = D.j1;
    view.layout = D.layout == Direction::Row      ? Direction::Column
                  : D.layout == Direction::Column ? Direction::Row
                                                  : Direction::General;
    view.sigma = D.sigma;
    return view;
}

Orientation orientation(const Direction &D) {
    if (D.layout == Direction::Row) return Orientation::Modes;
    if (D.layout == Direction::Column && D.k1 != 0) return Orientation::Transposed;
    return Orientation::Either;
}

std::vector<Direction> projective_line(int N) {
    std::vector<Direction> dirs;
    for_each_direction(N, [&](Direction &&D) { dirs.push_back(std::move(D)); });
    return dirs;
}

double piece_energy(const Direction &D, const Hamiltonian &H, const double *modes) {
    const int N = H.truncation();
    double sum = 0.0;
    for (int s = 1; s < N; ++s) {
        if (!D.owned[s]) continue;
        const int a = modulo(static_cast<std::int64_t>(s) * D.k1, N);
        const int b = modulo(static_cast<std::int64_t>(s) * D.k2, N);
        sum += H.mode_energy(mode_index(a, b, N), modes);
    }
    return sum;
}

bool line_stream(const Direction &D, const Hamiltonian &H, const double *modes, bool transposed, double *b) {
    const int N = H.truncation();
    const double *lambda = H.weights(), *f = H.forcing();
    int a = 0, c = 0;
    bool active = false;
    for (int s = 0; s < N; ++s) {
        if (D.owned[s]) {
            // A mode outside the half the flows keep is its mirror's
            // conjugate (kernels.cpp): the same bits. Mode (a, c) is at
            // (c, a) in the transposed modes.
            const std::size_t m = mode_index(a, c, N);
            const int row = transposed ? c : a, column = transposed ? a : c;
            const bool kept = kept_mode(row, column, N);
            const std::size_t k = kept ? mode_index(row, column, N) : mirror_index(row, column, N);
            b[2 * s] = modes[2 * k] * lambda[m];
            b[2 * s + 1] = (kept ? modes[2 * k + 1] : -modes[2 * k + 1]) * lambda[m];
            if (f) {
                b[2 * s] += f[2 * m];
                b[2 * s + 1] += f[2 * m + 1];
            }
            active = active || b[2 * s] != 0.0 || b[2 * s + 1] != 0.0;
        } else {
            b[2 * s] = b[2 * s + 1] = 0.0;
        }
        a += D.k1;
        if (a >= N) a -= N;
        c += D.k2;
        if (c >= N) c -= N;
    }
    return active;
}

}  // namespace sine_euler
}  // namespace lpi
