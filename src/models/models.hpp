// Factories of the built-in models. Each validates its parameters and throws
// lpi::Error with a specific message.
#pragma once

#include <memory>

#include "../core/checkpoint.hpp"
#include "../core/model.hpp"

namespace lpi {

std::unique_ptr<Model> make_rigid_body(double I1, double I2, double I3);
std::unique_ptr<Model> make_pendulum();

// The inertias of a rigid-body model; false when `model` is another kind.
bool rigid_body_inertia(const Model &model, double inertia[3]);

// The small built-in models keep their state compensated: the working layout
// is [x, carry], the value is x + carry (a double-double), and every flow adds
// an increment exactly but for u^2 |x|. Round-off in the Casimirs then has no
// bias and grows like sqrt(steps) times u times the flows' angles, not u
// (tests/test_invariants.c measures it).
void compensated_add(double &x, double &carry, double increment);

// Rotates (x_i, x_j) by angle a: x_i <- cos a x_i + sin a x_j,
// x_j <- -sin a x_i + cos a x_j, the exact flow of dx_i = w x_j, dx_j = -w x_i
// for time a / w.
void rotate_pair(double *x, double *carry, int i, int j, double angle);

// Base of the small models whose working state is [x (dim), carry (dim)].
constexpr std::size_t kMaxCompensatedDim = 8;
class CompensatedModel : public Model {
public:
    std::size_t state_size() const override { return 2 * dim(); }
    void to_public(const double *state, double *x) const override;
    void from_public(const double *x, double *state) const override;
    void vector_field(const double *state, double *rate) const override;

protected:
    // x + carry rounded to double: what energies and Casimirs are evaluated on.
    void value(const double *state, double *x) const;
    virtual void public_vector_field(const double *x, double *rate) const = 0;
};

// Throws LPI_ERR_INVALID unless every carry of a CompensatedModel's working
// state is a rounding remainder of its entry (what a checkpoint must hold).
void check_compensated_state(const Model &model, const double *state);

// How checkpoints restore each built-in kind (src/registry.cpp lists them).
CheckpointKind rigid_body_checkpoint_kind();
CheckpointKind pendulum_checkpoint_kind();
CheckpointKind sine_euler_checkpoint_kind();  // sine_euler_checkpoint.cpp

}  // namespace lpi
