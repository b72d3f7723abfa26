#include "implicit_midpoint.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "../core/error.hpp"

namespace lpi {

ImplicitMidpoint::ImplicitMidpoint(std::size_t size, ImplicitSettings settings)
    : settings_(settings), midpoint_(size), next_(size), rate_(size) {}

std::size_t ImplicitMidpoint::evaluations_per_step() const {
    return static_cast<std::size_t>(std::ceil(std::max(1.0, average_iterations_)));
}

bool ImplicitMidpoint::advance(Model &model, double *x, double dt, std::int64_t n) {
    const std::size_t size = midpoint_.size();
    std::int64_t iterations = 0;
    for (std::int64_t step = 0; step < n; ++step) {
        // Midpoint y solves y = x + (h/2) f(y); start from the explicit Euler guess.
        model.vector_field(x, rate_.data());
        for (std::size_t i = 0; i < size; ++i) midpoint_[i] = x[i] + 0.5 * dt * rate_[i];
        double scale = 1.0;
        for (std::size_t i = 0; i < size; ++i) scale = std::max(scale, std::fabs(x[i]));
        bool converged = false;
        for (int k = 0; k < settings_.max_iterations && !converged; ++k) {
            model.vector_field(midpoint_.data(), rate_.data());
            ++iterations;
            double change = 0.0;
            for (std::size_t i = 0; i < size; ++i) {
                const double y = x[i] + 0.5 * dt * rate_[i];
                const double d = std::fabs(y - midpoint_[i]);
                if (d > change || std::isnan(d)) change = d;  // a NaN, once seen, stays
                midpoint_[i] = y;
            }
            if (!std::isfinite(change))
                fail(LPI_ERR_NO_CONVERGENCE,
                     "implicit midpoint: fixed-point iteration diverged at step " +
                         std::to_string(step) + " (dt too large for the iteration); state rolled back");
            converged = change <= settings_.tolerance * scale;
        }
        if (!converged)
            fail(LPI_ERR_NO_CONVERGENCE,
                 "implicit midpoint: fixed-point iteration did not converge in " +
                     std::to_string(settings_.max_iterations) + " iterations at step " +
                     std::to_string(step) + " (dt too large for the iteration, or raise the "
                     "limit); state rolled back");
        for (std::size_t i = 0; i < size; ++i) x[i] = 2.0 * midpoint_[i] - x[i];
        if ((step + 1) % kFiniteCheckInterval == 0 && !all_finite(x, size)) return false;
    }
    average_iterations_ = static_cast<double>(iterations) / static_cast<double>(n);
    return all_finite(x, size);
}

}  // namespace lpi
