#include "systems.hpp"

#include "fields.hpp"
#include "processes.hpp"

namespace lpi_cli {

namespace {

Handle with_state(Handle h, const std::vector<double> &x) {
    check(lpi_set_state(h.get(), x.data(), x.size()), h.get(), "set state");
    return h;
}

}  // namespace

Handle rigid_body(double I1, double I2, double I3, const std::vector<double> &m) {
    Handle h;
    check(lpi_rigid_body_create(h.out(), I1, I2, I3), nullptr, "create rigid body");
    return with_state(std::move(h), m);
}

Handle pendulum(const std::vector<double> &x) {
    Handle h;
    check(lpi_pendulum_create(h.out()), nullptr, "create pendulum");
    return with_state(std::move(h), x);
}

Handle sine_euler(int N, const std::function<std::vector<double>(int N)> &modes) {
    Handle h;
    check(create_sine_euler(h.out(), N), nullptr, "create sine-Euler");
    const std::vector<double> w = modes(N);
    check(lpi_sine_euler_set_modes(h.get(), w.data(), w.size()), h.get(), "set modes");
    return h;
}

Handle figure2_system() { return sine_euler(7, [](int) { return figure2_field(); }); }

std::string sine_euler_unavailable() {
    lpi_system *probe = nullptr;
    if (lpi_sine_euler_create(&probe, 3) == LPI_OK) {
        lpi_destroy(probe);
        return "";
    }
    return lpi_last_error(nullptr);
}

int product_energy(double u, double *out, void *) {
    *out = 0.02 * u + 0.01 * u * u;
    return 0;
}

int product_derivative(double u, double *out, void *) {
    *out = 0.02 + 0.02 * u;
    return 0;
}

}  // namespace lpi_cli
