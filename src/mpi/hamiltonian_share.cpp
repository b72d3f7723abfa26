// The Hamiltonian spread over processes (see the header).
#include "hamiltonian_share.hpp"

#include <optional>

#include "../core/error.hpp"
#include "../models/sine_euler/indexing.hpp"

namespace lpi {
namespace mpi {

using sine_euler::Direction;
using sine_euler::Hamiltonian;
using sine_euler::mode_index;

HamiltonianShare::HamiltonianShare(int N, const LineOwnership &lines, int rank)
    : N_(N), M_((N - 1) / 2), lines_(lines), rank_(rank), first_(lines.first[rank]),
      mine_(lines.count(rank)),
      lambda_(static_cast<std::size_t>(N) * (1 + static_cast<std::size_t>(mine_))),
      owner_(static_cast<std::size_t>(N) * mine_) {
    for (int s = 0; s < N; ++s) {
        lambda_[s] = Hamiltonian::euler_weight(0, s, N);
        for (int d = first_; d < first_ + mine_; ++d) lambda_[entry(d, s)] = Hamiltonian::euler_weight(d, s, N);
    }
}

HamiltonianShare::Place HamiltonianShare::place(int a, int b) const {
    if (a <= M_) return {a, b, false};
    return {N_ - a, b == 0 ? 0 : N_ - b, true};
}

void HamiltonianShare::record_owners(std::size_t index, const Direction &D) {
    for (int s = 1; s < N_; ++s) {
        if (!D.owned[s]) continue;
        const int a = sine_euler::modulo(static_cast<std::int64_t>(s) * D.k1, N_);
        const int b = sine_euler::modulo(static_cast<std::int64_t>(s) * D.k2, N_);
        if (a == 0) continue;  // line 0: piece 0's
        const Place p = place(a, b);
        if (lines_.owner[p.line] == rank_) owner_[entry(p.line, p.element) - N_] = static_cast<std::uint32_t>(index);
    }
}

void HamiltonianShare::read_pieces(const std::function<void(Direction &&)> &keep) {
    // Whether a later class claimed a held mode (and, apart, its conjugate).
    std::vector<unsigned char> claimed;
    std::size_t index = 0;
    sine_euler::for_each_direction(
        N_,
        [&](Direction &&D) {
            record_owners(index++, D);
            std::vector<unsigned char>().swap(D.owned);
            keep(std::move(D));
        },
        [&](int a, int b) -> unsigned char * {
            const Place p = place(a, b);
            if (lines_.owner[p.line] != rank_) return nullptr;
            if (claimed.empty()) claimed.assign(2 * owner_.size(), 0);
            return &claimed[2 * (entry(p.line, p.element) - N_) + p.mirrored];
        });
}

HamiltonianShare::Share HamiltonianShare::share_of(const Hamiltonian &H) const {
    const double *lambda = H.weights(), *f = H.forcing();
    Share share;
    share.f.resize(f ? lambda_.size() * 2 : 0);
    share.lambda.resize(lambda_.size());
    auto copy = [&](std::size_t e, int a, int b) {
        const std::size_t m = mode_index(a, b, N_);
        share.lambda[e] = lambda[m];
        if (f) share.f[2 * e] = f[2 * m], share.f[2 * e + 1] = f[2 * m + 1];
    };
    for (int s = 0; s < N_; ++s) {
        copy(static_cast<std::size_t>(s), 0, s);
        for (int d = first_; d < first_ + mine_; ++d) copy(entry(d, s), d, s);
    }
    share.euler = H.is_default();
    return share;
}

void HamiltonianShare::keep(Share &share) noexcept {
    lambda_.swap(share.lambda);
    f_.swap(share.f);
    euler_ = share.euler;
}

Hamiltonian HamiltonianShare::whole(const Communicator &comm) const {
    std::optional<Hamiltonian> H;
    if (euler_) {
        comm.agree([&] { H.emplace(N_); });
        return std::move(*H);
    }
    // Every process's lines, as complex entries (lambda, 0) then f; the
    // buffers allocated, and agreed on, before the collective.
    const int per_mode = f_.empty() ? 1 : 2;
    const int P = lines_.P;
    std::vector<double> held, all;
    std::vector<int> counts, offsets;
    comm.agree([&] {
        held.reserve(2 * static_cast<std::size_t>(per_mode) * N_ * mine_);
        for (std::size_t e = N_; e < lambda_.size(); ++e) {
            held.push_back(lambda_[e]);
            held.push_back(0.0);
            if (!f_.empty()) held.push_back(f_[2 * e]), held.push_back(f_[2 * e + 1]);
        }
        counts.resize(P), offsets.resize(P);
        all.resize(2 * static_cast<std::size_t>(per_mode) * N_ * M_);
    });
    for (int r = 0; r < P; ++r) {
        counts[r] = per_mode * lines_.count(r) * N_;
        offsets[r] = per_mode * (lines_.first[r] - 1) * N_;
    }
    comm.allgatherv(held.data(), per_mode * mine_ * N_, all.data(), counts, offsets);

    // Assembled, and agreed on, after it.
    comm.agree([&] {
        const std::size_t modes = static_cast<std::size_t>(N_) * N_;
        std::vector<double> lambda(modes), f(f_.empty() ? 0 : 2 * modes);
        for (int s = 0; s < N_; ++s) {
            lambda[mode_index(0, s, N_)] = lambda_[s];
            if (!f.empty()) f[2 * s] = f_[2 * s], f[2 * s + 1] = f_[2 * s + 1];
        }
        for (int r = 0; r < P; ++r) {
            const double *slab = all.data() + 2 * static_cast<std::size_t>(offsets[r]);
            const int count = lines_.count(r);
            for (int s = 0; s < N_; ++s)
                for (int i = 0; i < count; ++i) {
                    const double *z = slab + 2 * per_mode * (static_cast<std::size_t>(s) * count + i);
                    const int d = lines_.first[r] + i;
                    const std::size_t m = mode_index(d, s, N_), minus = sine_euler::mirror_index(d, s, N_);
                    lambda[m] = lambda[minus] = z[0];
                    if (f.empty()) continue;
                    f[2 * m] = f[2 * minus] = z[2];
                    f[2 * m + 1] = z[3];
                    f[2 * minus + 1] = -z[3];
                }
        }
        H.emplace(N_, lambda.data(), modes, f.empty() ? nullptr : f.data(), f.size());
    });
    return std::move(*H);
}

template <class F>
void HamiltonianShare::for_each_origin_mode(const Direction &D, F &&f) const {
    for (int s = 1; s < N_; ++s) {
        const int a = sine_euler::modulo(static_cast<std::int64_t>(s) * D.k1, N_);
        f(s, a == 0 ? -1 : lines_.owner[a <= M_ ? a : N_ - a]);
    }
}

void HamiltonianShare::origin_line_riders(const Direction &D, std::size_t index, Riders &riders) const {
    const int per_mode = f_.empty() ? 1 : 2;
    riders.own.clear();
    riders.counts.assign(static_cast<std::size_t>(lines_.P), 0);
    for_each_origin_mode(D, [&](int s, int holder) {
        if (holder < 0) return;
        riders.counts[holder] += per_mode;
        if (holder != rank_) return;
        const int a = sine_euler::modulo(static_cast<std::int64_t>(s) * D.k1, N_);
        const int b = sine_euler::modulo(static_cast<std::int64_t>(s) * D.k2, N_);
        const Place p = place(a, b);
        const std::size_t e = entry(p.line, p.element);
        const bool owned = owner_[e - N_] == index;
        riders.own.push_back(owned ? lambda_[e] : 0.0);
        riders.own.push_back(owned ? 1.0 : 0.0);
        if (per_mode == 2) {
            riders.own.push_back(owned ? f_[2 * e] : 0.0);
            riders.own.push_back(owned ? (p.mirrored ? -f_[2 * e + 1] : f_[2 * e + 1]) : 0.0);
        }
    });
}

void HamiltonianShare::reserve(OriginLineWeights &out) const {
    const std::size_t n = static_cast<std::size_t>(N_);
    out.lambda.reserve(n);
    out.owned.reserve(n);
    out.f.reserve(f_.empty() ? 0 : 2 * n);
    rider_start_.reserve(static_cast<std::size_t>(lines_.P) + 1);
}

void HamiltonianShare::read_origin_line(const Direction &D, std::size_t index, const Riders &riders,
                                        OriginLineWeights &out) const {
    const std::size_t n = static_cast<std::size_t>(N_);
    const bool forced = !f_.empty();
    out.lambda.assign(n, 0.0);
    out.owned.assign(n, 0);
    out.f.assign(forced ? 2 * n : 0, 0.0);
    // Where each process's values start in riders.gathered.
    std::vector<std::size_t> &next = rider_start_;
    next.assign(static_cast<std::size_t>(lines_.P) + 1, 0);
    for (int r = 0; r < lines_.P; ++r) next[r + 1] = next[r] + 2 * static_cast<std::size_t>(riders.counts[r]);
    for_each_origin_mode(D, [&](int s, int holder) {
        if (holder < 0) {  // mode (0, b) of line 0: piece 0's, held here
            if (index != 0) return;
            const int b = sine_euler::modulo(static_cast<std::int64_t>(s) * D.k2, N_);
            out.owned[s] = 1;
            out.lambda[s] = lambda_[b];
            if (forced) out.f[2 * s] = f_[2 * b], out.f[2 * s + 1] = f_[2 * b + 1];
            return;
        }
        const double *z = riders.gathered.data() + next[holder];
        next[holder] += forced ? 4 : 2;
        out.lambda[s] = z[0];
        out.owned[s] = z[1] != 0.0;
        if (forced) out.f[2 * s] = z[2], out.f[2 * s + 1] = z[3];
    });
}

}  // namespace mpi
}  // namespace lpi
