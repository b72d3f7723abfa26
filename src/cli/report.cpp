#include "report.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "plots.hpp"

// OpenBLAS's own call, when OpenBLAS is the BLAS the library loaded (weak:
// null otherwise, and no link dependency).
extern "C" void openblas_set_num_threads(int) __attribute__((weak));

namespace lpi_cli {

namespace {

// The report measures one core. OpenBLAS would otherwise spread the Casimir
// spectra (LAPACK) over helper threads that then busy-wait for about a tenth
// of a second, on the process's CPU clock, inside the next timed steps.
void measure_on_one_core() {
    if (openblas_set_num_threads) openblas_set_num_threads(1);
}

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

// One method's energy history: its step and the samples.
struct History {
    double dt = 0.0;
    std::vector<Sample> samples;
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

bool is_sine_euler(const lpi_system *sys) {
    int32_t N = 0;
    return lpi_sine_euler_size(sys, &N) == LPI_OK;
}

// A run of `steps` steps of dt sampled at most `samples` times, equally
// spaced in steps: the energy error and Casimir drift at each sample (up to
// a failed step, if one fails).
std::vector<Sample> diagnose(const Scene &scene, const char *method, double dt, int64_t steps, int samples) {
    Handle h = scene.create();
    check(lpi_set_method(h.get(), method), h.get(), "set method");
    const double h0 = energy_of(h.get());
    const std::vector<double> c0 = casimirs_of(h.get());
    const bool spectrum = is_sine_euler(h.get());
    const int64_t count = std::min<int64_t>(steps, samples);
    std::vector<Sample> out;
    int64_t done = 0;
    for (int64_t k = 1; k <= count; ++k) {
        const int64_t target = steps * k / count;
        if (lpi_step(h.get(), dt, target - done) != LPI_OK) break;
        done = target;
        out.push_back({lpi_time(h.get()), std::fabs((energy_of(h.get()) - h0) / h0),
                       casimir_drift(spectrum, casimirs_of(h.get()), c0)});
    }
    return out;
}

// One (method, dt) cell: a timed pass (one lpi_step call, repeated until the
// clock resolves it), then a diagnostic pass sampling energy and Casimirs.
Row measure(const Scene &scene, const char *method, int order, double dt,
            const std::vector<double> &reference, const ReportOptions &options) {
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
    const std::vector<Sample> samples = diagnose(scene, method, row.dt, row.steps, options.samples);
    for (const Sample &s : samples) {
        row.energy_error = std::max(row.energy_error, s.energy_error);
        row.casimir_drift = std::max(row.casimir_drift, s.casimir_drift);
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

void write_history(const std::string &path, const std::map<std::string, History> &histories) {
    FILE *f = std::fopen(path.c_str(), "w");
    if (!f) return;
    std::fprintf(f, "method,dt,time,energy_error,casimir_drift\n");
    for (const auto &[method, history] : histories)
        for (const Sample &s : history.samples)
            std::fprintf(f, "%s,%.17g,%.10g,%.6e,%.6e\n", method.c_str(), history.dt, s.time,
                         s.energy_error, s.casimir_drift);
    std::fclose(f);
}

// Index of a registered method, -1 if none has that name.
int method_index(const std::string &method) {
    for (int i = 0; i < lpi_method_count(); ++i)
        if (method == lpi_method_name(i)) return i;
    return -1;
}

bool is_poisson(const std::string &method) { return lpi_method_is_poisson(method_index(method)) == 1; }

bool have_gnuplot() { return std::system("command -v gnuplot >/dev/null 2>&1") == 0; }

// The i-th method's colour in a plot: twenty that read apart on white
// (Okabe and Ito's, then Kelly's colours of maximum contrast).
std::string plot_colour(std::size_t i) {
    static const char *const colours[] = {"#0072b2", "#d55e00", "#009e73", "#cc79a7", "#56b4e9",
                                          "#e69f00", "#000000", "#875692", "#be0032", "#848482",
                                          "#8db600", "#654522", "#604e97", "#f99379", "#2b3d26",
                                          "#a1caf1", "#b3446c", "#c2b280", "#882d17", "#dcd300"};
    return std::string("rgb '") + colours[i % 20] + "'";
}

// The i-th method's marker: gnuplot's fifteen shapes (filled ones first),
// then five glyphs; twenty in all, as many as the colours.
std::string plot_marker(std::size_t i) {
    static const char *const markers[] = {"7", "5", "9", "11", "13", "15", "6", "4", "8", "10",
                                          "12", "14", "1", "2", "3", "'★'", "'♣'", "'♠'", "'♥'", "'#'"};
    return std::string("pt ") + markers[i % 20];
}

// The i-th method of a plot: its own colour and marker; the baselines (not
// Poisson maps) dashed, so the two families read apart at a glance.
std::string plot_style(std::size_t i, const std::string &method) {
    return "lc " + plot_colour(i) + " " + plot_marker(i) + " dt " + (is_poisson(method) ? "1" : "2");
}

// A method's legend entry: its order and stages (a step's cost in leapfrog
// steps), which is what tells the curves apart.
std::string method_label(const std::string &method) {
    const int i = method_index(method);
    const int stages = lpi_method_stages(i);
    return method + " (order " + std::to_string(lpi_method_order(i)) + ", " + std::to_string(stages) +
           (stages == 1 ? " stage)" : " stages)");
}

// Starts a gnuplot script: CSV input, a grid, the key outside.
FILE *open_plot_script(const std::string &path) {
    FILE *f = std::fopen(path.c_str(), "w");
    if (f)
        std::fprintf(f, "set datafile separator ','\nset grid xtics ytics mxtics mytics lw 0.5, lw 0.2\n"
                        "set key below center horizontal maxcols 3 samplen 3\nset xlabel offset 0,0.5\nset bmargin 12\nset tics out nomirror\nset border 3\n");
    return f;
}

// Draws the work-precision and energy plots with gnuplot from the CSV files.
bool plot(const std::string &dir, const Scene &scene, const std::vector<std::string> &methods,
          const std::vector<Row> &rows, const std::map<std::string, History> &histories) {
    const std::string script = dir + "/" + scene.name + ".gp";
    FILE *f = open_plot_script(script);
    if (!f) return false;
    const std::string base = dir + "/" + scene.name;
    Range cpu, error, energy;
    for (const Row &r : rows)
        if (r.status == LPI_OK) cpu.add(r.cpu), error.add(r.error);
    for (const auto &entry : histories)
        for (const Sample &s : entry.second.samples) energy.add(s.energy_error);
    std::string commands = format("set title '%s: error at T = %g against CPU time' noenhanced\n"
                                  "set xlabel 'CPU seconds'\nset ylabel 'error |x(T) - x_{ref}(T)|'\n",
                                  scene.name.c_str(), scene.final_time) +
                           decade_axis("x", cpu.lo, cpu.hi) + decade_axis("y", error.lo, error.hi) + "plot ";
    for (std::size_t i = 0; i < methods.size(); ++i)
        commands += format("%s'%s.csv' using (strcol(2) eq '%s' && strcol(10) eq 'LPI_OK' ? $6 : 1/0):7 "
                           "with linespoints %s lw 1.5 ps 1.2 title '%s' noenhanced",
                           i ? ", " : "", base.c_str(), methods[i].c_str(), plot_style(i, methods[i]).c_str(),
                           method_label(methods[i]).c_str());
    emit_figure(f, base + "_work_precision", 1000, 820, commands + "\n");

    const double history_dt = histories.empty() ? 0.0 : histories.begin()->second.dt;
    commands = format("set title '%s: relative energy error against time, every method at dt = %g' noenhanced\n"
                      "unset logscale x\nset xrange [0:%g]\nset xtics autofreq\nset mxtics default\n"
                      "set format x '%%g'\nset xlabel 'time'\nset ylabel '|H(t) - H(0)| / |H(0)|'\n",
                      scene.name.c_str(), history_dt, scene.final_time) +
               decade_axis("y", energy.lo, energy.hi) + "plot ";
    for (std::size_t i = 0; i < methods.size(); ++i) {
        // Markers on every few samples only, each method's at its own offset.
        const auto h = histories.find(methods[i]);
        const std::size_t n = h == histories.end() ? 0 : h->second.samples.size();
        const std::size_t interval = std::max<std::size_t>(1, n / 8);
        commands += format("%s'%s_energy.csv' using (strcol(1) eq '%s' && (int($0) + %zu) %% %zu == 0 ? $3 : 1/0):"
                           "($4 > 0 ? $4 : 1/0) with points %s ps 1.1 notitle, "
                           "'' using (strcol(1) eq '%s' ? $3 : 1/0):($4 > 0 ? $4 : 1/0) with lines lc %s dt %d "
                           "lw 1.2 notitle, 1/0 with linespoints %s ps 1.1 lw 1.2 title '%s' noenhanced",
                           i ? ", " : "", base.c_str(), methods[i].c_str(), i * interval / methods.size(), interval,
                           plot_style(i, methods[i]).c_str(), methods[i].c_str(), plot_colour(i).c_str(),
                           is_poisson(methods[i]) ? 1 : 2, plot_style(i, methods[i]).c_str(),
                           method_label(methods[i]).c_str());
    }
    emit_figure(f, base + "_energy", 1000, 820, commands + "\n");
    std::fclose(f);
    return std::system(("gnuplot '" + script + "' 2>/dev/null").c_str()) == 0;
}

}  // namespace

void run_report(const Scene &scene, const ReportOptions &options) {
    measure_on_one_core();
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
    std::map<std::string, History> histories;
    // Every method's energy history at one step size, sampled as densely as
    // the others (at its stretched step a 35-stage method makes 3 steps to
    // T = 10): the legend gives the stages, a step's cost.
    const double history_dt = scene.steps[scene.steps.size() / 2];
    const int64_t history_steps = std::max<int64_t>(1, std::llround(scene.final_time / history_dt));
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
        int64_t previous_steps = 0;
        for (double base_dt : scene.steps) {
            const double dt = std::min(base_dt * stretch, scene.final_time);
            // Stretched steps near T round to the same step count: measure it once.
            const int64_t steps = std::max<int64_t>(1, std::llround(scene.final_time / dt));
            if (steps == previous_steps) continue;
            previous_steps = steps;
            const Row r = measure(scene, method, lpi_method_order(i), dt, reference, options);
            rows.push_back(r);
            std::printf("%-24s %9.4g %9lld %11.3e %11.3e %11.3e %11.3e %10.1f  %s\n", r.method.c_str(),
                        r.dt, static_cast<long long>(r.steps), r.cpu, r.error, r.energy_error,
                        r.casimir_drift, 1e9 * r.cpu / static_cast<double>(r.steps),
                        r.status == LPI_OK ? "" : lpi_status_name(r.status));
        }
        History &history = histories[method];
        history.dt = scene.final_time / static_cast<double>(history_steps);
        history.samples = diagnose(scene, method, history.dt, history_steps, options.samples);
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
    write_history(base + "_energy.csv", histories);
    std::printf("   wrote %s.csv and %s_energy.csv (energy history of every method at dt = %g)\n", base.c_str(),
                base.c_str(), scene.final_time / static_cast<double>(history_steps));
    if (!have_gnuplot())
        std::printf("   gnuplot not found: no PNG plots (apt-get install gnuplot-nox)\n");
    else if (plot(options.out_dir, scene, methods, rows, histories))
        std::printf("   wrote %s_work_precision.png and %s_energy.png, each with .svg\n", base.c_str(), base.c_str());
    else
        std::printf("   gnuplot failed: see %s.gp\n", base.c_str());
}

// ---- Long runs: what each method buys over the whole run -------------------

namespace {

struct LongRow {
    int run = 0;  // row number, keys the history CSV
    std::string method;
    double dt = 0.0;
    int64_t steps = 0;
    double cpu = 0.0;  // seconds inside lpi_step only: diagnostics are not timed
    double energy_error = 0.0, casimir_drift = 0.0;  // maxima over the samples
    double final_casimir_drift = 0.0;
    double reached = 0.0;  // time reached: the final time unless a step failed
    int status = LPI_OK;
    std::vector<Sample> history;
};

// One run to the final time in `samples` equal chunks of whole steps; after
// each chunk the energy error and the spectrum drift are sampled. A failed
// step ends the run: the row keeps the status, the time reached and the
// maxima up to there.
LongRow long_run(const LongRunScene &scene, const std::string &method, double dt, int samples) {
    const double interval = scene.final_time / samples;
    const int64_t per_sample = std::max<int64_t>(1, std::llround(interval / dt));
    LongRow row;
    row.method = method;
    row.dt = interval / static_cast<double>(per_sample);
    row.steps = per_sample * samples;
    Handle h = scene.create();
    check(lpi_set_method(h.get(), method.c_str()), h.get(), "set method");
    // Warm up (FFTW plans are made on a system's first step), then start again.
    const std::vector<double> x0 = state_of(h.get());
    if (lpi_step(h.get(), row.dt, 1) == LPI_OK)
        check(lpi_set_state(h.get(), x0.data(), x0.size()), h.get(), "set state");
    const double h0 = energy_of(h.get());
    const std::vector<double> spectrum0 = casimirs_of(h.get());
    for (int k = 1; k <= samples; ++k) {
        const double t0 = cpu_seconds();
        row.status = lpi_step(h.get(), row.dt, per_sample);
        row.cpu += cpu_seconds() - t0;
        if (row.status != LPI_OK) break;  // reported in the row, not fatal
        const Sample s{lpi_time(h.get()), std::fabs((energy_of(h.get()) - h0) / h0),
                       spectrum_drift(casimirs_of(h.get()), spectrum0)};
        row.energy_error = std::max(row.energy_error, s.energy_error);
        row.casimir_drift = std::max(row.casimir_drift, s.casimir_drift);
        row.final_casimir_drift = s.casimir_drift;
        row.reached = s.time;
        row.history.push_back(s);
    }
    return row;
}

std::string format_steps(const std::vector<double> &steps) {
    std::string text;
    for (double dt : steps) {
        char item[32];
        std::snprintf(item, sizeof item, "%s%g", text.empty() ? "" : ", ", dt);
        text += item;
    }
    return text;
}

void write_long_csv(const std::string &base, const LongRunScene &scene, const std::vector<LongRow> &rows) {
    FILE *f = std::fopen((base + ".csv").c_str(), "w");
    FILE *g = std::fopen((base + "_history.csv").c_str(), "w");
    if (!f || !g) {
        std::fprintf(stderr, "lpi: cannot write %s.csv and %s_history.csv\n", base.c_str(), base.c_str());
        if (f) std::fclose(f);
        if (g) std::fclose(g);
        return;
    }
    std::fprintf(f, "scene,run,method,order,poisson,dt,steps,cpu_seconds,max_energy_error,"
                    "max_casimir_drift,final_casimir_drift,reached_time,status\n");
    std::fprintf(g, "run,method,dt,time,energy_error,casimir_drift\n");
    for (const LongRow &r : rows) {
        const int i = method_index(r.method);
        std::fprintf(f, "%s,%d,%s,%d,%d,%.17g,%lld,%.6e,%.6e,%.6e,%.6e,%.10g,%s\n", scene.name.c_str(),
                     r.run, r.method.c_str(), lpi_method_order(i), lpi_method_is_poisson(i), r.dt,
                     static_cast<long long>(r.steps), r.cpu, r.energy_error, r.casimir_drift,
                     r.final_casimir_drift, r.reached, lpi_status_name(r.status));
        for (const Sample &s : r.history)
            std::fprintf(g, "%d,%s,%.17g,%.10g,%.6e,%.6e\n", r.run, r.method.c_str(), r.dt, s.time,
                         s.energy_error, s.casimir_drift);
    }
    std::fclose(f);
    std::fclose(g);
}

// Max energy error and max Casimir drift against CPU time (one curve per
// method through its step sizes), and both against time for the run of each
// method whose CPU time is nearest `history_cpu`.
bool plot_long(const std::string &base, const LongRunScene &scene, const std::vector<LongRow> &rows,
               const std::vector<std::string> &methods, double history_cpu) {
    FILE *f = open_plot_script(base + ".gp");
    if (!f) return false;
    const char *energy_label = "|H(t) - H(0)| / |H(0)|";
    const char *casimir_label = "max_i |{/Symbol l}_i(t) - {/Symbol l}_i(0)| / max_i |{/Symbol l}_i(0)|";
    struct Panel {
        const char *file, *title, *label;
        int column;  // in SCENE.csv
        double LongRow::*maximum;
        double Sample::*sample;
        int history_column;  // in SCENE_history.csv
    };
    const Panel panels[] = {
        {"energy", "energy error", energy_label, 9, &LongRow::energy_error, &Sample::energy_error, 5},
        {"casimirs", "Casimir drift (spectrum of W)", casimir_label, 10, &LongRow::casimir_drift,
         &Sample::casimir_drift, 6}};
    Range cpu;
    for (const LongRow &r : rows)
        if (r.status == LPI_OK) cpu.add(r.cpu);
    for (const Panel &p : panels) {
        Range y;
        for (const LongRow &r : rows)
            if (r.status == LPI_OK) y.add(r.*p.maximum);
        std::string commands =
            format("set xlabel 'CPU seconds (the steps only)'\n"
                   "set title '%s, %s: maximum %s over the run' noenhanced\nset ylabel 'max_{t <= T} %s'\n",
                   scene.name.c_str(), scene.setting.c_str(), p.title, p.label) +
            decade_axis("x", cpu.lo, cpu.hi) + decade_axis("y", y.lo, y.hi) + "plot ";
        for (std::size_t i = 0; i < methods.size(); ++i) {
            std::vector<double> steps;
            for (const LongRow &r : rows)
                if (r.method == methods[i] && r.status == LPI_OK) steps.push_back(r.dt);
            commands += format("%s'%s.csv' using (strcol(3) eq '%s' && strcol(13) eq 'LPI_OK' ? $8 : 1/0):"
                               "($%d > 0 ? $%d : 1/0) with linespoints %s lw 1.5 ps 1.5 title '%s, dt = %s' "
                               "noenhanced",
                               i ? ", " : "", base.c_str(), methods[i].c_str(), p.column, p.column,
                               plot_style(i, methods[i]).c_str(), method_label(methods[i]).c_str(),
                               format_steps(steps).c_str());
        }
        emit_figure(f, base + "_" + p.file, 1000, 820, commands + "\n");
    }
    // Against time: one panel per measure, the key once, on the right; each
    // method's run nearest the given CPU time.
    std::vector<const LongRow *> nearest(methods.size(), nullptr);
    for (std::size_t i = 0; i < methods.size(); ++i)
        for (const LongRow &r : rows)
            if (r.method == methods[i] && r.status == LPI_OK &&
                (!nearest[i] || std::fabs(std::log(r.cpu / history_cpu)) <
                                    std::fabs(std::log(nearest[i]->cpu / history_cpu))))
                nearest[i] = &r;
    std::string commands =
        format("set multiplot layout 2,1 title '%s, %s: each method at its run nearest %.3g CPU seconds' "
               "noenhanced\nset logscale y\nunset logscale x\nset autoscale x\nset xtics autofreq\n"
               "set mxtics default\nset format x '%%g'\nset xlabel 'time'\nset key default\n"
               "set key outside right top vertical samplen 3\nset lmargin 12\nset bmargin 3.5\n"
               "set rmargin at screen 0.58\n",
               scene.name.c_str(), scene.setting.c_str(), history_cpu);
    for (const Panel &p : panels) {
        Range y;
        for (const LongRow *r : nearest)
            if (r)
                for (const Sample &s : r->history) y.add(s.*p.sample);
        commands += format("set title '%s' noenhanced\nset ylabel '%s'\n", p.title, p.label) +
                    decade_axis("y", y.lo, y.hi) + "plot ";
        bool first = true;
        for (std::size_t i = 0; i < methods.size(); ++i) {
            if (!nearest[i]) continue;
            const int c = p.history_column;
            const std::size_t interval = std::max<std::size_t>(1, nearest[i]->history.size() / 8);
            commands += format("%s'%s_history.csv' using ($1 == %d && (int($0) + %zu) %% %zu == 0 ? $4 : 1/0):"
                               "($%d > 0 ? $%d : 1/0) with points %s ps 1.1 notitle, "
                               "'' using ($1 == %d ? $4 : 1/0):($%d > 0 ? $%d : 1/0) with lines lc %s dt %d "
                               "lw 1.5 notitle, 1/0 with linespoints %s ps 1.1 lw 1.5 title '%s, dt = %g' noenhanced",
                               first ? "" : ", ", base.c_str(), nearest[i]->run, i * interval / methods.size(),
                               interval, c, c, plot_style(i, methods[i]).c_str(), nearest[i]->run, c, c,
                               plot_colour(i).c_str(), is_poisson(methods[i]) ? 1 : 2,
                               plot_style(i, methods[i]).c_str(), method_label(methods[i]).c_str(),
                               nearest[i]->dt);
            first = false;
        }
        commands += "\nunset key\n";
    }
    emit_figure(f, base + "_history", 1000, 900, commands + "unset multiplot\n");
    std::fclose(f);
    return std::system(("gnuplot '" + base + ".gp' 2>/dev/null").c_str()) == 0;
}

}  // namespace

void run_long_scene(const LongRunScene &scene, const std::string &out_dir) {
    measure_on_one_core();
    if (!(scene.final_time > 0.0) || !std::isfinite(scene.final_time)) {
        std::fprintf(stderr, "lpi report: %s needs --T > 0\n", scene.name.c_str());
        std::exit(2);
    }
    double largest_step = 0.0;
    for (const LongRunSweep &sweep : scene.sweeps)
        for (double dt : sweep.steps) largest_step = std::max(largest_step, dt);
    const int samples = static_cast<int>(std::clamp(std::floor(scene.final_time / largest_step), 1.0,
                                                     static_cast<double>(scene.max_samples)));
    std::printf("\n== %s: %s, %s\n", scene.name.c_str(), scene.description.c_str(), scene.setting.c_str());
    std::printf("   energy error and drift of the spectrum of W (all Casimirs; largest eigenvalue change\n"
                "   over the largest |eigenvalue|), sampled at the same %d times in every run; CPU time\n"
                "   of the steps alone.\n   %s\n",
                samples, scene.exclusion_reason.c_str());
    std::printf("%-14s %8s %9s %10s %11s %11s %11s  %s\n", "method", "dt", "steps", "cpu [s]",
                "max|dH/H|", "max|dC|/|C|", "at T", "status");
    std::vector<LongRow> rows;
    std::vector<std::string> methods;
    const std::vector<bool> accepted = accepted_methods(scene.create);
    for (const LongRunSweep &sweep : scene.sweeps) {
        const int i = method_index(sweep.method);
        if (i < 0 || !accepted[static_cast<std::size_t>(i)]) {
            std::printf("%-14s not available in this build\n", sweep.method.c_str());
            continue;
        }
        methods.push_back(sweep.method);
        for (double dt : sweep.steps) {
            LongRow r = long_run(scene, sweep.method, dt, samples);
            r.run = static_cast<int>(rows.size());
            char status[96] = "";
            if (r.status != LPI_OK)
                std::snprintf(status, sizeof status, "%s at t = %.4g", lpi_status_name(r.status), r.reached);
            std::printf("%-14s %8.4g %9lld %10.3e %11.3e %11.3e %11.3e  %s\n", r.method.c_str(), r.dt,
                        static_cast<long long>(r.steps), r.cpu, r.energy_error, r.casimir_drift,
                        r.final_casimir_drift, status);
            std::fflush(stdout);
            rows.push_back(std::move(r));
        }
    }

    // Where each method wins: its cheapest run that keeps a bound over the
    // whole run.
    struct Bound {
        const char *what;
        double LongRow::*measure;
        double limit;
    };
    const Bound bounds[] = {{"max|dH/H| < 1e-2", &LongRow::energy_error, 1e-2},
                            {"max|dH/H| < 1e-3", &LongRow::energy_error, 1e-3},
                            {"max|dH/H| < 1e-4", &LongRow::energy_error, 1e-4},
                            {"max|dH/H| < 1e-5", &LongRow::energy_error, 1e-5},
                            {"max|dC|/|C| < 1e-9", &LongRow::casimir_drift, 1e-9}};
    std::printf("\n   CPU seconds of each method's cheapest run that stays within the bound to T = %g\n"
                "   (- = none of its runs does):\n   %-14s", scene.final_time, "method");
    for (const Bound &b : bounds) std::printf(" %19s", b.what);
    std::printf("\n");
    for (const std::string &m : methods) {
        std::printf("   %-14s", m.c_str());
        for (const Bound &b : bounds) {
            const LongRow *cheapest = nullptr;
            for (const LongRow &r : rows)
                if (r.method == m && r.status == LPI_OK && r.*b.measure < b.limit &&
                    (!cheapest || r.cpu < cheapest->cpu))
                    cheapest = &r;
            if (cheapest)
                std::printf(" %9.3g (dt %5.3g)", cheapest->cpu, cheapest->dt);
            else
                std::printf(" %19s", "-");
        }
        std::printf("\n");
    }

    mkdir(out_dir.c_str(), 0777);
    const std::string base = out_dir + "/" + scene.name;
    write_long_csv(base, scene, rows);
    std::printf("   wrote %s.csv and %s_history.csv (every sample of every run)\n", base.c_str(), base.c_str());
    // The history plot compares the methods at about equal cost: the
    // geometric mean of all successful runs' CPU times.
    double log_sum = 0.0;
    int count = 0;
    for (const LongRow &r : rows)
        if (r.status == LPI_OK && r.cpu > 0.0) log_sum += std::log(r.cpu), ++count;
    if (!have_gnuplot())
        std::printf("   gnuplot not found: no PNG plots (apt-get install gnuplot-nox)\n");
    else if (count > 0 && plot_long(base, scene, rows, methods, std::exp(log_sum / count)))
        std::printf("   wrote %s_energy.png, %s_casimirs.png and %s_history.png\n", base.c_str(), base.c_str(),
                    base.c_str());
    else
        std::printf("   gnuplot failed: see %s.gp\n", base.c_str());
}

}  // namespace lpi_cli
