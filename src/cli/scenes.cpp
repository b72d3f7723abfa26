#include "scenes.hpp"

#include <cmath>

namespace lpi_cli {

namespace {

Handle with_state(Handle h, const std::vector<double> &x) {
    check(lpi_set_state(h.get(), x.data(), x.size()), h.get(), "set state");
    return h;
}

}  // namespace

std::vector<Scene> builtin_scenes() {
    std::vector<Scene> scenes;
    {
        Scene s;
        s.name = "rigid-body";
        s.description = "free rigid body, I = (1, 2, 3), m(0) = (1, 0.5, -0.3)";
        s.create = [] {
            Handle h;
            check(lpi_rigid_body_create(h.out(), 1.0, 2.0, 3.0), nullptr, "create rigid body");
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
    return scenes;
}

}  // namespace lpi_cli
