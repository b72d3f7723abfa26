// Classical fourth-order Runge-Kutta, written once: the rk4 baseline on the
// full vector field J(x) grad H(x) (what a user would otherwise pick; not a
// Poisson map, so Casimirs drift), and the stages that the sine-Euler matrix
// baselines run on the modes (direct-eq5) and on the matrix W (rk4-matrix).
#pragma once

#include <cstddef>
#include <vector>

#include "../core/methods.hpp"

namespace lpi {

// The stage vectors of RK4 on n values of type T (double, or
// std::complex<double> for a matrix).
template <class T>
class RungeKutta4Stages {
public:
    explicit RungeKutta4Stages(std::size_t n) : k1_(n), k2_(n), k3_(n), k4_(n), stage_(n) {}

    // One step x <- x + dt/6 (k1 + 2 k2 + 2 k3 + k4); rate(y, k) writes the
    // vector field at y to k.
    template <class Rate>
    void step(T *x, double dt, Rate &&rate) {
        const std::size_t n = k1_.size();
        rate(x, k1_.data());
        for (std::size_t i = 0; i < n; ++i) stage_[i] = x[i] + 0.5 * dt * k1_[i];
        rate(stage_.data(), k2_.data());
        for (std::size_t i = 0; i < n; ++i) stage_[i] = x[i] + 0.5 * dt * k2_[i];
        rate(stage_.data(), k3_.data());
        for (std::size_t i = 0; i < n; ++i) stage_[i] = x[i] + dt * k3_[i];
        rate(stage_.data(), k4_.data());
        for (std::size_t i = 0; i < n; ++i)
            x[i] += dt / 6.0 * (k1_[i] + 2.0 * k2_[i] + 2.0 * k3_[i] + k4_[i]);
    }

private:
    std::vector<T> k1_, k2_, k3_, k4_, stage_;
};

// The rk4 row of the method table (listed in src/registry.cpp).
Method runge_kutta4_method();

}  // namespace lpi
