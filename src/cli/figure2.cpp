// The paper's Figure 2 reproduced: sine-Euler at N = 7, leapfrog, dt = 0.05,
// 10^5 steps (t = 5000), relative energy error and Casimir drift over time.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "output.hpp"
#include "plots.hpp"
#include "run_watch.hpp"
#include "scenes.hpp"
#include "systems.hpp"

namespace lpi_cli {

bool run_figure2(const std::string &out_dir) {
    const int N = 7;
    const double dt = 0.05;
    const int64_t steps = 100000, every = 100;
    Handle h = figure2_system();
    check(lpi_set_method(h.get(), "leapfrog"), h.get(), "set method");
    const double H0 = energy_of(h.get());
    double traces0[2], traces[2];
    check(lpi_sine_euler_casimir_traces(h.get(), 2, traces0), h.get(), "Casimir traces");
    std::vector<double> spectrum0(N), spectrum(N);
    const bool have_spectrum = lpi_casimirs(h.get(), spectrum0.data(), N) == LPI_OK;

    std::printf("\n== figure2: McLachlan 1993, Figure 2. N = 7, leapfrog, dt = %g, %lld steps\n", dt,
                static_cast<long long>(steps));
    std::printf("   field: |w| = 1 over one mode of each pair +-m (w_0 = 0), H(0) = %.15g\n", H0);
    const std::string csv = out_dir + "/figure2.csv";
    std::string text = "time,energy_error,c2_drift,spectrum_drift\n";
    double worst_first = 0.0, worst_second = 0.0, c2_drift = 0.0, spectrum_change = 0.0;
    const double t0 = cpu_seconds();
    for (int64_t done = 0; done < steps; done += every) {
        stop_if_interrupted();
        check(lpi_step(h.get(), dt, every), h.get(), "step");
        const double rel = (energy_of(h.get()) - H0) / H0;
        check(lpi_sine_euler_casimir_traces(h.get(), 2, traces), h.get(), "Casimir traces");
        c2_drift = std::fabs(traces[1] - traces0[1]) / traces0[1];
        // The spectrum every 10^4 steps; "nan" in the rows between (not measured).
        const bool spectrum_row = have_spectrum && (done + every) % 10000 == 0;
        if (spectrum_row) {
            check(lpi_casimirs(h.get(), spectrum.data(), N), h.get(), "spectrum");
            spectrum_change = spectrum_drift(spectrum, spectrum0);
        }
        (done < steps / 2 ? worst_first : worst_second) =
            std::max(done < steps / 2 ? worst_first : worst_second, std::fabs(rel));
        text += format("%.6g,%.6e,%.6e,", lpi_time(h.get()), rel, c2_drift) +
                (spectrum_row ? format("%.6e\n", spectrum_change) : std::string("nan\n"));
    }
    const double cpu = cpu_seconds() - t0;
    // The CSV goes in place with the image, or, where a file fails, neither does.
    PlotScript script(out_dir, "figure2.gp");
    const std::string data = script.data("figure2.csv", text);
    std::printf("   max |H - H0|/H0: %.3e over t in [0, 2500], %.3e over [2500, 5000]: %s\n",
                worst_first, worst_second,
                worst_second <= 1.5 * worst_first ? "bounded, no secular growth" : "GROWING");
    std::printf("   Casimir C2 = sum |w|^2: relative drift %.2e after 1e5 steps (%.2e per step;"
                " the paper saw about 5e-15 per step)\n", c2_drift, c2_drift / steps);
    if (have_spectrum)
        std::printf("   spectrum of W (all N Casimirs): relative drift %.2e (%.2e per step)\n",
                    spectrum_change, spectrum_change / steps);
    std::printf("   %.2f CPU seconds (diagnostics included)\n", cpu);
    if (!have_gnuplot()) {
        const std::string why = script.save_data();
        stop_if_interrupted();
        if (!why.empty()) return cannot_write(why);
        std::printf("   wrote %s; gnuplot not found: no PNG\n", csv.c_str());
        return true;
    }
    // The drift starts at round-off: its axis spans the decades from there.
    Range drift;
    drift.add(1e-16);
    drift.add(std::max(c2_drift, spectrum_change));
    script += "set datafile separator ','\nset grid\nset tics out nomirror\nset border 3\n"
              "set xlabel 'time'\nset key top left\n";
    const std::string commands =
        "set multiplot layout 2,1\nunset logscale y\nset autoscale y\nset ytics autofreq\nset mytics default\n"
        "set format y '%g'\nset title 'McLachlan 1993, Figure 2: sine-Euler N = 7, leapfrog, dt = 0.05' noenhanced\n"
        "set ylabel '(H(t) - H(0)) / H(0)  [10^{-5}]'\n"
        "plot " + data + " using 1:($2 * 1e5) every ::1 with lines lc rgb '#0072b2' notitle\n"
        "set title 'Casimir drift'\nset ylabel 'relative drift'\n" + decade_axis("y", drift.lo, drift.hi) +
        "plot " + data + " using 1:($3 > 0 ? $3 : 1/0) every ::1 with lines lc rgb '#d55e00' lw 1.5 "
        "title 'C_2 = {/Symbol S} |w|^2', " + data + " using 1:($4 > 0 ? $4 : 1/0) every ::1 with points "
        "lc rgb '#009e73' pt 7 ps 0.8 title 'spectrum of W (every 10^4 steps)'\nunset multiplot\n";
    script.add_figure("figure2", 1000, 700, commands);
    const std::string why = script.draw();
    stop_if_interrupted();  // gnuplot ended by the signal, or the files written
    if (!why.empty()) return cannot_write(why);
    std::printf("   wrote %s, %s/figure2.png and .svg\n", csv.c_str(), out_dir.c_str());
    return true;
}

}  // namespace lpi_cli
