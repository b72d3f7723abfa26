// The distributed sine-Euler model. A flow of direction D moves the working
// state to D's layout (one exchange, line_exchange.hpp), computes the line
// spectrum from line 0, which every process holds, and integrates the lines
// held here block by block exactly as the model of one process does: gather,
// forward transform, phase (apply_phase), backward transform, and the
// increment added to the modes. While stepping a process holds its lines,
// line 0, its share of the Hamiltonian (hamiltonian_share.hpp) and O(N)
// tables; the whole field is gathered only on request (getters, Casimirs,
// checkpoints).
#include "sine_euler_mpi.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "../core/integrator.hpp"
#include "../models/sine_euler.hpp"
#include "../models/sine_euler/coordinates.hpp"
#include "../models/sine_euler/indexing.hpp"
#include "../models/sine_euler/kernels.hpp"
#include "../models/sine_euler/line_flows.hpp"
#include "../models/sine_euler/transforms.hpp"
#include "communicator.hpp"
#include "hamiltonian_share.hpp"
#include "line_exchange.hpp"
#include "lpi_config.h"

namespace lpi {

namespace {

using namespace sine_euler;
using mpi::Communicator;
using mpi::LineExchange;
using mpi::HamiltonianShare;
using mpi::LineOwnership;
using mpi::OriginLineWeights;
using mpi::Riders;

// FNV-1a of `size` bytes: the processes compare their inputs.
long long fingerprint(const void *data, std::size_t size) {
    std::uint64_t h = 1469598103934665603ull;
    const auto *bytes = static_cast<const unsigned char *>(data);
    for (std::size_t i = 0; i < size; ++i) h = (h ^ bytes[i]) * 1099511628211ull;
    return static_cast<long long>(h);
}

class SineEulerMpi final : public SineEulerModel {
public:
    SineEulerMpi(int N, std::shared_ptr<const Communicator> comm)
        : N_(N), eps_(2.0 * std::acos(-1.0) / N), comm_(std::move(comm)),
          lines_(N, comm_->size()), mine_(lines_.count(comm_->rank())),
          first_(lines_.first[comm_->rank()]), exchange_(*comm_, lines_), share_(N, lines_, comm_->rank()) {
        share_.read_pieces([&](Direction &&D) { dirs_.push_back(std::move(D)); });
    }

    const char *kind() const override { return "sine-euler"; }
    int truncation() const override { return N_; }
    std::size_t dim() const override { return static_cast<std::size_t>(N_) * N_; }
    std::size_t state_size() const override { return mpi::local_state_size(N_, mine_); }

    std::vector<std::string> split_names() const override { return split_.names(); }
    void set_split(const std::string &name) override { split_.select(name, kind()); }
    std::string split() const override { return split_.current(); }
    std::size_t piece_count() const override { return dirs_.size(); }
    // As the model of one process stores them: N, and lambda and f when they
    // are not Euler's.
    std::vector<double> checkpoint_parameters() const override {
        std::optional<Hamiltonian> H;
        if (!share_.is_default()) H.emplace(hamiltonian());
        std::vector<double> p;
        comm_->agree([&] {  // it allocates: one outcome on every process
            p = {double(N_)};
            if (!H) return;
            const std::vector<double> lambda_f = H->parameters();
            p.insert(p.end(), lambda_f.begin(), lambda_f.end());
        });
        return p;
    }
    Hamiltonian hamiltonian() const override { return share_.whole(*comm_); }
    void set_hamiltonian(Hamiltonian H) override {
        if (H.truncation() != N_)
            fail(LPI_ERR_INTERNAL, "a Hamiltonian of N = " + std::to_string(H.truncation()) +
                                       " given to a system of N = " + std::to_string(N_));
        std::vector<double> p;
        comm_->agree([&] { p = H.parameters(); });
        require_same_input(p.data(), p.size(), "Hamiltonian (lambda and f)");
        // Made, and agreed on, before it is put in place: no process keeps
        // another Hamiltonian than the rest when one fails to allocate.
        HamiltonianShare::Share share;
        comm_->agree([&] { share = share_.share_of(H); });
        share_.keep(share);
        origin_piece_ = kNoPiece;
    }

