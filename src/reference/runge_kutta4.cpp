#include "runge_kutta4.hpp"

namespace lpi {

RungeKutta4::RungeKutta4(std::size_t size)
    : k1_(size), k2_(size), k3_(size), k4_(size), stage_(size) {}

bool RungeKutta4::advance(Model &model, double *x, double dt, std::int64_t n) {
    const std::size_t size = k1_.size();
    for (std::int64_t step = 0; step < n; ++step) {
        model.vector_field(x, k1_.data());
        for (std::size_t i = 0; i < size; ++i) stage_[i] = x[i] + 0.5 * dt * k1_[i];
        model.vector_field(stage_.data(), k2_.data());
        for (std::size_t i = 0; i < size; ++i) stage_[i] = x[i] + 0.5 * dt * k2_[i];
        model.vector_field(stage_.data(), k3_.data());
        for (std::size_t i = 0; i < size; ++i) stage_[i] = x[i] + dt * k3_[i];
        model.vector_field(stage_.data(), k4_.data());
        for (std::size_t i = 0; i < size; ++i)
            x[i] += dt / 6.0 * (k1_[i] + 2.0 * k2_[i] + 2.0 * k3_[i] + k4_[i]);
        if ((step + 1) % kFiniteCheckInterval == 0 && !all_finite(x, size)) return false;
    }
    return all_finite(x, size);
}

}  // namespace lpi
