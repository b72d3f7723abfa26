#include "runge_kutta4.hpp"

#include "../core/integrator.hpp"
#include "../core/model.hpp"

namespace lpi {

namespace {

class RungeKutta4 final : public Integrator {
public:
    explicit RungeKutta4(std::size_t size) : size_(size), stages_(size) {}

    std::int64_t advance(Model &model, double *x, double dt, std::int64_t n,
                         StepsInProgress &progress) override {
        auto rate = [&model](const double *y, double *k) { model.vector_field(y, k); };
        return run_checked_steps(
            n, progress, [&](std::int64_t) { stages_.step(x, dt, rate); },
            [&] { return all_finite(x, size_); });
    }
    std::size_t evaluations_per_step() const override { return 4; }

private:
    std::size_t size_;
    RungeKutta4Stages<double> stages_;
};

std::unique_ptr<Integrator> make_runge_kutta4(const Method &, const Model &model,
                                              const ImplicitSettings &) {
    return std::make_unique<RungeKutta4>(model.state_size());
}

}  // namespace

Method runge_kutta4_method() {
    return baseline_method("rk4", 4, "classical Runge-Kutta (Kutta 1901); not a Poisson map",
                           make_runge_kutta4);
}

}  // namespace lpi
