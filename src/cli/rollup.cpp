// The question McLachlan 1993 ends on: does the vorticity of sine-Euler roll
// up into the highest modes over long times? A smooth field is run long with
// leapfrog; the enstrophy fraction in the highest third of the shells is
// written against time, and the enstrophy spectrum at a few times.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "fields.hpp"
#include "output.hpp"
#include "plots.hpp"
#include "run_watch.hpp"
#include "scenes.hpp"
#include "systems.hpp"

namespace lpi_cli {

namespace {

struct Spectra {
    std::vector<double> energy, enstrophy;  // shell k at entry k - 1
};

Spectra spectra_of(const lpi_system *sys) {
    size_t shells = 0;
    check(lpi_sine_euler_spectrum(sys, nullptr, nullptr, 0, &shells), sys, "spectrum");  // a query of K
    Spectra s{std::vector<double>(shells), std::vector<double>(shells)};
    check(lpi_sine_euler_spectrum(sys, s.energy.data(), s.enstrophy.data(), shells, &shells), sys, "spectrum");
    return s;
}

// The fraction of the enstrophy in shells k > 2K/3 (K shells in all).
double high_fraction(const std::vector<double> &enstrophy) {
    const std::size_t K = enstrophy.size(), first = (2 * K) / 3;
    double high = 0.0, all = 0.0;
    for (std::size_t k = 0; k < K; ++k) {
        all += enstrophy[k];
        if (k >= first) high += enstrophy[k];
    }
    return all > 0.0 ? high / all : 0.0;
}

}  // namespace

int run_rollup(const OwnRun &run) {
    const int N = run.N > 0 ? run.N : 63;
    const int64_t steps = run.steps > 0 ? run.steps : 100000;
    const double dt = run.dt > 0.0 ? run.dt : 0.05;
    // Row r is written after step r * steps / rows (whole steps, the last at `steps`).
    const int64_t rows = std::min<int64_t>(steps, 500);
    auto row_end = [&](int64_t r) { return steps / rows * r + steps % rows * r / rows; };
    // The spectrum is kept at the start and after 1/100, 1/10 and all of the run.
    const std::vector<int64_t> spectrum_rows = {0, std::max<int64_t>(1, rows / 100),
                                                std::max<int64_t>(1, rows / 10), rows};
    Handle h = sine_euler(N, smooth_field);
    lpi_system *sys = h.get();
    check(lpi_set_method(sys, "leapfrog"), sys, "set method");
    const double H0 = energy_of(sys);
    double Z0 = 0.0;
    check(lpi_sine_euler_enstrophy(sys, &Z0), sys, "enstrophy");
    Spectra s0 = spectra_of(sys);
    const std::size_t K = s0.enstrophy.size();
    std::printf("\n== rollup: does the vorticity roll up into the high modes? sine-Euler N = %d, "
                "leapfrog, dt = %g, %lld steps (t = %g)\n",
                N, dt, static_cast<long long>(steps), dt * static_cast<double>(steps));
    std::printf("   smooth random field (|w_m| ~ exp(-|m|^2/18)); %zu shells, the highest third: "
                "k > %zu\n", K, (2 * K) / 3);
    const std::string no_dir = make_output_dir(run.out_dir);
    if (!no_dir.empty()) {
        std::fprintf(stderr, "lpi run: --out %s\n", no_dir.c_str());
        return 1;
    }
    const std::string base = run.out_dir + "/rollup", csv = base + ".csv", spectra = base + "_spectra.csv";
    for (const std::string &path : {csv, spectra}) {
        const std::string why = output_problem(path);
        if (!why.empty()) return cannot_write(why), 1;
    }
    std::string rows_text = "time,energy_error,enstrophy_error,high_third_fraction\n";
    rows_text += format("0,0,0,%.17g\n", high_fraction(s0.enstrophy));
    std::vector<Spectra> kept = {s0};
    std::vector<double> kept_times = {0.0};
    // Both files, as far as the run got (also when it is interrupted or a step
    // fails): "" or why not.
    auto write_files = [&] {
        std::string text = "k";
        for (double t : kept_times) text += format(",enstrophy_t%g", t);
        text += "\n";
        for (std::size_t k = 0; k < K; ++k) {
            text += std::to_string(k + 1);
            for (const Spectra &s : kept) text += format(",%.17g", s.enstrophy[k]);
            text += "\n";
        }
        const std::string why = write_output(csv, rows_text);
        return why.empty() ? write_output(spectra, text) : why;
    };
    double first_fraction = high_fraction(s0.enstrophy), late_sum = 0.0, peak = first_fraction;
    int64_t late_rows = 0;
    // Ctrl-C and SIGTERM stop the run as they stop lpi run (lpi(1)): within a
    // few steps, through the observer, with a row at the step reached.
    catch_interrupts();
    std::printf("   stepping (Ctrl-C stops it, writing the rows so far)\n");
    std::fflush(stdout);
    Progress progress(0, steps);
    Watch watch;
    watch.progress = &progress;
    check(lpi_set_observer(sys, observation_interval(sys), watch_steps, &watch), sys, "set observer");
    const double t0 = cpu_seconds();
    int64_t done = 0;
    int status = LPI_OK;
    for (int64_t r = 1; r <= rows && !interrupted_by; ++r) {
        watch.call_start = done;
        status = lpi_step(sys, dt, row_end(r) - done);
        if (status != LPI_OK && status != LPI_STOPPED) break;
        done = status == LPI_STOPPED ? watch.stopped_at : row_end(r);
        const Spectra s = spectra_of(sys);
        double Z = 0.0;
        check(lpi_sine_euler_enstrophy(sys, &Z), sys, "enstrophy");
        const double fraction = high_fraction(s.enstrophy);
        peak = std::max(peak, fraction);
        if (2 * r > rows) late_sum += fraction, ++late_rows;
        rows_text += format("%.17g,%.17g,%.17g,%.17g\n", lpi_time(sys), (energy_of(sys) - H0) / H0, (Z - Z0) / Z0,
                            fraction);
        if (status == LPI_STOPPED) break;
        progress.update(done);
        if (std::find(spectrum_rows.begin(), spectrum_rows.end(), r) != spectrum_rows.end()) {
            kept.push_back(s);
            kept_times.push_back(lpi_time(sys));
        }
    }
    progress.finish();
    const double cpu = cpu_seconds() - t0;
    const std::string why = write_files();
    if (status != LPI_OK && status != LPI_STOPPED) {
        std::fprintf(stderr, "lpi run: rollup: step %lld failed: %s (%s); %s ends there\n",
                     static_cast<long long>(done), lpi_last_error(sys), lpi_status_name(status), csv.c_str());
        if (!why.empty()) cannot_write(why);
        return 1;
    }
    if (!why.empty()) return cannot_write(why), 1;
    if (interrupted_by) {
        std::printf("interrupted at step %lld (t = %.17g); wrote %s and %s\n", static_cast<long long>(done),
                    lpi_time(sys), csv.c_str(), spectra.c_str());
        return 128 + interrupted_by;
    }
    // Equipartition of the enstrophy over the modes puts in each shell its
    // share of the modes: the fraction the highest third would hold then.
    std::vector<double> modes_per_shell(K, 0.0);
    for (int a = -(N / 2); a <= N / 2; ++a)
        for (int b = -(N / 2); b <= N / 2; ++b) {
            const std::size_t k = static_cast<std::size_t>(std::floor(std::sqrt(double(a * a + b * b)) + 0.5));
            if (k > 0) modes_per_shell[k - 1] += 1.0;
        }
    std::printf("   enstrophy fraction in the highest third: %.3g at t = 0, peak %.3g, mean %.3g over "
                "the second half (%.3g if the enstrophy were spread evenly over the modes)\n",
                first_fraction, peak, late_rows ? late_sum / late_rows : first_fraction,
                high_fraction(modes_per_shell));
    std::printf("   %.1f CPU seconds; wrote %s.csv and %s_spectra.csv\n", cpu, base.c_str(), base.c_str());
    if (!have_gnuplot()) {
        std::printf("   gnuplot not found: no PNG\n");
        return 0;
    }
    PlotScript script(run.out_dir, "rollup.gp");
    std::string commands = format(
        "set datafile separator ','\nset grid\nset tics out nomirror\nset border 3\n"
        "set multiplot layout 1,2\nset title 'enstrophy in the highest third of the shells' noenhanced\n"
        "set xlabel 'time'\nset ylabel 'fraction'\nset key bottom right\n"
        "plot 'rollup.csv' using 1:4 every ::1 with lines lc rgb '#0072b2' title 'sine-Euler N = %d', "
        "%g with lines dt 2 lc rgb '#999999' title 'equipartition'\n"
        "set title 'enstrophy spectrum' noenhanced\nset xlabel 'shell k'\nset ylabel 'Z(k)'\n"
        "set logscale x\nset key bottom left\n",
        N, high_fraction(modes_per_shell));
    // The y axis spans the spectra after the start: the smooth initial one
    // falls to 1e-90 and is drawn only where it is within that range.
    Range range;
    for (std::size_t i = 1; i < kept.size(); ++i)
        for (double z : kept[i].enstrophy) range.add(z);
    for (double z : kept[0].enstrophy) range.add(std::max(z, range.lo));
    commands += decade_axis("y", range.lo, range.hi) + "plot ";
    for (std::size_t i = 0; i < kept.size(); ++i)
        commands += format("%s'rollup_spectra.csv' using 1:($%zu > 0 ? $%zu : 1/0) with linespoints lc %s "
                           "pt 7 ps 0.5 title 't = %g'",
                           i ? ", " : "", i + 2, i + 2, plot_colour(i).c_str(), kept_times[i]);
    commands += "\nunset multiplot\n";
    script.add_figure("rollup", 1100, 450, commands);
    const std::string not_drawn = script.draw();
    if (interrupted_by) return interrupted_drawing(not_drawn.empty(), run.out_dir + "/rollup.gp");
    if (!not_drawn.empty()) return cannot_write(not_drawn), 1;
    std::printf("   wrote %s.png and .svg\n", base.c_str());
    return 0;
}

}  // namespace lpi_cli
