// How sine-Euler's field is spread over P processes, and how it moves from
// one direction's lines to the next's.
//
// Layout of direction D (a piece, src/models/sine_euler/projective_line.hpp):
// the lines d = 1 .. M of D (M = (N-1)/2) are cut into P contiguous runs, one
// per process; process r holds the N modes d j + s k of each of its lines,
// element s of its line i at complex entry s * count + i (the layout of a
// transform block, so a block of lines is gathered by rows). Lines -d are the
// conjugates of lines d and are not held. Every process also holds the whole
// line through the origin {s k} (N modes): the flow of D leaves it fixed and
// needs all of it for its line spectrum.
//
// The working state of a process (doubles): [0] the index of the direction
// whose layout it holds, then line 0 (N complex, element s = mode s k), then
// its lines (count * N complex). The index travels with the state, so a copy
// (the rollback of a failed step, an observed step's copy) keeps its meaning.
//
// The exchange. Moving from direction D to D' is a linear bijection of
// Z_N^2: mode p = d' j' + s' k' lies on line v = sigma (p x k) of D at element
// u = sigma (j x p), both linear in (d', s'). Each mode of D' goes from the
// process that holds its line v (or -v, conjugated) to the one that holds
// its line d'; modes on line 0 of D are at hand everywhere. One MPI_Alltoallv
// carries all of them, and each process also sends every other the modes of
// the new line 0 that it holds (O(N) in all): one collective per flow. Both
// sides enumerate the modes from process r to process q in one order (by d'
// in q's lines, then d in r's lines, then v = d, -d, then s' solving
// gamma s' = v - delta(d') mod N), so nothing but values is sent, and the
// work is O(N^2 / P) per process. Values every process needs from a few
// (the Hamiltonian's weights on the new line 0, hamiltonian_share.hpp) ride
// along in the same collective.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "../models/sine_euler/projective_line.hpp"
#include "communicator.hpp"

namespace lpi {
namespace mpi {

struct LineOwnership {
    LineOwnership(int N, int processes);
    int N, M, P;
    std::vector<int> first;  // process r holds lines first[r] .. first[r+1]-1
    std::vector<int> owner;  // owner[d] for d = 1 .. M
    int count(int r) const { return first[r + 1] - first[r]; }
};

// Sizes of a process's working state.
inline std::size_t line0_entry() { return 1; }  // doubles before line 0
inline std::size_t slab_entry(int N) { return 1 + 2 * static_cast<std::size_t>(N); }
inline std::size_t local_state_size(int N, int count) {
    return slab_entry(N) + 2 * static_cast<std::size_t>(N) * count;
}

// The mode (a, b) of element s of line d of a direction.
inline void line_mode(const sine_euler::Direction &D, int N, int d, int s, int &a, int &b) {
    a = static_cast<int>((static_cast<std::int64_t>(d) * D.j1 + static_cast<std::int64_t>(s) * D.k1) % N);
    b = static_cast<int>((static_cast<std::int64_t>(d) * D.j2 + static_cast<std::int64_t>(s) * D.k2) % N);
}

// Values that travel with an exchange: each process sends its own to every
// process and receives everyone's, in rank order (an allgather inside the
// exchange's one collective). Complex entries: 2 doubles each.
struct Riders {
    std::vector<double> own;       // this process's values
    std::vector<int> counts;       // entries each process sends (every process knows all)
    std::vector<double> gathered;  // after the exchange: every process's, in rank order
};

// Moves a process's working state from one direction's layout to another's,
// with buffers kept between flows.
class LineExchange {
public:
    LineExchange(const Communicator &comm, const LineOwnership &lines)
        : comm_(comm), lines_(lines), held_(most_line0_modes_held()),
          first_solution_(static_cast<std::size_t>(lines.N)), nu_multiple_(static_cast<std::size_t>(lines.N)) {}
    // state holds the layout of `from`; afterwards that of `to`. With riders,
    // their values travel in the same collective; when from and to are the
    // same direction only they travel.
    void move(const sine_euler::Direction &from, std::size_t from_index,
              const sine_euler::Direction &to, std::size_t to_index, double *state,
              Riders *riders = nullptr);
    // Sizes every buffer of move (and the riders', when given) for the
    // largest exchange this process can make, so that a move allocates
    // nothing: a step reserves before its first flow, where a failure is
    // agreed on by every process.
    void reserve(Riders *riders = nullptr);

private:
    void exchange_riders(Riders &riders);       // the riders alone
    void gather_riders(Riders &riders) const;   // from receive_, after the collective
    static constexpr std::uint64_t kRider = UINT64_MAX;  // a target: a rider, not a state entry

    const Communicator &comm_;
    const LineOwnership &lines_;
    std::vector<double> send_, receive_, old_line0_;
    std::vector<std::uint64_t> targets_;  // complex entry of the state for each value received
    std::vector<int> send_counts_, send_offsets_, receive_counts_, receive_offsets_;
    std::vector<std::size_t> rider_offsets_;  // where each process's riders start in receive_
    std::size_t most_line0_modes_held() const;
    std::size_t most_sent() const;      // complex entries, all processes together
    std::size_t most_received() const;  // complex entries
    void check_reserved(const Riders *riders) const;
    std::size_t held_;  // most_line0_modes_held()
    // Where the new line 0's modes come from (see move).
    std::vector<int> origin_source_, origin_order_, origin_first_, next_origin_;
    // The transition's tables (N entries each), filled by each move.
    std::vector<int> first_solution_, nu_multiple_;
};

}  // namespace mpi
}  // namespace lpi
