#include "report.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace lpi_cli {

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Row {
    std::string method;
    int order = 0;
    double dt = 0.0;
    int64_t steps = 0;
    double cpu = kNaN;
    double error = kNaN;
    double energy_error = 0.0;
    double casimir_drift = 0.0;
    int status = LPI_OK;
};

struct Sample {
    double time, energy_error, casimir_drift;
};

double distance(const std::vector<double> &a, const std::vector<double> &b) {
    double s = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) s += (a[i] - b[i]) * (a[i] - b[i]);
    return std::sqrt(s);
}

std::vector<double> reference_state(const Scene &scene) {
    Handle h = scene.create();
    if (scene.exact_reference) {
        std::vector<double> x(lpi_dim(h.get()));
        check(lpi_rigid_body_exact(h.get(), scene.final_time, x.data()), h.get(), "exact solution");
        return x;
    }
    check(lpi_set_method(h.get(), scene.reference_method.c_str()), h.get(), "reference method");
    const int64_t n = std::llround(scene.final_time / scene.reference_step);
    check(lpi_step(h.get(), scene.final_time / n, n), h.get(), "reference run");
    return state_of(h.get());
}

// One (method, dt) cell: a timed pass (one lpi_step call, repeated until the
// clock resolves it), then a diagnostic pass sampling energy and Casimirs.
Row measure(const Scene &scene, const char *method, int order, double dt,
            const std::vector<double> &reference, const ReportOptions &options,
            std::vector<Sample> *history) {
    Row row;
    row.method = method;
    row.order = order;
    row.steps = std::max<int64_t>(1, std::llround(scene.final_time / dt));
    row.dt = scene.final_time / static_cast<double>(row.steps);
    double elapsed = 0.0;
    int repeats = 0;
    std::vector<double> end;
    do {
        Handle h = scene.create();
        check(lpi_set_method(h.get(), method), h.get(), "set method");
        // Warm up (FFTW plans are made on a system's first step), then start
        // again from the initial state: planning is not part of the figure.
        const std::vector<double> x0 = state_of(h.get());
        if (lpi_step(h.get(), row.dt, 1) == LPI_OK)
            check(lpi_set_state(h.get(), x0.data(), x0.size()), h.get(), "set state");
        const double t0 = cpu_seconds();
        row.status = lpi_step(h.get(), row.dt, row.steps);
        elapsed += cpu_seconds() - t0;
        ++repeats;
        if (row.status != LPI_OK) return row;  // reported, not fatal: e.g. RK4 unstable
        end = state_of(h.get());
    } while (elapsed < options.min_timing_seconds);
    row.cpu = elapsed / repeats;
    row.error = distance(end, reference);

    Handle h = scene.create();
    check(lpi_set_method(h.get(), method), h.get(), "set method");
    const double h0 = energy_of(h.get());
    const std::vector<double> c0 = casimirs_of(h.get());
    const int64_t samples = std::min<int64_t>(row.steps, options.samples);
    int64_t done = 0;
    for (int64_t k = 1; k <= samples; ++k) {
        const int64_t target = row.steps * k / samples;
        if (lpi_step(h.get(), row.dt, target - done) != LPI_OK) break;
        done = target;
        const double de = std::fabs((energy_of(h.get()) - h0) / h0);
        const std::vector<double> c = casimirs_of(h.get());
        double dc = 0.0;
        for (std::size_t i = 0; i < c.size(); ++i)
            dc = std::max(dc, std::fabs(c[i] - c0[i]) / std::max(std::fabs(c0[i]), 1e-300));
        row.energy_error = std::max(row.energy_error, de);
        row.casimir_drift = std::max(row.casimir_drift, dc);
        if (history) history->push_back({lpi_time(h.get()), de, dc});
    }
    return row;
}

// CPU time a method needs for `target` error, interpolated log-log along its
// sweep. `bound` is set when even the largest step beats the target (the
// figure is then an upper bound); NaN when the sweep does not reach it.
double cpu_at_error(const std::vector<Row> &rows, const std::string &method, double target,
                    bool *bound) {
    const Row *previous = nullptr;
    *bound = false;
    for (const Row &r : rows) {
        if (r.method != method || !(r.error > 0.0) || std::isnan(r.cpu)) continue;
        if (!previous && r.error <= target) {
            *bound = true;
            return r.cpu;
        }
        if (previous && (previous->error - target) * (r.error - target) <= 0.0) {
            const double f = std::log(target / previous->error) / std::log(r.error / previous->error);
            return std::exp(std::log(previous->cpu) + f * std::log(r.cpu / previous->cpu));
        }
        previous = &r;
    }
    return kNaN;
}

