// `lpi report`, the work-precision sweep: every applicable method over the
// scene's step sizes, each cell timed and diagnosed, then the tables of CPU
// time at equal error, the CSV files and the plots.
#include "report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <cstdlib>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "output.hpp"
#include "plots.hpp"
#include "run_watch.hpp"

// OpenBLAS's own call, when an OpenBLAS is loaded where the program sees it
// (weak: null otherwise, and no link dependency).
extern "C" void openblas_set_num_threads(int) __attribute__((weak));

namespace lpi_cli {

// The report measures one core. OpenBLAS would otherwise spread the Casimir
// spectra (LAPACK) over helper threads that then busy-wait for about a tenth
// of a second, on the process's CPU clock, inside the next timed steps. The
// library loads LAPACK at the first spectrum (src/core/lapack.cpp), and
// OpenBLAS reads its thread count from the environment then; one loaded
// before (preloaded) takes its own call.
void measure_on_one_core() {
    setenv("OPENBLAS_NUM_THREADS", "1", 1);
    if (openblas_set_num_threads) openblas_set_num_threads(1);
}

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

// The final errors the tables give each method's CPU time at, largest first.
const double kTargets[] = {1e-2, 1e-4, 1e-6, 1e-8};

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

// The reference state at T, and what it is worth. A run's difference from
// the same method at twice its step bounds its truncation error wherever that
// method converges, but not its round-off, which a run at twice the step
// shares: on the pendulum, kahan-li-8 at dt = 0.005 differs by 2.9e-15 from
// its run at 0.01 and by 4e-14 from mclachlan-8 at 0.005. So the run of
// another method at the same step is asked too. An error within
// kResolvedOver times the first, or twice the second, is the reference's as
// much as the method's; the exact solution is worth its documented accuracy.
struct Reference {
    std::vector<double> state;
    double halving = 0.0;  // from the reference method at twice the step
    double other = 0.0;    // from kOtherReference at the same step
    double unresolved = 0.0;  // errors at or below this are not resolved
};
constexpr double kResolvedOver = 10.0;
constexpr const char *kOtherReference = "mclachlan-8";

std::vector<double> reference_run(const Scene &scene, const std::string &method, int64_t steps) {
    Handle h = scene.create();
    check(lpi_set_method(h.get(), method.c_str()), h.get(), "reference method");
    // Not timed: observed, to stop at a signal (observing changes no bit).
    check(lpi_set_observer(h.get(), observation_interval(h.get()), stop_at_signal, nullptr), h.get(), "observer");
    const int status = lpi_step(h.get(), scene.final_time / static_cast<double>(steps), steps);
    stop_if_interrupted();
    check(status, h.get(), "reference run");
    return state_of(h.get());
}

Reference reference_state(const Scene &scene) {
    Reference reference;
    if (scene.exact_reference) {
        Handle h = scene.create();
        reference.state.resize(lpi_dim(h.get()));
        check(lpi_rigid_body_exact(h.get(), scene.final_time, reference.state.data()), h.get(),
              "exact solution");
        reference.unresolved = scene.exact_accuracy;
        return reference;
    }
    const int64_t n = std::max<int64_t>(2, 2 * (step_count(scene.final_time, scene.reference_step, "lpi report " + scene.name) / 2));
    reference.state = reference_run(scene, scene.reference_method, n);
    reference.halving = distance(reference.state, reference_run(scene, scene.reference_method, n / 2));
    reference.other = distance(reference.state, reference_run(scene, kOtherReference, n));
    reference.unresolved = std::max(kResolvedOver * reference.halving, 2.0 * reference.other);
    return reference;
}

// Its Casimirs are the spectrum of W (casimir_drift measures them as one).
bool is_sine_euler(const lpi_system *sys) { return std::strcmp(lpi_kind(sys), "sine-euler") == 0; }

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
        stop_if_interrupted();
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
    row.steps = std::max<int64_t>(1, step_count(scene.final_time, dt, "lpi report " + scene.name));
    row.dt = scene.final_time / static_cast<double>(row.steps);
    double elapsed = 0.0;
    int repeats = 0;
    std::vector<double> end;
    do {
        stop_if_interrupted();
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
// sweep. `bound` is set when even the largest step that ran beats the target
// (the figure is then an upper bound), unless that step spans T: no run of
// the method costs less; NaN when the sweep does not reach it.
double cpu_at_error(const std::vector<Row> &rows, const std::string &method, double target,
                    bool *bound) {
    const Row *previous = nullptr;
    *bound = false;
    for (const Row &r : rows) {
        if (r.method != method || !(r.error > 0.0) || std::isnan(r.cpu)) continue;
        if (!previous && r.error <= target) {
            *bound = r.steps > 1;
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

// The CSV files' text.
std::string csv_text(const std::vector<Row> &rows, const Scene &scene) {
    std::string text = "scene,method,order,dt,steps,cpu_seconds,error,max_energy_error,max_casimir_drift,status\n";
    for (const Row &r : rows)
        text += format("%s,%s,%d,%.17g,%lld,%.6e,%.6e,%.6e,%.6e,%s\n", scene.name.c_str(), r.method.c_str(),
                       r.order, r.dt, static_cast<long long>(r.steps), r.cpu, r.error, r.energy_error,
                       r.casimir_drift, lpi_status_name(r.status));
    return text;
}

std::string history_text(const std::map<std::string, History> &histories) {
    std::string text = "method,dt,time,energy_error,casimir_drift\n";
    for (const auto &[method, history] : histories)
        for (const Sample &s : history.samples)
            text += format("%s,%.17g,%.10g,%.6e,%.6e\n", method.c_str(), history.dt, s.time, s.energy_error,
                           s.casimir_drift);
    return text;
}

// Draws the work-precision and energy plots with gnuplot from the CSV files
// (`sweep` and `history`: the script's names of its data files), which it
// puts in place with the images. "" or why not.
std::string plot(PlotScript &script, const std::string &sweep, const std::string &history, const Scene &scene,
                 const std::vector<std::string> &methods, const std::vector<Row> &rows,
                 const std::map<std::string, History> &histories) {
    script += csv_plot_preamble();
    const std::string &base = scene.name;  // in dir
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
        commands += format("%s%s using (strcol(2) eq '%s' && strcol(10) eq 'LPI_OK' ? $6 : 1/0):7 "
                           "with linespoints %s lw 1.5 ps 1.2 title '%s' noenhanced",
                           i ? ", " : "", sweep.c_str(), methods[i].c_str(), plot_style(i, methods[i]).c_str(),
                           method_label(methods[i]).c_str());
    script.add_figure(base + "_work_precision", 1000, 820, commands + "\n");

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
        commands += format("%s%s using (strcol(1) eq '%s' && (int($0) + %zu) %% %zu == 0 ? $3 : 1/0):"
                           "($4 > 0 ? $4 : 1/0) with points %s ps 1.1 notitle, "
                           "'' using (strcol(1) eq '%s' ? $3 : 1/0):($4 > 0 ? $4 : 1/0) with lines lc %s dt %d "
                           "lw 1.2 notitle, 1/0 with linespoints %s ps 1.1 lw 1.2 title '%s' noenhanced",
                           i ? ", " : "", history.c_str(), methods[i].c_str(), i * interval / methods.size(), interval,
                           plot_style(i, methods[i]).c_str(), methods[i].c_str(), plot_colour(i).c_str(),
                           is_poisson(methods[i]) ? 1 : 2, plot_style(i, methods[i]).c_str(),
                           method_label(methods[i]).c_str());
    }
    script.add_figure(base + "_energy", 1000, 820, commands + "\n");
    return script.draw();
}

}  // namespace

bool run_report(const Scene &scene, const ReportOptions &options) {
    measure_on_one_core();
    const std::string why_not = scene.unavailable();
    if (!why_not.empty()) {
        std::printf("\n== %s: skipped in this build: %s\n", scene.name.c_str(), why_not.c_str());
        return true;
    }
    if (scene.custom_run) return scene.custom_run(options.out_dir);
    const Reference reference = reference_state(scene);
    const double unresolved = reference.unresolved;
    std::printf("\n== %s: %s, T = %g\n", scene.name.c_str(), scene.description.c_str(),
                scene.final_time);
    if (scene.exact_reference)
        std::printf("   reference: the exact solution; error = |x(T) - x_exact(T)|\n"
                    "   lpi_rigid_body_exact(3) is accurate to %.1e here\n", unresolved);
    else
        std::printf("   reference: %s with dt = %g; error = |x(T) - x_ref(T)|\n"
                    "   the reference differs by %.1e from its run at twice the step and by %.1e from\n"
                    "   %s at its step\n",
                    scene.reference_method.c_str(), scene.reference_step, reference.halving,
                    reference.other, kOtherReference);
    std::printf("   errors below %.2e are not resolved by the reference (marked ~ref)\n", unresolved);
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
    const int64_t history_steps = std::max<int64_t>(1, step_count(scene.final_time, history_dt, "lpi report " + scene.name));
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
        std::vector<Row> sweep;  // largest step first
        for (double base_dt : scene.steps) {
            const double dt = std::min(base_dt * stretch, scene.final_time);
            // Stretched steps near T round to the same step count: measure it once.
            const int64_t steps = std::max<int64_t>(1, step_count(scene.final_time, dt, "lpi report " + scene.name));
            if (!sweep.empty() && steps == sweep.back().steps) continue;
            sweep.push_back(measure(scene, method, lpi_method_order(i), dt, reference.state, options));
        }
        // Where the largest step already beats the largest target, its time
        // there is only an upper bound of the time to the target (suzuki-4 on
        // sine-Euler N = 7: < 1.5e-4 s at an error 24 times below 1e-2,
        // where 7.4e-5 s reach it), and the comparisons below named a slower
        // method the best: steps twice as large until the error passes it
        // (or one step spans T, or a step fails).
        while (sweep.front().status == LPI_OK && sweep.front().error < kTargets[0] && sweep.front().steps > 1) {
            const double dt = std::min(2.0 * sweep.front().dt, scene.final_time);
            const int64_t steps = std::max<int64_t>(1, step_count(scene.final_time, dt, "lpi report " + scene.name));
            if (steps == sweep.front().steps) break;
            sweep.insert(sweep.begin(), measure(scene, method, lpi_method_order(i), dt, reference.state, options));
        }
        for (const Row &r : sweep) {
            rows.push_back(r);
            std::printf("%-24s %9.4g %9lld %11.3e %11.3e %11.3e %11.3e %10.1f  %s\n", r.method.c_str(),
                        r.dt, static_cast<long long>(r.steps), r.cpu, r.error, r.energy_error,
                        r.casimir_drift, 1e9 * r.cpu / static_cast<double>(r.steps),
                        r.status != LPI_OK ? lpi_status_name(r.status) : r.error <= unresolved ? "~ref" : "");
        }
        History &history = histories[method];
        history.dt = scene.final_time / static_cast<double>(history_steps);
        history.samples = diagnose(scene, method, history.dt, history_steps, options.samples);
    }

    std::printf("\n   CPU seconds to reach a final error (interpolated along each sweep;\n   < = reached at the largest step that ran, an upper bound; - = not reached;\n   ~ref = not resolved by the reference):\n");
    std::printf("   %-24s", "method");
    for (double t : kTargets) std::printf(" %11.0e", t);
    std::printf("\n");
    for (const std::string &m : methods) {
        std::printf("   %-24s", m.c_str());
        for (double t : kTargets) {
            bool bound = false;
            const double c = cpu_at_error(rows, m, t, &bound);
            if (t <= unresolved)
                std::printf(" %11s", "~ref");
            else if (std::isnan(c))
                std::printf(" %11s", "-");
            else
                std::printf(" %s%10.3e", bound ? "<" : " ", c);
        }
        std::printf("\n");
    }

    // At equal final error: each baseline's CPU time over the best Poisson
    // (splitting) method's. A time reached at the largest step that ran is an
    // upper bound ('<'); it still counts (leaving it out named a slower
    // method the best), and a ratio over it is then a lower bound ('>').
    std::printf("\n   at equal final error, CPU time of each baseline over the best splitting method\n"
                "   (< an upper bound, > a lower bound: reached at the largest step that ran):\n");
    std::vector<std::string> splittings, baselines;  // the methods swept, in table order
    for (const std::string &m : methods) (is_poisson(m) ? splittings : baselines).push_back(m);
    for (double t : kTargets) {
        if (t <= unresolved) continue;
        double best = kNaN;
        bool best_bound = false;
        std::string best_method;
        for (const std::string &m : splittings) {
            bool bound = false;
            const double c = cpu_at_error(rows, m, t, &bound);
            if (c > 0.0 && !(c >= best)) best = c, best_method = m, best_bound = bound;
        }
        if (std::isnan(best)) continue;
        // A splitting whose time is only an upper bound may need less than
        // the best time found: that is then an upper bound of the best too.
        std::string maybe_cheaper;
        for (const std::string &m : splittings) {
            bool bound = false;
            cpu_at_error(rows, m, t, &bound);
            if (bound && !best_bound && m != best_method && maybe_cheaper.empty()) maybe_cheaper = m;
        }
        if (maybe_cheaper.empty())
            std::printf("   error %.0e: best splitting %s %s%.3e s;", t, best_method.c_str(),
                        best_bound ? "<" : "", best);
        else
            std::printf("   error %.0e: best splitting %s %.3e s, or %s for less (reached at the largest step "
                        "that ran);", t, best_method.c_str(), best, maybe_cheaper.c_str());
        best_bound = best_bound || !maybe_cheaper.empty();
        for (const std::string &m : baselines) {
            bool bound = false;
            const double c = cpu_at_error(rows, m, t, &bound);
            if (std::isnan(c))
                std::printf(" %s not reached;", m.c_str());
            else if (bound && best_bound)
                std::printf(" %s reached at the largest step that ran too;", m.c_str());
            else
                std::printf(" %s %s%.2fx;", m.c_str(), bound ? "<" : best_bound ? ">" : "", c / best);
        }
        std::printf("\n");
    }

    // The CSV files go in place with the images, or, where a file fails,
    // none does: the directory keeps the last report whole.
    const std::string base = options.out_dir + "/" + scene.name;
    PlotScript script(options.out_dir, scene.name + ".gp");
    const std::string sweep = script.data(scene.name + ".csv", csv_text(rows, scene));
    const std::string energy = script.data(scene.name + "_energy.csv", history_text(histories));
    const std::string why = have_gnuplot() ? plot(script, sweep, energy, scene, methods, rows, histories)
                                           : script.save_data();
    stop_if_interrupted();  // gnuplot ended by the signal, or the files written
    if (!why.empty()) return cannot_write(why);
    std::printf("   wrote %s.csv and %s_energy.csv (energy history of every method at dt = %g)\n", base.c_str(),
                base.c_str(), scene.final_time / static_cast<double>(history_steps));
    if (!have_gnuplot())
        std::printf("   gnuplot not found: no PNG plots (apt-get install gnuplot-nox)\n");
    else
        std::printf("   wrote %s_work_precision.png and %s_energy.png, each with .svg\n", base.c_str(),
                    base.c_str());
    return true;
}

}  // namespace lpi_cli