    void set_threads(int n) override {
        if (n < 1) fail(LPI_ERR_INVALID, "thread count must be >= 1, got " + std::to_string(n));
#if !LPI_HAVE_OPENMP
        if (n > 1) fail(LPI_ERR_UNSUPPORTED, "threads need OpenMP; this build has none (one thread only)");
#endif
        // The library's threads exist while this one makes MPI calls.
        if (n > 1 && !comm_->allows_threads())
            fail(LPI_ERR_UNSUPPORTED, "threads within a process need MPI initialised with MPI_Init_thread "
                                      "at MPI_THREAD_FUNNELED or higher (MPI_Query_thread gives less)");
        threads_ = n;
    }

    // ---- spread over processes ------------------------------------------
    bool distributed() const override { return true; }
    bool finite(const double *state) const override {
        return comm_->all(all_finite(state, state_size()));
    }
    std::vector<double> whole_state(const double *state) const override;
    void on_one_process(ActionRef action) const override { comm_->on_root(action); }
    bool on_any_process(bool value) const override { return !comm_->all(!value); }
    void agree_on_every_process(ActionRef action) const override { comm_->agree(action); }
    void require_same_on_every_process(const void *bytes, std::size_t size, const char *what) const override {
        comm_->require_same(fingerprint(bytes, size), what);
    }
    std::vector<double> local_state(const double *modes, std::size_t direction) const;

    void to_public(const double *state, double *x) const override {
        public_from_state(N_, whole_state(state).data(), x);
    }
    // The conversions allocate (and a grid plans its FFT), which may fail on
    // one process alone: each is agreed on before the call goes on to its
    // next collective.
    void from_public(const double *x, double *state) const override {
        require_same_input(x, dim(), "state");
        comm_->agree([&] {
            std::vector<double> modes(2 * dim());
            state_from_public(N_, x, modes.data());
            const std::vector<double> local = local_state(modes.data(), 0);
            std::copy(local.begin(), local.end(), state);
        });
    }
    void public_from_modes(const double *modes, double *x) const override {
        require_same_input(modes, 2 * dim(), "modes");
        comm_->agree([&] { sine_euler::public_from_modes(N_, modes, x); });
    }
    void public_from_grid(const double *grid, double *x) const override {
        require_same_input(grid, dim(), "grid");
        comm_->agree([&] { sine_euler::public_from_grid(N_, grid, x); });
    }
    // Computed from the whole field on rank 0 and sent to every process, so
    // that every process returns the same bits.
    void grid(const double *state, double *out) const override {
        const std::vector<double> modes = whole_state(state);
        comm_->on_root([&] { grid_from_modes(N_, modes.data(), out); });
        comm_->broadcast(out, dim());
    }
    void casimirs(const double *state, double *out) const override {
        const std::vector<double> modes = whole_state(state);
        comm_->on_root([&] { sine_euler_spectrum(N_, modes.data(), out); });
        comm_->broadcast(out, casimir_count());
    }
    std::vector<double> casimir_traces(const double *state, int kmax) const override {
        const std::vector<double> modes = whole_state(state);
        std::vector<double> traces;
        comm_->on_root([&] { traces = sine_euler_traces(N_, modes.data(), kmax); });
        double count = static_cast<double>(traces.size());  // at most kmax < 2^31: exact
        comm_->broadcast(&count, 1);
        comm_->agree([&] { traces.resize(static_cast<std::size_t>(count)); });
        comm_->broadcast(traces.data(), traces.size());
        return traces;
    }
    std::size_t casimir_count() const override { return static_cast<std::size_t>(N_); }
    double energy(const double *state) const override;
    double enstrophy(const double *state) const override {
        // Halved before the sum, as on one process (SineEuler::enstrophy).
        return sum_over_field(state, [](std::size_t, const double *z) { return 0.5 * z[0] * z[0] + 0.5 * z[1] * z[1]; });
    }
    // Only the baselines ask for it, and they are refused for a model spread
    // over processes (make_integrator).
    void vector_field(const double *, double *) const override {
        fail(LPI_ERR_UNSUPPORTED, "the vector field of a sine-Euler system spread over processes");
    }