void write_csv(const std::string &path, const std::vector<Row> &rows, const Scene &scene) {
    FILE *f = std::fopen(path.c_str(), "w");
    if (!f) {
        std::fprintf(stderr, "lpi: cannot write %s\n", path.c_str());
        return;
    }
    std::fprintf(f, "scene,method,order,dt,steps,cpu_seconds,error,max_energy_error,max_casimir_drift,status\n");
    for (const Row &r : rows)
        std::fprintf(f, "%s,%s,%d,%.17g,%lld,%.6e,%.6e,%.6e,%.6e,%s\n", scene.name.c_str(),
                     r.method.c_str(), r.order, r.dt, static_cast<long long>(r.steps), r.cpu,
                     r.error, r.energy_error, r.casimir_drift, lpi_status_name(r.status));
    std::fclose(f);
}

void write_history(const std::string &path, const std::map<std::string, std::vector<Sample>> &histories,
                   double dt) {
    FILE *f = std::fopen(path.c_str(), "w");
    if (!f) return;
    std::fprintf(f, "method,dt,time,energy_error,casimir_drift\n");
    for (const auto &[method, samples] : histories)
        for (const Sample &s : samples)
            std::fprintf(f, "%s,%.17g,%.10g,%.6e,%.6e\n", method.c_str(), dt, s.time,
                         s.energy_error, s.casimir_drift);
    std::fclose(f);
}

bool is_poisson(const std::string &method) {
    for (int i = 0; i < lpi_method_count(); ++i)
        if (method == lpi_method_name(i)) return lpi_method_is_poisson(i) == 1;
    return false;
}

bool have_gnuplot() { return std::system("command -v gnuplot >/dev/null 2>&1") == 0; }

// Draws the work-precision and energy plots with gnuplot from the CSV files.
bool plot(const std::string &dir, const Scene &scene, const std::vector<std::string> &methods) {
    const std::string script = dir + "/" + scene.name + ".gp";
    FILE *f = std::fopen(script.c_str(), "w");
    if (!f) return false;
    const std::string base = dir + "/" + scene.name;
    std::fprintf(f,
                 "set datafile separator ','\nset terminal pngcairo size 1000,700 noenhanced\n"
                 "set logscale xy\nset grid\nset key outside right\nset format y '%%.0e'\nset format x '%%.0e'\n"
                 "set output '%s_work_precision.png'\n"
                 "set title '%s: error at T = %g against CPU time'\n"
                 "set xlabel 'CPU seconds'\nset ylabel 'error |x(T) - x_ref(T)|'\nplot ",
                 base.c_str(), scene.name.c_str(), scene.final_time);
    // Each method its own colour and point shape; the baselines (not Poisson
    // maps) dashed, so the two families read apart at a glance.
    auto style = [&](std::size_t i) {
        char text[96];
        std::snprintf(text, sizeof text, "lc %zu pt %zu dt %d", i % 8 + 1, i % 13 + 1,
                      is_poisson(methods[i]) ? 1 : 2);
        return std::string(text);
    };
    for (std::size_t i = 0; i < methods.size(); ++i)
        std::fprintf(f, "%s'%s.csv' using (strcol(2) eq '%s' && strcol(10) eq 'LPI_OK' ? $6 : 1/0):7 "
                        "with linespoints %s title '%s'",
                     i ? ", " : "", base.c_str(), methods[i].c_str(), style(i).c_str(),
                     methods[i].c_str());
    std::fprintf(f,
                 "\nset output '%s_energy.png'\nset title '%s: relative energy error against time'\n"
                 "unset logscale x\nset xlabel 'time'\nset ylabel '|H(t) - H(0)| / |H(0)|'\nplot ",
                 base.c_str(), scene.name.c_str());
    for (std::size_t i = 0; i < methods.size(); ++i)
        std::fprintf(f, "%s'%s_energy.csv' using (strcol(1) eq '%s' ? $3 : 1/0):($4 > 0 ? $4 : 1/0) "
                        "with lines lc %zu dt %d title '%s'",
                     i ? ", " : "", base.c_str(), methods[i].c_str(), i % 8 + 1,
                     is_poisson(methods[i]) ? 1 : 2, methods[i].c_str());
    std::fprintf(f, "\n");
    std::fclose(f);
    return std::system(("gnuplot '" + script + "' 2>/dev/null").c_str()) == 0;
}

}  // namespace

