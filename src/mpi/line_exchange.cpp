// The lines each process holds and the exchange between directions (see the
// header).
#include "line_exchange.hpp"

#include <algorithm>
#include <climits>
#include <numeric>
#include <string>

#include "../core/error.hpp"
#include "../models/sine_euler/indexing.hpp"

namespace lpi {
namespace mpi {

using sine_euler::Direction;
using sine_euler::modulo;

LineOwnership::LineOwnership(int n, int processes)
    : N(n), M((n - 1) / 2), P(processes), first(static_cast<std::size_t>(processes) + 1),
      owner(static_cast<std::size_t>(M) + 1, -1) {
    for (int r = 0; r <= P; ++r)
        first[r] = 1 + static_cast<int>(static_cast<std::int64_t>(r) * M / P);
    for (int r = 0; r < P; ++r)
        for (int d = first[r]; d < first[r + 1]; ++d) owner[d] = r;
}

namespace {

std::int64_t cross(std::int64_t x1, std::int64_t x2, std::int64_t y1, std::int64_t y2) {
    return x1 * y2 - x2 * y1;
}

// The linear map from direction D' = to (d', s') to direction D = from
// (v, u), and the solutions of gamma s' = c (mod N). Per mode it only looks
// up and adds: the tables (N entries each, in buffers the exchange keeps)
// are filled once per move, so the enumeration below does no division.
struct Transition {
    Transition(const Direction &from, const Direction &to, int n, std::vector<int> &first_solution,
               std::vector<int> &nu_multiple)
        : N(n), first_solution_(first_solution.data()), nu_multiple_(nu_multiple.data()) {
        const std::int64_t sigma = from.sigma;
        gamma = modulo(sigma * cross(to.k1, to.k2, from.k1, from.k2), N);
        delta = modulo(sigma * cross(to.j1, to.j2, from.k1, from.k2), N);
        mu = modulo(sigma * cross(from.j1, from.j2, to.j1, to.j2), N);
        nu = modulo(sigma * cross(from.j1, from.j2, to.k1, to.k2), N);
        g = std::gcd(gamma, N);
        period = N / g;
        // The inverse of gamma / g mod N / g (extended Euclid).
        std::int64_t r0 = period, r1 = (gamma / g) % period, t0 = 0, t1 = 1;
        while (r1 != 0) {
            const std::int64_t q = r0 / r1, r = r0 - q * r1, t = t0 - q * t1;
            r0 = r1, r1 = r, t0 = t1, t1 = t;
        }
        const int inverse = period == 1 ? 0 : modulo(t0, period);
        // first_solution[c] = (c / g) inverse mod period for c a multiple of
        // g, else -1; nu_multiple[s] = nu s mod N. Both by running sums.
        std::fill(first_solution_, first_solution_ + N, -1);
        for (int c = 0, s0 = 0; c < N; c += g) {
            first_solution_[c] = s0;
            s0 += inverse;
            if (s0 >= period) s0 -= period;
        }
        for (int s = 0, m = 0; s < N; ++s) {
            nu_multiple_[s] = m;
            m += nu;
            if (m >= N) m -= N;
        }
    }
    // Calls f(s') for the s' in 0 .. N-1, ascending, with gamma s' = c (mod
    // N), for c in 0 .. N-1.
    template <class F>
    void solve(int c, F &&f) const {
        for (int s = first_solution_[c]; s >= 0 && s < N; s += period) f(s);
    }
    int line_of_new_origin_line(int s) const { return static_cast<int>(static_cast<std::int64_t>(gamma) * s % N); }
    // Element s' of line d' lies at element (mu d' + nu s') mod N of its
    // old line: element_base(d') is the first term, element() adds the second.
    int element_base(int d_new) const { return static_cast<int>(static_cast<std::int64_t>(mu) * d_new % N); }
    int element(int base, int s_new) const {
        const int u = base + nu_multiple_[s_new];
        return u >= N ? u - N : u;
    }
    // delta d' mod N, the line of D that element 0 of line d' lies on.
    int line_offset(int d_new) const { return static_cast<int>(static_cast<std::int64_t>(delta) * d_new % N); }
    int N, gamma, delta, mu, nu, g, period;

private:
    int *first_solution_, *nu_multiple_;
};

// Calls f(d', s', d, element, mirrored) for each mode that `source` sends to
// `target`, in the order both use: the mode at element s' of line d' of the
// new direction is at `element` of line d of the old one, conjugated when
// `mirrored` (it lies on line -d there).
template <class F>
void for_each_exchanged(const Transition &T, const LineOwnership &L, int target, int source, F &&f) {
    const int N = L.N;
    for (int d_new = L.first[target]; d_new < L.first[target + 1]; ++d_new) {
        const int offset = T.line_offset(d_new), base = T.element_base(d_new);
        for (int d = L.first[source]; d < L.first[source + 1]; ++d) {
            // d - offset and N - d - offset lie in (-N, N): one correction each.
            const int on_d = d - offset, on_minus_d = N - d - offset;
            T.solve(on_d < 0 ? on_d + N : on_d,
                    [&](int s_new) { f(d_new, s_new, d, T.element(base, s_new), false); });
            T.solve(on_minus_d < 0 ? on_minus_d + N : on_minus_d, [&](int s_new) {
                const int u = T.element(base, s_new);
                f(d_new, s_new, d, u == 0 ? 0 : N - u, true);
            });
        }
    }
}

int as_count(std::size_t n) {
    if (n > static_cast<std::size_t>(INT_MAX))
        fail(LPI_ERR_OVERFLOW, "an exchange of " + std::to_string(n) +
                                   " modes overflows an MPI count (use more processes)");
    return static_cast<int>(n);
}

}  // namespace

void LineExchange::move(const Direction &from, std::size_t from_index, const Direction &to,
                        std::size_t to_index, double *state, Riders *riders) {
    if (from_index == to_index) {
        if (riders) exchange_riders(*riders);
        return;
    }
    const LineOwnership &L = lines_;
    const int N = L.N, P = L.P, me = comm_.rank(), mine = L.count(me);
    check_reserved(riders);
    const Transition T(from, to, N, first_solution_, nu_multiple_);
    double *line0 = state + line0_entry();
    double *slab = state + slab_entry(N);

    // Where each mode of the new line 0 comes from: the owner of its old
    // line, or -1 for modes on the old line 0 (at hand here). By owner, in
    // ascending s' within each.
    // (In buffers kept between flows: after reserve(), nothing here
    // allocates, so nothing fails on one process before the collective.)
    std::vector<int> &origin_source = origin_source_, &origin_order = origin_order_;
    std::vector<int> &origin_first = origin_first_, &next = next_origin_;
    origin_source.assign(static_cast<std::size_t>(N), -1);
    origin_first.assign(static_cast<std::size_t>(P) + 1, 0);
    for (int s = 1; s < N; ++s) {
        const int v = T.line_of_new_origin_line(s);
        if (v != 0) origin_source[s] = L.owner[v <= L.M ? v : N - v];
        if (origin_source[s] >= 0) ++origin_first[origin_source[s] + 1];
    }
    std::partial_sum(origin_first.begin(), origin_first.end(), origin_first.begin());
    origin_order.resize(static_cast<std::size_t>(origin_first[P]));
    next.assign(origin_first.begin(), origin_first.end() - 1);
    for (int s = 1; s < N; ++s)
        if (origin_source[s] >= 0) origin_order[next[origin_source[s]]++] = s;
    // The value of the old layout at element u of line v (v != 0).
    auto old_value = [&](int v, int u, double &re, double &im) {
        const bool mirrored = v > L.M;
        const int d = mirrored ? N - v : v, e = mirrored ? (u == 0 ? 0 : N - u) : u;
        const double *z = slab + 2 * (static_cast<std::size_t>(e) * mine + (d - L.first[me]));
        re = z[0];
        im = mirrored ? -z[1] : z[1];
    };

    // Where each value received goes (complex entries after the index: line
    // 0 at 0 .. N-1, the lines from N).
    std::uint64_t *target = targets_.data();
    std::size_t received = 0;
    receive_counts_.assign(P, 0);
    receive_offsets_.assign(P, 0);
    rider_offsets_.assign(P, 0);
    for (int r = 0; r < P; ++r) {
        const std::size_t start = received;
        for (int i = origin_first[r]; i < origin_first[r + 1]; ++i) target[received++] = origin_order[i];
        if (riders) {
            rider_offsets_[r] = received;
            std::fill_n(target + received, riders->counts[r], kRider);
            received += static_cast<std::size_t>(riders->counts[r]);
        }
        const std::uint64_t first_line = N - static_cast<std::uint64_t>(L.first[me]);
        for_each_exchanged(T, L, me, r, [&](int d_new, int s_new, int, int, bool) {
            target[received++] = first_line + static_cast<std::uint64_t>(s_new) * mine + d_new;
        });
        receive_offsets_[r] = as_count(start);
        receive_counts_[r] = as_count(received - start);
    }
    old_line0_.assign(line0, line0 + 2 * static_cast<std::size_t>(N));

    // Pack: for each process, the new line 0's modes held here, the riders,
    // then its lines' modes. Written through pointers into buffers sized by
    // reserve() to the largest exchange (checked above). This process's own
    // block goes straight to where it is received, and the collective
    // carries the others only (on one process: nothing to copy).
    auto pack = [&](int q, double *out) {
        std::size_t k = 0;  // complex entries
        for (int i = origin_first[me]; i < origin_first[me + 1]; ++i, ++k) {
            const int s = origin_order[i];
            old_value(T.line_of_new_origin_line(s), T.element(0, s), out[2 * k], out[2 * k + 1]);
        }
        if (riders) {
            std::copy(riders->own.begin(), riders->own.end(), out + 2 * k);
            k += riders->own.size() / 2;
        }
        for_each_exchanged(T, L, q, me, [&](int, int, int d, int e, bool mirrored) {
            const double *z = slab + 2 * (static_cast<std::size_t>(e) * mine + (d - L.first[me]));
            out[2 * k] = z[0];
            out[2 * k + 1] = mirrored ? -z[1] : z[1];
            ++k;
        });
        return k;
    };
    std::size_t sent = 0;
    send_counts_.assign(P, 0);
    send_offsets_.assign(P, 0);
    for (int q = 0; q < P; ++q) {
        send_offsets_[q] = as_count(sent);
        if (q != me) {
            const std::size_t count = pack(q, send_.data() + 2 * sent);
            send_counts_[q] = as_count(count);
            sent += count;
        } else if (pack(q, receive_.data() + 2 * static_cast<std::size_t>(receive_offsets_[me])) !=
                   static_cast<std::size_t>(receive_counts_[me])) {
            fail(LPI_ERR_INTERNAL, "a line exchange packed another count than it receives");
        }
    }
    receive_counts_[me] = 0;  // in place already
    comm_.alltoallv(send_.data(), send_counts_, send_offsets_, receive_.data(), receive_counts_,
                    receive_offsets_);

    double *entries = state + line0_entry();
    const double *in = receive_.data();
    for (std::size_t i = 0; i < received; ++i) {
        if (target[i] == kRider) continue;
        entries[2 * target[i]] = in[2 * i];
        entries[2 * target[i] + 1] = in[2 * i + 1];
    }
    if (riders) gather_riders(*riders);
    // Modes on the old line 0: from the copy held here.
    for (int s = 1; s < N; ++s)
        if (origin_source[s] < 0) {
            const int u = T.element(0, s);
            line0[2 * s] = old_line0_[2 * u];
            line0[2 * s + 1] = old_line0_[2 * u + 1];
        }
    for (int d_new = L.first[me]; d_new < L.first[me + 1]; ++d_new) {
        const int base = T.element_base(d_new);
        T.solve(modulo(-static_cast<std::int64_t>(T.line_offset(d_new)), N), [&](int s_new) {
            const int u = T.element(base, s_new);
            double *z = slab + 2 * (static_cast<std::size_t>(s_new) * mine + (d_new - L.first[me]));
            z[0] = old_line0_[2 * u];
            z[1] = old_line0_[2 * u + 1];
        });
    }
    state[0] = static_cast<double>(to_index);
}

// The most modes of one direction's line 0 that this process's lines of
// another direction hold. Mode s k' lies on line v = c s mod N for a c fixed
// by the two directions; with g = gcd(c, N), v runs over the multiples of g,
// each g times: g times the multiples of g among this process's lines d and
// their mirrors -d, at most over the divisors g of N (for a prime N, 2 per
// line; at N = 255, 170 for a process of 64 lines holding line 85).
std::size_t LineExchange::most_line0_modes_held() const {
    const int N = lines_.N, me = comm_.rank();
    std::size_t most = 0;
    for (int g = 1; g < N; ++g) {
        if (N % g != 0) continue;
        std::size_t multiples = 0;
        for (int d = lines_.first[me]; d < lines_.first[me + 1]; ++d) multiples += d % g == 0 ? 1 : 0;
        most = std::max(most, 2 * static_cast<std::size_t>(g) * multiples);
    }
    return std::min(most, static_cast<std::size_t>(N));
}

// Bounds, per process: `held` modes of the new line 0 (most_line0_modes_held)
// and as many riders of at most 4 doubles each (the weights of the modes of
// line 0 held in the reference direction's layout), both sent to every
// process; the lines send each of their N mine modes once. What is received:
// the N modes of line 0, riders of at most 2 entries a mode of it, and the N
// mine modes of the lines. Complex entries.
std::size_t LineExchange::most_sent() const {
    const std::size_t N = static_cast<std::size_t>(lines_.N), P = static_cast<std::size_t>(lines_.P);
    return P * (held_ + 2 * held_) + N * static_cast<std::size_t>(lines_.count(comm_.rank()));
}
std::size_t LineExchange::most_received() const {
    const std::size_t N = static_cast<std::size_t>(lines_.N);
    return N + 2 * N + N * static_cast<std::size_t>(lines_.count(comm_.rank()));
}

void LineExchange::reserve(Riders *riders) {
    const std::size_t N = static_cast<std::size_t>(lines_.N), P = static_cast<std::size_t>(lines_.P);
    const std::size_t held = held_;
    send_.resize(2 * most_sent());
    targets_.resize(most_received());
    receive_.resize(2 * most_received());
    old_line0_.reserve(2 * N);
    for (std::vector<int> *v : {&send_counts_, &send_offsets_, &receive_counts_, &receive_offsets_})
        v->reserve(P);
    rider_offsets_.reserve(P);
    origin_source_.reserve(N);
    origin_order_.reserve(N);
    origin_first_.reserve(P + 1);
    next_origin_.reserve(P);
    if (!riders) return;
    riders->own.reserve(4 * held);
    riders->counts.reserve(P);
    riders->gathered.reserve(4 * N);
}

// The buffers a move writes through pointers have their largest sizes, and
// the riders fit in them: a move cannot write past them.
void LineExchange::check_reserved(const Riders *riders) const {
    if (send_.size() < 2 * most_sent() || targets_.size() < most_received() ||
        receive_.size() < 2 * most_received())
        fail(LPI_ERR_INTERNAL, "a line exchange before its buffers were reserved");
    if (!riders) return;
    std::size_t received = 0;
    for (int count : riders->counts) received += static_cast<std::size_t>(count);
    if (riders->own.size() > 4 * held_ || riders->counts.size() != static_cast<std::size_t>(lines_.P) ||
        received > 2 * static_cast<std::size_t>(lines_.N))
        fail(LPI_ERR_INTERNAL, "line exchange riders past their bound");
}

void LineExchange::exchange_riders(Riders &riders) {
    check_reserved(&riders);
    const int P = lines_.P;
    double *out = send_.data();
    send_counts_.assign(P, 0);
    send_offsets_.assign(P, 0);
    receive_counts_.assign(P, 0);
    receive_offsets_.assign(P, 0);
    rider_offsets_.assign(P, 0);
    const int own = as_count(riders.own.size() / 2);
    std::size_t received = 0;
    for (int q = 0; q < P; ++q) {
        send_offsets_[q] = as_count(static_cast<std::size_t>(q) * own);
        std::copy(riders.own.begin(), riders.own.end(), out + 2 * static_cast<std::size_t>(q) * own);
        send_counts_[q] = own;
        rider_offsets_[q] = received;
        receive_offsets_[q] = as_count(received);
        receive_counts_[q] = riders.counts[q];
        received += static_cast<std::size_t>(riders.counts[q]);
    }
    comm_.alltoallv(send_.data(), send_counts_, send_offsets_, receive_.data(), receive_counts_,
                    receive_offsets_);
    gather_riders(riders);
}

void LineExchange::gather_riders(Riders &riders) const {
    riders.gathered.clear();
    for (int r = 0; r < lines_.P; ++r) {
        const double *first = receive_.data() + 2 * rider_offsets_[r];
        riders.gathered.insert(riders.gathered.end(), first, first + 2 * static_cast<std::size_t>(riders.counts[r]));
    }
}

}  // namespace mpi
}  // namespace lpi
