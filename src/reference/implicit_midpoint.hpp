// The implicit midpoint rule on the full vector field, x' = x + h f((x + x')/2),
// solved by fixed-point iteration on the midpoint: the implicit (symplectic on
// canonical systems, but not Lie-Poisson) baseline a user would otherwise pick.
#pragma once

#include <vector>

#include "../core/integrator.hpp"

namespace lpi {

class ImplicitMidpoint final : public Integrator {
public:
    ImplicitMidpoint(std::size_t size, ImplicitSettings settings);
    bool advance(Model &model, double *state, double dt, std::int64_t n) override;
    // Vector-field evaluations per step, averaged over the last advance.
    std::size_t evaluations_per_step() const override;

private:
    ImplicitSettings settings_;
    std::vector<double> midpoint_, next_, rate_;
    double average_iterations_ = 0.0;
};

}  // namespace lpi