void run_report(const Scene &scene, const ReportOptions &options) {
    mkdir(options.out_dir.c_str(), 0777);
    const std::string why_not = scene.unavailable();
    if (!why_not.empty()) {
        std::printf("\n== %s: skipped in this build: %s\n", scene.name.c_str(), why_not.c_str());
        return;
    }
    if (scene.custom_run) {
        scene.custom_run(options.out_dir);
        return;
    }
    const std::vector<double> reference = reference_state(scene);
    std::printf("\n== %s: %s, T = %g\n", scene.name.c_str(), scene.description.c_str(),
                scene.final_time);
    if (scene.exact_reference)
        std::printf("   reference: the exact solution; error = |x(T) - x_exact(T)|\n");
    else
        std::printf("   reference: %s with dt = %g; error = |x(T) - x_ref(T)|\n",
                    scene.reference_method.c_str(), scene.reference_step);
    if (!scene.exclusion_reason.empty()) std::printf("   %s\n", scene.exclusion_reason.c_str());
    std::printf("%-24s %9s %9s %11s %11s %11s %11s %10s  %s\n", "method", "dt", "steps", "cpu [s]",
                "error", "max|dH/H|", "max|dC/C|", "ns/step", "status");

    std::vector<Row> rows;
    std::vector<std::string> methods;
    std::map<std::string, std::vector<Sample>> histories;
    const double history_dt = scene.steps[scene.steps.size() / 2];
    const std::vector<bool> accepted = accepted_methods(scene.create);
    for (int i = 0; i < lpi_method_count(); ++i) {
        const char *method = lpi_method_name(i);
        if (!accepted[static_cast<std::size_t>(i)]) continue;  // not applicable here
        if (std::find(scene.excluded_methods.begin(), scene.excluded_methods.end(), method) !=
            scene.excluded_methods.end())
            continue;
        methods.push_back(method);
        // A composition of s leapfrog stages sweeps steps s times larger, so
        // every method spans about the same range of cost.
        const double stretch = std::max(1, lpi_method_stages(i));
        for (double base_dt : scene.steps) {
            const double dt = std::min(base_dt * stretch, scene.final_time);
            std::vector<Sample> *history = base_dt == history_dt ? &histories[method] : nullptr;
            const Row r = measure(scene, method, lpi_method_order(i), dt, reference, options, history);
            rows.push_back(r);
            std::printf("%-24s %9.4g %9lld %11.3e %11.3e %11.3e %11.3e %10.1f  %s\n", r.method.c_str(),
                        r.dt, static_cast<long long>(r.steps), r.cpu, r.error, r.energy_error,
                        r.casimir_drift, 1e9 * r.cpu / static_cast<double>(r.steps),
                        r.status == LPI_OK ? "" : lpi_status_name(r.status));
        }
    }

    std::printf("\n   CPU seconds to reach a final error (interpolated along each sweep;\n   < = reached at the largest step already, an upper bound; - = not reached):\n");
    const double targets[] = {1e-2, 1e-4, 1e-6, 1e-8};
    std::printf("   %-24s", "method");
    for (double t : targets) std::printf(" %11.0e", t);
    std::printf("\n");
    for (const std::string &m : methods) {
        std::printf("   %-24s", m.c_str());
        for (double t : targets) {
            bool bound = false;
            const double c = cpu_at_error(rows, m, t, &bound);
            if (std::isnan(c))
                std::printf(" %11s", "-");
            else
                std::printf(" %s%10.3e", bound ? "<" : " ", c);
        }
        std::printf("\n");
    }

    // At equal final error: each baseline's CPU time over the best Poisson
    // (splitting) method's.
    std::printf("\n   at equal final error, CPU time of each baseline over the best splitting method:\n");
    for (double t : targets) {
        double best = kNaN;
        std::string best_method;
        for (int i = 0; i < lpi_method_count(); ++i) {
            bool bound = false;
            const std::string m = lpi_method_name(i);
            if (lpi_method_is_poisson(i) != 1 ||
                std::find(methods.begin(), methods.end(), m) == methods.end())
                continue;
            const double c = cpu_at_error(rows, m, t, &bound);
            if (!bound && c > 0.0 && !(c >= best)) best = c, best_method = m;
        }
        if (std::isnan(best)) continue;
        std::printf("   error %.0e: best splitting %s %.3e s;", t, best_method.c_str(), best);
        for (int i = 0; i < lpi_method_count(); ++i) {
            bool bound = false;
            const std::string m = lpi_method_name(i);
            if (lpi_method_is_poisson(i) != 0 ||
                std::find(methods.begin(), methods.end(), m) == methods.end())
                continue;
            const double c = cpu_at_error(rows, m, t, &bound);
            if (std::isnan(c))
                std::printf(" %s not reached;", m.c_str());
            else
                std::printf(" %s %s%.2fx;", m.c_str(), bound ? "<" : "", c / best);
        }
        std::printf("\n");
    }

    const std::string base = options.out_dir + "/" + scene.name;
    write_csv(base + ".csv", rows, scene);
    write_history(base + "_energy.csv", histories, history_dt);
    std::printf("   wrote %s.csv and %s_energy.csv (energy history at dt = %g)\n", base.c_str(),
                base.c_str(), history_dt);
    if (!have_gnuplot())
        std::printf("   gnuplot not found: no PNG plots (apt-get install gnuplot-nox)\n");
    else if (plot(options.out_dir, scene, methods))
        std::printf("   wrote %s_work_precision.png and %s_energy.png\n", base.c_str(), base.c_str());
    else
        std::printf("   gnuplot failed: see %s.gp\n", base.c_str());
}

}  // namespace lpi_cli
