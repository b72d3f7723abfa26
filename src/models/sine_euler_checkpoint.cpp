// How a checkpoint restores a sine-Euler system. Its parameters are N alone
// for Euler's Hamiltonian (the checkpoints written before other Hamiltonians
// existed, and those of Euler since, byte for byte), or N, lambda (N^2) and f
// (2 N^2 interleaved) for any other.
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "../core/error.hpp"
#include "models.hpp"
#include "sine_euler.hpp"
#include "sine_euler/hamiltonian.hpp"

namespace lpi {

namespace {

// N, once the parameter count is checked against it.
int order_of(const std::vector<double> &p) {
    if (p.empty()) fail(LPI_ERR_FORMAT, "a sine-euler checkpoint gives no N");
    if (!(p[0] >= 0 && p[0] <= std::numeric_limits<std::int32_t>::max()) ||
        p[0] != std::floor(p[0]))
        fail(LPI_ERR_FORMAT, "sine-euler N is not an integer");
    const auto modes = static_cast<std::uint64_t>(p[0]) * static_cast<std::uint64_t>(p[0]);
    if (p.size() != 1 && p.size() - 1 != 3 * modes)
        fail(LPI_ERR_FORMAT, "a sine-euler checkpoint gives N alone or N, lambda (N^2) and f "
                             "(2 N^2): " + std::to_string(p.size()) + " parameters for N = " +
                                 std::to_string(static_cast<std::uint64_t>(p[0])));
    return static_cast<int>(p[0]);
}

std::unique_ptr<Model> build(const std::vector<double> &p) {
    const int N = order_of(p);
    std::unique_ptr<Model> model = make_sine_euler(N);
    if (p.size() > 1) {
        const std::size_t modes = static_cast<std::size_t>(N) * static_cast<std::size_t>(N);
        static_cast<SineEulerModel &>(*model).set_hamiltonian(
            sine_euler::Hamiltonian(N, p.data() + 1, modes, p.data() + 1 + modes, 2 * modes));
    }
    return model;
}

// The modes must pass lpi_sine_euler_set_modes: Hermitian and w_0 real, to
// its tolerance. The splitting flows keep them so to the bit (each mirror
// mode is written as the exact conjugate), but the rk4, implicit-midpoint and
// direct-eq5 baselines do not, so a checkpoint they leave cannot be held to
// bit-exact symmetry.
void check_modes(const Model &model, const double *state) {
    std::vector<double> x(model.dim());
    static_cast<const SineEulerModel &>(model).public_from_modes(state, x.data());
}

}  // namespace

CheckpointKind sine_euler_checkpoint_kind() {
    return {"sine-euler", kCheckedByKind,
            [](const std::vector<double> &p) {
                const auto N = static_cast<std::uint64_t>(order_of(p));
                return 2 * N * N;
            },
            build, check_modes};
}

}  // namespace lpi
