// How a System advances its state: an Integrator is built from a Method for a
// Model. Splitting methods compose the model's exact piece flows; reference
// methods (src/reference) integrate the full vector field.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include "methods.hpp"
#include "model.hpp"

namespace lpi {

class Integrator {
public:
    virtual ~Integrator() = default;
    // Advances n >= 1 steps of size dt in place. Returns false as soon as the
    // state is found non-finite (checked every few steps and at the end); the
    // caller then restores its copy.
    virtual bool advance(Model &model, double *state, double dt, std::int64_t n) = 0;
    // Piece flows (or vector-field evaluations) per step in a long run.
    virtual std::size_t evaluations_per_step() const = 0;
};

// How implicit methods solve their equations (fixed-point iteration).
struct ImplicitSettings {
    double tolerance = 1e-13;  // on max|increment| relative to max(1, max|x|)
    int max_iterations = 100;
};

std::unique_ptr<Integrator> make_integrator(const Method &method, const Model &model,
                                            const ImplicitSettings &implicit = {});

bool all_finite(const double *x, std::size_t n);

// How often long runs look for a non-finite state, in steps.
constexpr std::int64_t kFiniteCheckInterval = 256;

}  // namespace lpi
