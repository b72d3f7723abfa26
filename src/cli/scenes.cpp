#include "scenes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "fields.hpp"
#include "hamiltonians.hpp"
#include "systems.hpp"

namespace lpi_cli {

namespace {

// The moment scene's Hamiltonian, split as in the paper: a nearly harmonic
// ensemble with weak quartic coupling,
// H = V(x1, x4) + T(x3, x8) + P(x1 x3) with V = x1/2 + x1^2/100 + x4/100,
// T = x3/2 + x3^2/100 + x8/100 and P(u) = u/50 + u^2/100 (systems.hpp).
int potential_gradient(size_t, const double *x, double *g, void *) {
    g[0] = 0.5 + 0.02 * x[0];
    g[1] = 0.01;
    return 0;
}
int potential_energy(size_t, const double *x, double *h, void *) {
    *h = 0.5 * x[0] + 0.01 * x[0] * x[0] + 0.01 * x[1];
    return 0;
}

Handle coupled_moments() {
    Handle h;
    check(lpi_moments_create(h.out()), nullptr, "create moments");
    const int32_t potential[2] = {0, 3}, kinetic[2] = {2, 7};
    check(lpi_add_piece(h.get(), 2, potential, potential_gradient, potential_energy, nullptr), h.get(),
          "add piece");
    check(lpi_add_piece(h.get(), 2, kinetic, potential_gradient, potential_energy, nullptr), h.get(),
          "add piece");
    check(lpi_moments_add_product_piece(h.get(), product_energy, product_derivative, nullptr), h.get(),
          "add product piece");
    const std::vector<double> x = {1.0, 0.2, 0.5, 2.5, 0.6, 0.6, 0.3, 0.8};
    check(lpi_set_state(h.get(), x.data(), x.size()), h.get(), "set state");
    return h;
}

std::string format_number(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    return text;
}

// The spectrum of W (lpi_casimirs) is computed with LAPACK.
std::string sine_euler_spectrum_unavailable() {
    const std::string no_sine_euler = sine_euler_unavailable();
    if (!no_sine_euler.empty()) return no_sine_euler;
    Handle probe = sine_euler(3, [](int N) { return std::vector<double>(2 * N * N, 0.0); });
    double spectrum[3];
    const int status = lpi_casimirs(probe.get(), spectrum, 3);
    return status == LPI_OK ? "" : lpi_last_error(probe.get());
}


// What configures a sine-Euler scene beyond its Hamiltonian: its N, its
// initial grid and how its transforms run.
const std::vector<std::string> kSineEulerOptions = {"--N", "--init", "--threads", "--planning", "--wisdom"};

// A work-precision scene: its system, final time and sweep of step sizes
// (the reference solution is set by the caller).
Scene sweep_scene(const std::string &name, const std::string &description, std::function<Handle()> create,
                  double final_time, std::vector<double> steps) {
    Scene s;
    s.name = name;
    s.description = description;
    s.create = std::move(create);
    s.final_time = final_time;
    s.steps = std::move(steps);
    return s;
}

}  // namespace

std::vector<Scene> builtin_scenes(const SceneOptions &options) {
    std::vector<Scene> scenes;
    const double I1 = options.inertia[0], I2 = options.inertia[1], I3 = options.inertia[2];
    const std::vector<double> m0 = {1.0, 0.5, -0.3};
    Scene rigid = sweep_scene("rigid-body",
                              "free rigid body, I = (" + format_number(I1) + ", " + format_number(I2) + ", " +
                                  format_number(I3) + "), m(0) = (1, 0.5, -0.3)",
                              [I1, I2, I3, m0] { return rigid_body(I1, I2, I3, m0); }, 100.0,
                              {0.8, 0.4, 0.2, 0.1, 0.05, 0.025, 0.0125, 0.00625});
    rigid.options = {"--inertia"};
    rigid.exact_reference = true;
    {
        // lpi_rigid_body_exact(3): within 3e-15 |m| for rate T up to 10, then
        // growing like the unit round-off times rate T (5e-14 |m| at 300),
        // rate = |m| max |1/I_i - 1/I_j|.
        const double m = std::sqrt(m0[0] * m0[0] + m0[1] * m0[1] + m0[2] * m0[2]),
                     rate = m * std::max({std::fabs(1 / I1 - 1 / I2), std::fabs(1 / I2 - 1 / I3),
                                          std::fabs(1 / I1 - 1 / I3)});
        rigid.exact_accuracy = m * std::max(3e-15, 2e-16 * rate * rigid.final_time);
    }
    scenes.push_back(rigid);

    Scene pendulum_scene = sweep_scene(
        "pendulum", "planar pendulum H = x3^2/2 + x2, x(0) = (sin 2, -cos 2, 0.3)",
        [] { return pendulum({std::sin(2.0), -std::cos(2.0), 0.3}); }, 100.0,
        {0.8, 0.4, 0.2, 0.1, 0.05, 0.025, 0.0125, 0.00625});
    pendulum_scene.reference_method = "kahan-li-8";
    pendulum_scene.reference_step = 0.005;
    scenes.push_back(pendulum_scene);

    Scene moments = sweep_scene("moments", "moment algebra (8-dim), pieces V(x1,x4) + T(x3,x8) + P(x1 x3)",
                                coupled_moments, 20.0, {0.05, 0.025, 0.0125, 0.00625, 0.003125});
    moments.reference_method = "kahan-li-8";
    moments.reference_step = 0.01;
    scenes.push_back(moments);
    {
        Scene s;
        const int N = options.sine_euler_n;
        s.name = "sine-euler";
        s.description = "sine-Euler (Zeitlin su(N) 2D Euler), N = " + std::to_string(N) +
                        ", smooth random field, sum |w|^2 = 1";
        s.options = kSineEulerOptions;
        s.create = [N] { return sine_euler(N, smooth_field); };
        s.unavailable = sine_euler_unavailable;
        s.excluded_methods = {"direct-eq5"};
        s.exclusion_reason = "direct-eq5 (eq. 5 summed term by term, O(N^4): a cross-check of the fast methods) is left out";
        s.final_time = 10.0;
        s.steps = {0.4, 0.2, 0.1, 0.05, 0.025};
        s.reference_method = "kahan-li-8";
        s.reference_step = 0.02;
        scenes.push_back(s);
    }
    {
        // The work-precision scene above measures the error at T = 10; users
        // run long. Over a long run the non-Poisson methods drift secularly;
        // the splitting keeps the Casimirs to round-off. The steps divide the
        // sampling interval (T / 500 = 4 at T = 2000; 2 at the test's
        // T = 200), so every run is sampled at the same times. The sweep
        // costs about 80 CPU seconds at N = 31, T = 2000. Left out as
        // useless: larger steps (leapfrog at dt = 1 and the high orders at
        // dt = 4 lose 15% to 50% of the energy; isomp at 0.4 does not converge).
        LongRunScene long_run;
        const int N = options.sine_euler_n;
        long_run.name = "sine-euler-long";
        long_run.final_time = options.long_run_time;
        long_run.setting = "N = " + std::to_string(N) + ", T = " + format_number(long_run.final_time);
        long_run.description = "the sine-euler field run long: max energy error and Casimir "
                               "drift against CPU time";
        long_run.create = [N] { return sine_euler(N, smooth_field); };
        long_run.sweeps = {
            {"leapfrog", {0.5, 0.25, 0.125}},
            {"mclachlan-4", {2.0, 1.0, 0.5}},
            {"kahan-li-6", {2.0, 1.0}},
            {"rk4-matrix", {0.4, 0.2, 0.1, 0.05, 0.025}},
            {"isomp", {0.2}},
        };
        long_run.exclusion_reason =
            "rk4 is left out (the same map as rk4-matrix, several times slower), and so is\n"
            "   implicit-midpoint (about 5 leapfrog steps' cost a step).";
        Scene s;
        s.name = long_run.name;
        s.description = long_run.description + ", " + long_run.setting;
        s.options = {"--N", "--T"};
        // What lpi report checks before any scene runs (a --T too long for its steps).
        s.final_time = long_run.final_time;
        for (const LongRunSweep &sweep : long_run.sweeps) s.steps.insert(s.steps.end(), sweep.steps.begin(), sweep.steps.end());
        s.unavailable = sine_euler_spectrum_unavailable;
        s.custom_run = [long_run](const std::string &out_dir) { return run_long_scene(long_run, out_dir); };
        scenes.push_back(s);
    }
    {
        // The sine-bracket family (lpi_sine_euler_set_hamiltonian): the
        // sine-euler scene's field and sweep with other Hamiltonians.
        const int N = options.sine_euler_n;
        const double kd = options.qg_kd;
        const struct {
            const char *name;
            std::string description;
            std::function<Handle()> create;
            std::vector<std::string> options;  // beyond kSineEulerOptions
            std::function<std::vector<double>()> topography = nullptr;
        } family[] = {
            {"sqg", "surface quasi-geostrophy (lambda = 1/|n|), N = " + std::to_string(N),
             [N] { return sqg_system(N); }, {}},
            {"qg", "quasi-geostrophy, lambda = 1/(|n|^2 + kd^2), kd = " + format_number(kd) + ", N = " +
                       std::to_string(N),
             [N, kd] { return qg_system(N, kd); }, {"--kd"}},
            {"topography", "2D Euler over a smooth random topography h (its field: q = w + h), N = " + std::to_string(N),
             [N] { return topography_system(N); }, {}, [N] { return topography_grid(N); }},
        };
        for (const auto &member : family) {
            Scene s = sweep_scene(member.name, member.description + ", smooth random field", member.create, 10.0,
                                  {0.4, 0.2, 0.1, 0.05, 0.025});
            s.options = kSineEulerOptions;
            s.options.insert(s.options.end(), member.options.begin(), member.options.end());
            s.unavailable = sine_euler_unavailable;
            s.excluded_methods = {"direct-eq5"};
            s.exclusion_reason = "direct-eq5 (eq. 5 summed term by term, O(N^4): a cross-check of the fast methods) is left out";
            s.reference_method = "kahan-li-8";
            s.reference_step = 0.02;
            s.in_default_report = false;
            s.topography = member.topography;
            scenes.push_back(s);
        }
    }
    {
        Scene s;
        s.name = "rollup";
        s.description = "the paper's closing question: does a smooth sine-Euler field roll up into the "
                        "highest modes? N = 63, 10^5 leapfrog steps of 0.05 (--steps, --dt)";
        s.options = {"--N"};
        s.unavailable = sine_euler_unavailable;
        s.in_default_report = false;
        s.run_own = run_rollup;
        scenes.push_back(s);
    }
    {
        Scene s;
        s.name = "figure2";
        s.description = "the paper's Figure 2: sine-Euler N = 7, leapfrog, dt = 0.05, 10^5 steps, "
                        "|w| = 1, H(0) = 0.75";
        s.options = {"--init", "--threads", "--planning", "--wisdom"};  // N = 7
        s.create = figure2_system;
        s.final_time = 5000.0;
        s.run_step = 0.05;
        s.unavailable = sine_euler_unavailable;
        s.custom_run = run_figure2;
        scenes.push_back(s);
    }
    return scenes;
}

bool configures_scenes(const std::string &option) {
    for (const Scene &s : builtin_scenes())
        if (std::find(s.options.begin(), s.options.end(), option) != s.options.end()) return true;
    return false;
}

}  // namespace lpi_cli
