// The Hamiltonian of a sine-Euler system spread over processes
// (sine_euler/hamiltonian.hpp), itself spread: no process holds lambda or f
// whole. They are kept in the layout of the reference direction (0,1), piece
// 0: mode (a, b) is element b of line a, line -a is the conjugate of line a
// (lambda is symmetric, f Hermitian). A process holds, for the lines of that
// direction it owns (LineOwnership), lambda, f and the index of the piece that
// owns each mode (projective_line.hpp), and for line 0 (the modes (0, b),
// owned by piece 0) lambda and f: O(N^2 / P + N) numbers.
//
// The flow of a direction D needs the weights of the modes on D's line
// through the origin, {s k}, and whether D owns them; every process needs
// them, and they lie on lines of the reference direction spread over all
// processes. Their holders send them with the exchange that moves the state
// to D's layout (line_exchange.hpp, Riders): N values in all per flow.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "../models/sine_euler/hamiltonian.hpp"
#include "../models/sine_euler/projective_line.hpp"
#include "communicator.hpp"
#include "line_exchange.hpp"

namespace lpi {
namespace mpi {

// The weights of D's line through the origin: element s is mode s k.
struct OriginLineWeights {
    std::vector<double> lambda;         // N
    std::vector<double> f;              // 2 N, empty when f = 0
    std::vector<unsigned char> owned;   // N: D owns mode s k
};

class HamiltonianShare {
public:
    // Euler's Hamiltonian, for the lines of the reference direction that
    // process `rank` holds. The owners come from read_pieces.
    HamiltonianShare(int N, const LineOwnership &lines, int rank);

    // Goes through the pieces (for_each_direction), notes which piece owns
    // each of this process's modes, and hands every direction, without its
    // ownership table, to keep(), in order. Holds O(N^2 / P + N) meanwhile.
    void read_pieces(const std::function<void(sine_euler::Direction &&)> &keep);

    // This process's share of H (given whole on every process): made by
    // share_of, which allocates, and put in place by keep, which cannot fail
    // (so that a spread model agrees on the first before the second).
    struct Share {
        std::vector<double> lambda, f;
        bool euler = true;
    };
    Share share_of(const sine_euler::Hamiltonian &H) const;
    void keep(Share &share) noexcept;
    bool is_default() const { return euler_; }
    // The whole Hamiltonian on every process (collective; O(N^2) on request).
    sine_euler::Hamiltonian whole(const Communicator &comm) const;

    // What this process sends for the flow of piece `index` (direction D):
    // lambda and ownership, then f when there is one, of the modes of D's
    // line 0 that it holds, ascending in s; and the counts of every process.
    void origin_line_riders(const sine_euler::Direction &D, std::size_t index, Riders &riders) const;
    // The weights of D's line 0 from the riders gathered by the exchange.
    void read_origin_line(const sine_euler::Direction &D, std::size_t index, const Riders &riders,
                          OriginLineWeights &out) const;
    // Sizes out and the scratch of read_origin_line, so that it allocates
    // nothing during a step (LineExchange::reserve).
    void reserve(OriginLineWeights &out) const;

    // The term of H of the mode at complex entry e of a working state in the
    // reference layout (line 0: e = s; line first + i: e = N + s * count + i):
    // 1/2 lambda |z|^2 + Re(conj(f) z).
    double term(std::size_t e, const double *z) const {
        double h = sine_euler::half_weighted_norm2(lambda_[e], z);
        if (!f_.empty()) h += f_[2 * e] * z[0] + f_[2 * e + 1] * z[1];
        return h;
    }

private:
    // Where mode (a, b), a != 0, is held: its line of the reference
    // direction (1 .. M) and its element there, conjugated when on line -a.
    struct Place {
        int line, element;
        bool mirrored;
    };
    Place place(int a, int b) const;
    void record_owners(std::size_t index, const sine_euler::Direction &D);
    // Complex entry of a held mode of line d (held here), element s.
    std::size_t entry(int d, int s) const {
        return static_cast<std::size_t>(N_) + static_cast<std::size_t>(s) * mine_ + (d - first_);
    }
    // Calls f(s, holder) for s = 1 .. N-1 with the process that holds mode
    // s k of D, or -1 when it is on line 0 of the reference direction (held
    // everywhere).
    template <class F>
    void for_each_origin_mode(const sine_euler::Direction &D, F &&f) const;

    int N_, M_;
    const LineOwnership &lines_;
    int rank_, first_, mine_;
    bool euler_ = true;
    std::vector<double> lambda_;        // N (1 + mine) entries: line 0, then the lines held
    std::vector<double> f_;             // 2 N (1 + mine), empty when f = 0
    std::vector<std::uint32_t> owner_;  // piece owning each entry of the lines held
    mutable std::vector<std::size_t> rider_start_;  // read_origin_line's scratch: P + 1
};

}  // namespace mpi
}  // namespace lpi
