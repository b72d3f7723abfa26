// Classical fourth-order Runge-Kutta on the full vector field J(x) grad H(x):
// the baseline a user would otherwise pick. Not a Poisson map: Casimirs drift.
#pragma once

#include <vector>

#include "../core/integrator.hpp"

namespace lpi {

class RungeKutta4 final : public Integrator {
public:
    explicit RungeKutta4(std::size_t size);
    bool advance(Model &model, double *state, double dt, std::int64_t n) override;
    std::size_t evaluations_per_step() const override { return 4; }

private:
    std::vector<double> k1_, k2_, k3_, k4_, stage_;
};

}  // namespace lpi