    // The plans, and every buffer of the exchange and of line 0's weights
    // at its largest: a flow then allocates nothing, and FFTW has room for
    // what its executions allocate.
    void prepare_step() override {
        transforms();
        exchange_.reserve(&riders_);
        share_.reserve(origin_);
        require_fftw_execution_headroom(N_, threads_);
    }
    void flow(std::size_t piece, double t, double *state) override;
    TransformTiming time_transforms(std::size_t flows_per_step, std::int64_t steps) override;

    // Measured plans may differ between processes; that changes only the
    // rounding of each process's own lines (the phases come from the
    // heuristic's plan on every process).
    void set_planning(FftPlanning planning) override {
        std::unique_ptr<LineTransforms> planned;
        comm_->agree([&] {  // the new plans in place on every process, or on none
            planned = std::make_unique<LineTransforms>(N_, mine_, planning);
            planned->reserve_threads(static_cast<std::size_t>(threads_));
        });
        transforms_ = std::move(planned);
        planning_ = planning;
    }
    FftPlanning planning() const override { return planning_; }

private:
    LineTransforms &transforms();
    bool line_spectrum(const double *line0);
    template <class Term>
    double sum_over_field(const double *state, Term &&term) const;
    void require_same_input(const double *x, std::size_t n, const char *what) const {
        require_same_on_every_process(x, n * sizeof(double), what);
    }

