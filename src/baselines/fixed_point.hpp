// The stopping test of the implicit baselines' fixed-point iterations
// (implicit-midpoint, isomp), written once.
#pragma once

#include <cfloat>
#include <cmath>
#include <cstdint>

#include "../core/integrator.hpp"

namespace lpi {

// The largest change of an iteration so far, updated by one more
// component's change d: a NaN, once seen, stays.
inline double max_change(double change, double d) {
    return d > change || std::isnan(d) ? d : change;
}

// One step's test: the iteration has converged when its largest change is at
// most tolerance * max|x| (lpi_set_implicit_options), x the state the step
// starts from: relative at every size (an absolute floor of tolerance, as
// max(1, max|x|) gave, let a state of 1e-10 stop after one iteration, 2e-2
// off), down to the noise of subnormal arithmetic: where the vector field's
// products underflow (a quadratic field below about 1e-154) their roundings
// are DBL_TRUE_MIN's, and the change they make, `step_scale` (the step's
// factor on them: dt / 2 for the midpoint) times 2^30 of those, is a floor
// no iteration goes below (implicit-midpoint on sine-Euler at 1e-158 failed
// to converge in 10^4 iterations). The bound is formed once per step; where
// the product overflows, the true bound exceeds every double and DBL_MAX
// stands for it, so that the test never compares against +inf.
class FixedPointTest {
public:
    // The failures name the method; the caller's report adds the step.
    FixedPointTest(const ImplicitSettings &settings, double largest, double step_scale, const char *method)
        : settings_(settings), method_(method) {
        const double bound = std::fmax(settings.tolerance * largest, 0x1p30 * DBL_TRUE_MIN * std::fabs(step_scale));
        bound_ = std::isfinite(bound) ? bound : DBL_MAX;
    }

    // Whether an iteration whose largest change is `change` has converged;
    // LPI_ERR_NO_CONVERGENCE when it diverged (a change that is not finite).
    bool converged(double change) const {
        if (!std::isfinite(change)) diverged();
        return change <= bound_;
    }

    // LPI_ERR_NO_CONVERGENCE: no convergence in settings.max_iterations.
    [[noreturn]] void failed() const;

private:
    [[noreturn]] void diverged() const;

    const ImplicitSettings &settings_;
    const char *method_;
    double bound_;
};

}  // namespace lpi
