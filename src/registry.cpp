// The one list of what the layers above the core register with it: the
// baselines' method rows (after the core's splittings, in the order
// lpi_method_name lists them) and the model kinds a checkpoint can restore.
// Adding a baseline or a checkpointable model is one line here.
#include "baselines/implicit_midpoint.hpp"
#include "baselines/runge_kutta4.hpp"
#include "baselines/sine_euler_matrix_methods.hpp"
#include "core/checkpoint.hpp"
#include "core/methods.hpp"
#include "models/models.hpp"

namespace lpi {

void add_registered_methods(std::vector<Method> &table) {
    table.push_back(runge_kutta4_method());
    table.push_back(implicit_midpoint_method());
    for (Method &m : sine_euler_matrix_methods()) table.push_back(std::move(m));
}

const std::vector<CheckpointKind> &checkpoint_kinds() {
    static const std::vector<CheckpointKind> kinds = {
        rigid_body_checkpoint_kind(),
        pendulum_checkpoint_kind(),
        sine_euler_checkpoint_kind(),
    };
    return kinds;
}

}  // namespace lpi