    int N_;
    double eps_;
    std::shared_ptr<const Communicator> comm_;
    LineOwnership lines_;
    int mine_, first_;  // this process's lines: first_ .. first_ + mine_ - 1
    std::vector<Direction> dirs_;  // without their ownership tables (share_ keeps this process's)
    mutable LineExchange exchange_;  // its buffers only change in a const call (energy)
    HamiltonianShare share_;
    // The weights of line 0 of piece origin_piece_, fetched with the exchange.
    static constexpr std::size_t kNoPiece = SIZE_MAX;
    std::size_t origin_piece_ = kNoPiece;
    OriginLineWeights origin_;
    Riders riders_;
    SplitChoice split_{{"directions"}};
    int threads_ = 1;
    FftPlanning planning_ = FftPlanning::Estimate;
    std::unique_ptr<LineTransforms> transforms_;  // this process's lines, planned on the first flow
};

LineTransforms &SineEulerMpi::transforms() {
    if (!transforms_) transforms_ = std::make_unique<LineTransforms>(N_, mine_, planning_);
    transforms_->reserve_threads(static_cast<std::size_t>(threads_));
    return *transforms_;
}

std::vector<double> SineEulerMpi::whole_state(const double *state) const {
    const Direction &D = dirs_[static_cast<std::size_t>(state[0])];
    const int P = lines_.P;
    std::vector<int> counts, offsets;
    std::vector<double> lines, modes;
    // Allocated, and agreed on, before the collective.
    comm_->agree([&] {
        counts.resize(P), offsets.resize(P);
        lines.resize(2 * static_cast<std::size_t>(N_) * lines_.M);
        modes.resize(2 * dim());
    });
    for (int r = 0; r < P; ++r) {
        counts[r] = lines_.count(r) * N_;
        offsets[r] = (lines_.first[r] - 1) * N_;
    }
    comm_->allgatherv(state + mpi::slab_entry(N_), mine_ * N_, lines.data(), counts, offsets);
    const double *line0 = state + mpi::line0_entry();
    for (int s = 0; s < N_; ++s) {
        int a, b;
        mpi::line_mode(D, N_, 0, s, a, b);
        modes[2 * mode_index(a, b, N_)] = line0[2 * s];
        modes[2 * mode_index(a, b, N_) + 1] = line0[2 * s + 1];
    }
    for (int r = 0; r < P; ++r) {
        const double *slab = lines.data() + 2 * static_cast<std::size_t>(offsets[r]);
        const int count = lines_.count(r);
        for (int i = 0; i < count; ++i)
            for (int s = 0; s < N_; ++s) {
                int a, b;
                mpi::line_mode(D, N_, lines_.first[r] + i, s, a, b);
                const double *z = slab + 2 * (static_cast<std::size_t>(s) * count + i);
                double *w = modes.data() + 2 * mode_index(a, b, N_);
                double *m = modes.data() + 2 * mirror_index(a, b, N_);
                w[0] = z[0], w[1] = z[1];
                m[0] = z[0], m[1] = -z[1];
            }
    }
    return modes;
}

std::vector<double> SineEulerMpi::local_state(const double *modes, std::size_t direction) const {
    const Direction &D = dirs_[direction];
    std::vector<double> state(state_size());
    state[0] = static_cast<double>(direction);
    double *line0 = state.data() + mpi::line0_entry(), *slab = state.data() + mpi::slab_entry(N_);
    for (int s = 0; s < N_; ++s) {
        int a, b;
        mpi::line_mode(D, N_, 0, s, a, b);
        line0[2 * s] = modes[2 * mode_index(a, b, N_)];
        line0[2 * s + 1] = modes[2 * mode_index(a, b, N_) + 1];
        for (int i = 0; i < mine_; ++i) {
            mpi::line_mode(D, N_, first_ + i, s, a, b);
            const std::size_t e = static_cast<std::size_t>(s) * mine_ + i;
            slab[2 * e] = modes[2 * mode_index(a, b, N_)];
            slab[2 * e + 1] = modes[2 * mode_index(a, b, N_) + 1];
        }
    }
    return state;
}

// The sum of term(e, z) over the modes z of the field held in `state` (e:
// the complex entry after the index): this process's lines count twice
// (their conjugates -d are not held), line 0 is counted by rank 0; the
// partial sums are added in rank order, the same on every process.
template <class Term>
double SineEulerMpi::sum_over_field(const double *state, Term &&term) const {
    const double *entries = state + mpi::line0_entry();
    double sum = 0.0;
    for (std::size_t e = N_; e < static_cast<std::size_t>(N_) * (1 + mine_); ++e) sum += 2.0 * term(e, entries + 2 * e);
    if (comm_->rank() == 0)
        for (std::size_t e = 0; e < static_cast<std::size_t>(N_); ++e) sum += term(e, entries + 2 * e);
    double total = 0.0;
    for (double part : comm_->allgather(sum)) total += part;
    return total;
}

// H in the layout of the reference direction, where the share of the
// Hamiltonian is held: a copy of the state is moved there.
double SineEulerMpi::energy(const double *state) const {
    // The copy and the exchange's buffers, agreed on before the exchange.
    std::vector<double> reference;
    comm_->agree([&] {
        reference.assign(state, state + state_size());
        exchange_.reserve();
    });
    const std::size_t held = static_cast<std::size_t>(state[0]);
    exchange_.move(dirs_[held], held, dirs_[0], 0, reference.data());
    return sum_over_field(reference.data(), [&](std::size_t e, const double *z) { return share_.term(e, z); });
}

// b_s = lambda_sk w_sk + f_sk on the modes the flow's piece owns (origin_),
// B = FFT(b), as the model of one process computes it. False when every b_s
// is zero.
bool SineEulerMpi::line_spectrum(const double *line0) {
    double *b = transforms_->spectrum();
    const double *lambda = origin_.lambda.data(), *f = origin_.f.empty() ? nullptr : origin_.f.data();
    bool active = false;
    for (int s = 0; s < N_; ++s) {
        if (origin_.owned[s]) {
            b[2 * s] = line0[2 * s] * lambda[s];
            b[2 * s + 1] = line0[2 * s + 1] * lambda[s];
            if (f) {
                b[2 * s] += f[2 * s];
                b[2 * s + 1] += f[2 * s + 1];
            }
            active = active || b[2 * s] != 0.0 || b[2 * s + 1] != 0.0;
        } else {
            b[2 * s] = b[2 * s + 1] = 0.0;
        }
    }
    if (!active) return false;
    transforms_->transform_spectrum();
    return true;
}

void SineEulerMpi::flow(std::size_t piece, double t, double *state) {
    transforms();
    const std::size_t held = static_cast<std::size_t>(state[0]);
    const Direction &D = dirs_[piece];
    // The weights of D's line 0 travel with the exchange, unless held already.
    const bool fetch = origin_piece_ != piece;
    if (fetch) share_.origin_line_riders(D, piece, riders_);
    exchange_.move(dirs_[held], held, D, piece, state, fetch ? &riders_ : nullptr);
    if (fetch) {
        origin_piece_ = kNoPiece;
        share_.read_origin_line(D, piece, riders_, origin_);
        origin_piece_ = piece;
    }
    if (!line_spectrum(state + mpi::line0_entry())) return;
    const double factor = t / (2.0 * eps_);
    double *slab = state + mpi::slab_entry(N_);
    // Block b of this process's lines: gathered from the rows of the slab,
    // transformed, multiplied by the lines' (exp(t Lambda_l) - 1) / N,
    // transformed back and added to the modes.
    const std::size_t row = 2 * static_cast<std::size_t>(mine_);
    run_line_flows(
        *transforms_, N_, mine_, threads_, factor,
        [&](int b, double *x) {
            const int i0 = b * kBlock, count = lines_in_block(mine_, b);
            for (int s = 0; s < N_; ++s)
                std::memcpy(x + 2 * static_cast<std::size_t>(s) * count, slab + s * row + 2 * i0,
                            sizeof(double) * 2 * count);
        },
        [&](int b, double *x) {
            flow_block(*transforms_, N_, first_ + b * kBlock, lines_in_block(mine_, b), -D.sigma, x);
        },
        [&](int b, double *x) {
            const int i0 = b * kBlock, count = lines_in_block(mine_, b);
            for (int s = 0; s < N_; ++s) {
                double *z = slab + s * row + 2 * i0;
                const double *increment = x + 2 * static_cast<std::size_t>(s) * count;
                for (int i = 0; i < 2 * count; ++i) z[i] = z[i] + increment[i];
            }
        });
}

// The transforms of this process's lines alone; the slowest process's time.
TransformTiming SineEulerMpi::time_transforms(std::size_t flows_per_step, std::int64_t steps) {
    const std::size_t flows = flow_count(flows_per_step, steps);
    const double seconds = time_line_transforms(transforms(), N_, mine_, threads_, flows);
    const double per_step = static_cast<double>(steps);
    return {comm_->max(seconds) / per_step, static_cast<double>(flows) * (1.0 + 2.0 * lines_.M) / per_step};
}

}  // namespace

std::unique_ptr<Model> make_sine_euler_mpi(int N, std::shared_ptr<const mpi::Communicator> communicator) {
    const std::vector<long long> &orders = communicator->allgather(static_cast<long long>(N));
    // Compared with rank 0's, so that every process names the same pair.
    for (std::size_t rank = 1; rank < orders.size(); ++rank)
        if (orders[rank] != orders[0])
            fail(LPI_ERR_INVALID, "the processes passed different N (" + std::to_string(orders[0]) +
                                      " on rank 0, " + std::to_string(orders[rank]) + " on rank " +
                                      std::to_string(rank) + ")");
    if (N < 3 || N % 2 == 0)
        fail(LPI_ERR_INVALID, "N must be odd and >= 3 (Zeitlin's su(N) truncation), got " +
                                  std::to_string(N));
    std::unique_ptr<Model> model;
    communicator->agree([&] {
        // This process's share, refused before anything is allocated: its
        // lines and line 0, N complex modes each, in two working states and
        // the two buffers of an exchange, and lambda and f of as many modes.
        const double M = (N - 1) / 2, P = communicator->size(), lines = std::ceil(M / P) + 1;
        const double bytes = static_cast<double>(N) * lines * (4 * 2 + 3) * sizeof(double);
        char text[160];
        std::snprintf(text, sizeof text,
                      "sine-Euler N = %d over %d processes needs about %.3g bytes (%.3g GiB) on each",
                      N, communicator->size(), bytes, bytes / (1024.0 * 1024.0 * 1024.0));
        require_physical_memory(bytes, text);
        model = std::make_unique<SineEulerMpi>(N, communicator);
    });
    return model;
}

std::vector<double> local_state_of_modes(const Model &model, const double *modes) {
    return static_cast<const SineEulerMpi &>(model).local_state(modes, 0);
}

}  // namespace lpi
