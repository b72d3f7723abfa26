// How a checkpoint restores a sine-Euler system: its one parameter is N.
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "../core/error.hpp"
#include "models.hpp"
#include "sine_euler.hpp"

namespace lpi {

namespace {

int order_of(const std::vector<double> &p) {
    if (!(p[0] >= 0 && p[0] <= std::numeric_limits<std::int32_t>::max()) ||
        p[0] != std::floor(p[0]))
        fail(LPI_ERR_FORMAT, "sine-euler N is not an integer");
    return static_cast<int>(p[0]);
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
    return {"sine-euler", 1,
            [](const std::vector<double> &p) {
                const auto N = static_cast<std::uint64_t>(order_of(p));
                return 2 * N * N;
            },
            [](const std::vector<double> &p) { return make_sine_euler(order_of(p)); },
            check_modes};
}

}  // namespace lpi
