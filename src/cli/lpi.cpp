// lpi: the liepoisson command. `lpi report [scene]` integrates a scene with
// every method over a range of step sizes and prints error against CPU time.
// It uses only the public C API, as any user program would.
#include <liepoisson.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <functional>
#include <string>
#include <vector>

namespace {

struct Scene {
    std::string name;
    std::string description;
    std::function<int(lpi_system **)> create;
    std::vector<double> initial_state;
    double final_time;
    std::vector<double> steps;
    std::string reference_method;
    double reference_step;
};

std::vector<Scene> scenes() {
    return {
        {"rigid-body", "free rigid body, I = (1, 2, 3), m(0) = (1, 0.5, -0.3)",
         [](lpi_system **s) { return lpi_rigid_body_create(s, 1.0, 2.0, 3.0); },
         {1.0, 0.5, -0.3}, 100.0, {0.2, 0.1, 0.05, 0.025, 0.0125}, "rk4", 1e-4},
        {"pendulum", "planar pendulum H = x3^2/2 + x2, x(0) = (sin 2, -cos 2, 0.3)",
         [](lpi_system **s) { return lpi_pendulum_create(s); },
         {std::sin(2.0), -std::cos(2.0), 0.3}, 100.0, {0.2, 0.1, 0.05, 0.025, 0.0125}, "rk4",
         1e-4},
    };
}

double cpu_seconds() {
    timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// Exits with a message: the command (not the library) decides to stop.
void check(int status, lpi_system *sys, const char *what) {
    if (status == LPI_OK) return;
    std::fprintf(stderr, "lpi: %s failed: %s (%s)\n", what, lpi_last_error(sys),
                 lpi_status_name(status));
    std::exit(1);
}

lpi_system *make_system(const Scene &scene, const char *method) {
    lpi_system *sys = nullptr;
    check(scene.create(&sys), nullptr, "create");
    check(lpi_set_method(sys, method), sys, "set method");
    check(lpi_set_state(sys, scene.initial_state.data(), scene.initial_state.size()), sys,
          "set state");
    return sys;
}

std::vector<double> final_state(lpi_system *sys) {
    std::vector<double> x(lpi_dim(sys));
    check(lpi_get_state(sys, x.data(), x.size()), sys, "get state");
    return x;
}

double distance(const std::vector<double> &a, const std::vector<double> &b) {
    double s = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) s += (a[i] - b[i]) * (a[i] - b[i]);
    return std::sqrt(s);
}

struct Row {
    std::string method;
    double dt;
    int64_t steps;
    double cpu;
    double error;
    double energy_error;
    double casimir_drift;
};

// One (method, dt) cell: a timed pass (one lpi_step call, repeated until the
// clock resolves it) and a diagnostic pass sampling energy and Casimirs.
Row measure(const Scene &scene, const char *method, double dt, const std::vector<double> &reference) {
    Row row{method, dt, static_cast<int64_t>(std::llround(scene.final_time / dt)), 0, 0, 0, 0};
    int repeats = 0;
    double elapsed = 0.0;
    std::vector<double> end;
    while (elapsed < 0.05 || repeats == 0) {
        lpi_system *sys = make_system(scene, method);
        const double t0 = cpu_seconds();
        check(lpi_step(sys, dt, row.steps), sys, "step");
        elapsed += cpu_seconds() - t0;
        ++repeats;
        end = final_state(sys);
        lpi_destroy(sys);
    }
    row.cpu = elapsed / repeats;
    row.error = distance(end, reference);

    lpi_system *sys = make_system(scene, method);
    double h0 = 0.0;
    check(lpi_energy(sys, &h0), sys, "energy");
    std::vector<double> c0(lpi_casimir_count(sys)), c(c0.size());
    check(lpi_casimirs(sys, c0.data(), c0.size()), sys, "casimirs");
    const int64_t samples = std::min<int64_t>(row.steps, 1000);
    int64_t done = 0;
    for (int64_t k = 1; k <= samples; ++k) {
        const int64_t target = row.steps * k / samples;
        check(lpi_step(sys, dt, target - done), sys, "step");
        done = target;
        double h = 0.0;
        check(lpi_energy(sys, &h), sys, "energy");
        row.energy_error = std::max(row.energy_error, std::fabs((h - h0) / h0));
        check(lpi_casimirs(sys, c.data(), c.size()), sys, "casimirs");
        for (std::size_t i = 0; i < c.size(); ++i)
            row.casimir_drift = std::max(row.casimir_drift, std::fabs((c[i] - c0[i]) / c0[i]));
    }
    lpi_destroy(sys);
    return row;
}

void report(const Scene &scene) {
    lpi_system *ref = make_system(scene, scene.reference_method.c_str());
    const int64_t ref_steps = std::llround(scene.final_time / scene.reference_step);
    check(lpi_step(ref, scene.reference_step, ref_steps), ref, "reference step");
    const std::vector<double> reference = final_state(ref);
    lpi_destroy(ref);

    std::printf("\n== %s: %s, T = %g\n", scene.name.c_str(), scene.description.c_str(),
                scene.final_time);
    std::printf("   reference: %s with dt = %g; error = |x(T) - x_ref(T)|\n",
                scene.reference_method.c_str(), scene.reference_step);
    std::printf("%-22s %9s %9s %11s %11s %12s %12s %9s\n", "method", "dt", "steps", "cpu [s]",
                "error", "max|dH/H|", "max|dC/C|", "ns/step");
    for (int i = 0; i < lpi_method_count(); ++i) {
        for (double dt : scene.steps) {
            const Row r = measure(scene, lpi_method_name(i), dt, reference);
            std::printf("%-22s %9.4g %9lld %11.3e %11.3e %12.3e %12.3e %9.1f\n", r.method.c_str(),
                        r.dt, static_cast<long long>(r.steps), r.cpu, r.error, r.energy_error,
                        r.casimir_drift, 1e9 * r.cpu / r.steps);
        }
    }
}

int usage(FILE *to) {
    std::fprintf(to,
                 "usage: lpi report [SCENE...]   error against CPU time for every method\n"
                 "       lpi --version | --help\n"
                 "scenes:");
    for (const Scene &s : scenes()) std::fprintf(to, " %s", s.name.c_str());
    std::fprintf(to, " (default: all)\n");
    return to == stdout ? 0 : 2;
}

}  // namespace

int main(int argc, char **argv) {
    if (argc < 2) return usage(stderr);
    const std::string command = argv[1];
    if (command == "--help" || command == "-h") return usage(stdout);
    if (command == "--version") {
        std::printf("lpi (liepoisson) %s\n", lpi_version_string());
        return 0;
    }
    if (command != "report") {
        std::fprintf(stderr, "lpi: unknown command '%s'\n", command.c_str());
        return usage(stderr);
    }
    std::printf("liepoisson %s: error against CPU time (one core)\n", lpi_version_string());
    const std::vector<Scene> all = scenes();
    if (argc == 2) {
        for (const Scene &s : all) report(s);
        return 0;
    }
    for (int a = 2; a < argc; ++a) {
        auto it = std::find_if(all.begin(), all.end(), [&](const Scene &s) { return s.name == argv[a]; });
        if (it == all.end()) {
            std::fprintf(stderr, "lpi: unknown scene '%s'\n", argv[a]);
            return usage(stderr);
        }
        report(*it);
    }
    return 0;
}
