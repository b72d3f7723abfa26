#include "scenes.hpp"

#include <cmath>
#include <cstdio>

#include "fields.hpp"

namespace lpi_cli {

namespace {

// The moment scene's Hamiltonian, split as in the paper: a nearly harmonic
// ensemble with weak quartic coupling,
// H = V(x1, x4) + T(x3, x8) + P(x1 x3) with V = x1/2 + x1^2/100 + x4/100,
// T = x3/2 + x3^2/100 + x8/100 and P(u) = u/50 + u^2/100.
int potential_gradient(size_t, const double *x, double *g, void *) {
    g[0] = 0.5 + 0.02 * x[0];
    g[1] = 0.01;
    return 0;
}
int potential_energy(size_t, const double *x, double *h, void *) {
    *h = 0.5 * x[0] + 0.01 * x[0] * x[0] + 0.01 * x[1];
    return 0;
}
int product_h(double u, double *out, void *) {
    *out = 0.02 * u + 0.01 * u * u;
    return 0;
}
int product_dh(double u, double *out, void *) {
    *out = 0.02 + 0.02 * u;
    return 0;
}

std::string format_number(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    return text;
}

std::string sine_euler_unavailable() {
    lpi_system *probe = nullptr;
    if (lpi_sine_euler_create(&probe, 3) == LPI_OK) {
        lpi_destroy(probe);
        return "";
    }
    return lpi_last_error(nullptr);
}

Handle with_state(Handle h, const std::vector<double> &x) {
    check(lpi_set_state(h.get(), x.data(), x.size()), h.get(), "set state");
    return h;
}

}  // namespace

std::vector<Scene> builtin_scenes(const SceneOptions &options) {
    std::vector<Scene> scenes;
    {
        Scene s;
        s.name = "rigid-body";
        const double I1 = options.inertia[0], I2 = options.inertia[1], I3 = options.inertia[2];
        s.description = "free rigid body, I = (" + format_number(I1) + ", " + format_number(I2) + ", " +
                        format_number(I3) + "), m(0) = (1, 0.5, -0.3)";
        s.create = [I1, I2, I3] {
            Handle h;
            check(lpi_rigid_body_create(h.out(), I1, I2, I3), nullptr, "create rigid body");
            return with_state(std::move(h), {1.0, 0.5, -0.3});
        };
        s.final_time = 100.0;
        s.steps = {0.2, 0.1, 0.05, 0.025, 0.0125, 0.00625};
        s.exact_reference = true;
        scenes.push_back(s);
    }
    {
        Scene s;
        s.name = "pendulum";
        s.description = "planar pendulum H = x3^2/2 + x2, x(0) = (sin 2, -cos 2, 0.3)";
        s.create = [] {
            Handle h;
            check(lpi_pendulum_create(h.out()), nullptr, "create pendulum");
            return with_state(std::move(h), {std::sin(2.0), -std::cos(2.0), 0.3});
        };
        s.final_time = 100.0;
        s.steps = {0.2, 0.1, 0.05, 0.025, 0.0125, 0.00625};
        s.reference_method = "rk4";
        s.reference_step = 2e-4;
        scenes.push_back(s);
    }
    {
        Scene s;
        s.name = "moments";
        s.description = "moment algebra (8-dim), pieces V(x1,x4) + T(x3,x8) + P(x1 x3)";
        s.create = [] {
            Handle h;
            check(lpi_moments_create(h.out()), nullptr, "create moments");
            const int32_t potential[2] = {0, 3}, kinetic[2] = {2, 7};
            check(lpi_add_piece(h.get(), 2, potential, potential_gradient, potential_energy, nullptr),
                  h.get(), "add piece");
            check(lpi_add_piece(h.get(), 2, kinetic, potential_gradient, potential_energy, nullptr),
                  h.get(), "add piece");
            check(lpi_moments_add_product_piece(h.get(), product_h, product_dh, nullptr), h.get(),
                  "add product piece");
            return with_state(std::move(h), {1.0, 0.2, 0.5, 2.5, 0.6, 0.6, 0.3, 0.8});
        };
        s.final_time = 20.0;
        s.steps = {0.05, 0.025, 0.0125, 0.00625, 0.003125};
        s.reference_method = "kahan-li-8";
        s.reference_step = 5e-4;
        scenes.push_back(s);
    }
    {
        Scene s;
        const int N = options.sine_euler_n;
        s.name = "sine-euler";
        s.description = "sine-Euler (Zeitlin su(N) 2D Euler), N = " + std::to_string(N) +
                        ", smooth random field, sum |w|^2 = 1 (--N to change N)";
        s.create = [N] {
            Handle h;
            check(lpi_sine_euler_create(h.out(), N), nullptr, "create sine-Euler");
            const std::vector<double> w = smooth_random_field(N, 3.0, 7);
            check(lpi_sine_euler_set_modes(h.get(), w.data(), w.size()), h.get(), "set modes");
            return h;
        };
        s.unavailable = sine_euler_unavailable;
        s.excluded_methods = {"direct-eq5"};
        s.exclusion_reason = "direct-eq5 (O(N^4), a correctness reference) is left out";
        s.final_time = 10.0;
        s.steps = {0.4, 0.2, 0.1, 0.05, 0.025};
        s.reference_method = "kahan-li-8";
        s.reference_step = 0.02;
        scenes.push_back(s);
    }
    {
        Scene s;
        s.name = "figure2";
        s.description = "the paper's Figure 2: sine-Euler N = 7, leapfrog, dt = 0.05, 10^5 steps, "
                        "|w| = 1, H(0) = 0.75";
        s.create = [] {
            Handle h;
            check(lpi_sine_euler_create(h.out(), 7), nullptr, "create sine-Euler");
            const std::vector<double> w = figure2_field();
            check(lpi_sine_euler_set_modes(h.get(), w.data(), w.size()), h.get(), "set modes");
            return h;
        };
        s.final_time = 5000.0;
        s.run_step = 0.05;
        s.unavailable = sine_euler_unavailable;
        s.custom_run = run_figure2;
        scenes.push_back(s);
    }
    return scenes;
}

}  // namespace lpi_cli
