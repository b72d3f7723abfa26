// `lpi report` of a long-run scene (sine-euler-long): what each method buys
// over the whole run. Each method at its own step sizes, run to the final time
// once per step, its maximum energy error and Casimir drift set against the CPU
// time of the steps; tables, CSV files and plots.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "output.hpp"
#include "plots.hpp"
#include "run_watch.hpp"
#include "report.hpp"

namespace lpi_cli {

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
    // Below 2^62 / samples: the whole run's count stays below 2^62 too.
    const int64_t per_sample = std::max<int64_t>(1, step_count(interval, dt, "lpi report " + scene.name));
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
        stop_if_interrupted();
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

// SCENE.csv and SCENE_history.csv, as data files of `script` (which puts them
// in place): the script's names of the two.
std::pair<std::string, std::string> long_csv(PlotScript &script, const LongRunScene &scene,
                                             const std::vector<LongRow> &rows) {
    std::string csv = "scene,run,method,order,poisson,dt,steps,cpu_seconds,max_energy_error,"
                      "max_casimir_drift,final_casimir_drift,reached_time,status\n";
    std::string history = "run,method,dt,time,energy_error,casimir_drift\n";
    for (const LongRow &r : rows) {
        const int i = method_index(r.method);
        csv += format("%s,%d,%s,%d,%d,%.17g,%lld,%.6e,%.6e,%.6e,%.6e,%.10g,%s\n", scene.name.c_str(), r.run,
                      r.method.c_str(), lpi_method_order(i), lpi_method_is_poisson(i), r.dt,
                      static_cast<long long>(r.steps), r.cpu, r.energy_error, r.casimir_drift,
                      r.final_casimir_drift, r.reached, lpi_status_name(r.status));
        for (const Sample &s : r.history)
            history += format("%d,%s,%.17g,%.10g,%.6e,%.6e\n", r.run, r.method.c_str(), r.dt, s.time,
                              s.energy_error, s.casimir_drift);
    }
    return {script.data(scene.name + ".csv", csv), script.data(scene.name + "_history.csv", history)};
}

// Max energy error and max Casimir drift against CPU time (one curve per
// method through its step sizes), and both against time for the run of each
// method whose CPU time is nearest `history_cpu`.
// "" or why not.
// `files`: the script's names of SCENE.csv and SCENE_history.csv.
std::string plot_long(PlotScript &script, const std::pair<std::string, std::string> &files,
                      const LongRunScene &scene, const std::vector<LongRow> &rows,
                      const std::vector<std::string> &methods, double history_cpu) {
    const std::string &base = scene.name;  // in dir
    script += csv_plot_preamble();
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
            commands += format("%s%s using (strcol(3) eq '%s' && strcol(13) eq 'LPI_OK' ? $8 : 1/0):"
                               "($%d > 0 ? $%d : 1/0) with linespoints %s lw 1.5 ps 1.5 title '%s, dt = %s' "
                               "noenhanced",
                               i ? ", " : "", files.first.c_str(), methods[i].c_str(), p.column, p.column,
                               plot_style(i, methods[i]).c_str(), method_label(methods[i]).c_str(),
                               format_steps(steps).c_str());
        }
        script.add_figure(base + "_" + p.file, 1000, 820, commands + "\n");
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
            commands += format("%s%s using ($1 == %d && (int($0) + %zu) %% %zu == 0 ? $4 : 1/0):"
                               "($%d > 0 ? $%d : 1/0) with points %s ps 1.1 notitle, "
                               "'' using ($1 == %d ? $4 : 1/0):($%d > 0 ? $%d : 1/0) with lines lc %s dt %d "
                               "lw 1.5 notitle, 1/0 with linespoints %s ps 1.1 lw 1.5 title '%s, dt = %g' noenhanced",
                               first ? "" : ", ", files.second.c_str(), nearest[i]->run, i * interval / methods.size(),
                               interval, c, c, plot_style(i, methods[i]).c_str(), nearest[i]->run, c, c,
                               plot_colour(i).c_str(), is_poisson(methods[i]) ? 1 : 2,
                               plot_style(i, methods[i]).c_str(), method_label(methods[i]).c_str(),
                               nearest[i]->dt);
            first = false;
        }
        commands += "\nunset key\n";
    }
    script.add_figure(base + "_history", 1000, 900, commands + "unset multiplot\n");
    return script.draw();
}

}  // namespace

bool run_long_scene(const LongRunScene &scene, const std::string &out_dir) {
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

    // The CSV files go in place with the images, or, where a file fails,
    // none does: the directory keeps the last report whole.
    const std::string base = out_dir + "/" + scene.name;
    PlotScript script(out_dir, scene.name + ".gp");
    const std::pair<std::string, std::string> files = long_csv(script, scene, rows);
    // The history plot compares the methods at about equal cost: the
    // geometric mean of all successful runs' CPU times.
    double log_sum = 0.0;
    int count = 0;
    for (const LongRow &r : rows)
        if (r.status == LPI_OK && r.cpu > 0.0) log_sum += std::log(r.cpu), ++count;
    const bool drawn = have_gnuplot() && count > 0;
    const std::string why = drawn ? plot_long(script, files, scene, rows, methods, std::exp(log_sum / count))
                                  : script.save_data();
    stop_if_interrupted();  // gnuplot ended by the signal, or the files written
    if (!why.empty()) return cannot_write(why);
    std::printf("   wrote %s.csv and %s_history.csv (every sample of every run)\n", base.c_str(), base.c_str());
    if (!have_gnuplot())
        std::printf("   gnuplot not found: no PNG plots (apt-get install gnuplot-nox)\n");
    else if (count == 0)
        std::printf("   no run succeeded: no plots\n");
    else
        std::printf("   wrote %s_energy.png, %s_casimirs.png and %s_history.png\n", base.c_str(), base.c_str(),
                    base.c_str());
    return true;
}

}  // namespace lpi_cli
