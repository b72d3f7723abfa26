#include "implicit_midpoint.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "../core/integrator.hpp"
#include "../core/model.hpp"
#include "fixed_point.hpp"

namespace lpi {

namespace {

class ImplicitMidpoint final : public Integrator {
public:
    ImplicitMidpoint(std::size_t size, ImplicitSettings settings)
        : settings_(settings), midpoint_(size), rate_(size) {}

    std::int64_t advance(Model &model, double *x, double dt, std::int64_t n,
                         StepsInProgress &progress) override {
        const std::size_t size = midpoint_.size();
        // Counted over the whole call (its stretches between observations
        // are advances of their own), as isomp counts.
        if (progress.first == 1) call_iterations_ = 0, call_steps_ = 0;
        std::int64_t steps = 0;
        const std::int64_t found = run_checked_steps(
            n, progress,
            [&](std::int64_t) {
                ++steps;
                call_iterations_ += this->step(model, x, dt);
            },
            [&] { return all_finite(x, size); });
        call_steps_ += steps;
        average_iterations_ = static_cast<double>(call_iterations_) / static_cast<double>(call_steps_);
        return found;
    }

    // Vector-field evaluations per step, averaged over the last call: the
    // starting guess's and one an iteration.
    std::size_t evaluations_per_step() const override {
        return static_cast<std::size_t>(std::ceil(1.0 + std::max(1.0, average_iterations_)));
    }
    double average_iterations() const override { return average_iterations_; }
    void restore_average_iterations(double average) override { average_iterations_ = average; }

private:
    // One step; returns the iterations it took.
    int step(Model &model, double *x, double dt) {
        const std::size_t size = midpoint_.size();
        // Midpoint y solves y = x + (h/2) f(y); start from the explicit Euler guess.
        model.vector_field(x, rate_.data());
        for (std::size_t i = 0; i < size; ++i) midpoint_[i] = x[i] + 0.5 * dt * rate_[i];
        double largest = 0.0;
        for (std::size_t i = 0; i < size; ++i) largest = std::max(largest, std::fabs(x[i]));
        const FixedPointTest test(settings_, largest, 0.5 * dt, "implicit midpoint");
        bool converged = false;
        int iterations = 0;
        while (iterations < settings_.max_iterations && !converged) {
            model.vector_field(midpoint_.data(), rate_.data());
            double change = 0.0;
            for (std::size_t i = 0; i < size; ++i) {
                const double y = x[i] + 0.5 * dt * rate_[i];
                change = max_change(change, std::fabs(y - midpoint_[i]));
                midpoint_[i] = y;
            }
            ++iterations;
            converged = test.converged(change);
        }
        if (!converged) test.failed();
        for (std::size_t i = 0; i < size; ++i) x[i] = 2.0 * midpoint_[i] - x[i];
        return iterations;
    }

    ImplicitSettings settings_;
    std::vector<double> midpoint_, rate_;
    std::int64_t call_iterations_ = 0, call_steps_ = 0;
    double average_iterations_ = 0.0;
};

std::unique_ptr<Integrator> make_implicit_midpoint(const Method &, const Model &model,
                                                   const ImplicitSettings &implicit) {
    return std::make_unique<ImplicitMidpoint>(model.state_size(), implicit);
}

}  // namespace

Method implicit_midpoint_method() {
    return baseline_method(
        "implicit-midpoint", 2,
        "implicit midpoint rule, fixed-point iteration (Hairer, Lubich & Wanner, Geometric "
        "Numerical Integration (2006) sect. IV.4.2, VI.3); symplectic for canonical systems, not "
        "a Lie-Poisson map",
        make_implicit_midpoint);
}

}  // namespace lpi
