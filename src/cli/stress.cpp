// lpi stress: the stiff and extreme cases of every system against every
// applicable method. Per case, step and method it prints whether the run stayed
// bounded, the largest relative energy error and Casimir drift seen at the
// samples, and the outcome status; a failed lpi_step is checked to have
// left the state as it was, bit for bit.
//
// What must hold (the exit status is 1 otherwise):
//  - a Poisson method never fails on finite input (status LPI_OK) unless the
//    exact flow of a piece itself overflows, and keeps every Casimir to
//    round-off: relative drift at most a floor plus kDriftPerFlow per exact
//    piece flow (a linear bound, the worst case of accumulated round-off;
//    generic so(3)'s rotations take their shears from sin and cos of the
//    angle, whatever its size, not by scaling and squaring, which grew the
//    error with ||t A|| and had the bound grown alike, 1164 times at 1e3
//    periods), and kUnboundedSlack times that on a run that did not stay
//    bounded;
//  - every failure (rk4 beyond its stability limit, implicit-midpoint not
//    converging) is a documented status with the state rolled back bit for bit.
//
// Casimir drift is |C(t) - C(0)| / max S, where S is the magnitude of C's
// terms (the scale of its round-off), maximised over the samples so far
// (round-off made while the terms were large stays in the state): C itself for sums of squares (|m|^2, x1^2 + x2^2), the largest
// |eigenvalue| for the sine-Euler spectrum, and for the moment invariants I, K
// the sum of the absolute values of their monomials. The latter are evaluated
// here in long double from the public state (x87 extended range reaches
// 1e4932), so states with entries near 1e150, where K ~ 1e450 overflows a
// double, still get a finite, relative measure.
#include "stress.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "stress_cases.hpp"

namespace lpi_cli {

namespace {

constexpr double kDriftPerFlow = 1e-15;  // about 4.5 unit round-offs per flow
// A run that grows (an unstable composition of the moment algebra's shears)
// makes its round-off at terms its samples do not see: inside a step whose
// substeps grow and shrink them again. Sampling every step changes nothing
// measured; sofroniou-spaletta-10 at dt = one period drifts 8 times the
// bound. So such a run is judged against a looser bound, which a Casimir
// actually lost (a drift of order 1 at these steps) still fails.
constexpr double kUnboundedSlack = 1e4;

struct Outcome {
    int status = LPI_OK;
    bool rolled_back = true;   // meaningful when status != LPI_OK
    bool bounded = true;
    double energy_error = 0.0;
    bool absolute_energy_error = false;  // H(0) = 0: |H - H(0)|, not relative
    double casimir_drift = 0.0;
    std::int64_t steps_done = 0;
    std::size_t flows_per_step = 1;
    std::string message;  // lpi_last_error of a failure
};

double max_abs(const std::vector<double> &x) {
    double m = 0.0;
    for (double v : x) m = std::max(m, std::fabs(v));
    return m;
}

bool all_finite(const std::vector<double> &x) {
    for (double v : x)
        if (!std::isfinite(v)) return false;
    return true;
}

void library_casimirs(const lpi_system *sys, std::vector<long double> &c) {
    std::vector<double> values(lpi_casimir_count(sys));
    check(lpi_casimirs(sys, values.data(), values.size()), sys, "casimirs");
    c.assign(values.begin(), values.end());
}

Outcome run_case(const Case &k, const std::string &method, double dt) {
    Outcome out;
    Handle h = k.create();
    lpi_system *sys = h.get();
    check(lpi_set_method(sys, method.c_str()), sys, "set method");
    check(lpi_flows_per_step(sys, &out.flows_per_step), sys, "flows per step");
    const std::vector<double> x0 = state_of(sys);
    const double h0 = energy_of(sys);
    const double bound = 1e3 * std::max(max_abs(x0), DBL_MIN);

    std::vector<long double> c0, s0, c, s;
    auto measure = [&](const std::vector<double> &x, std::vector<long double> &values,
                       std::vector<long double> *scale) {
        if (k.measure) {
            std::vector<long double> sc;
            k.measure(x, values, sc);
            if (scale) *scale = sc;
            return;
        }
        library_casimirs(sys, values);
        if (!scale) return;
        long double largest = 0.0L;
        for (long double v : values) largest = std::max(largest, std::fabs(v));
        scale->assign(values.size(), 0.0L);
        for (std::size_t q = 0; q < values.size(); ++q)
            (*scale)[q] = k.spectrum_scale ? largest : std::fabs(values[q]);
    };
    measure(x0, c0, &s0);

    const int chunks = static_cast<int>(std::min<std::int64_t>(k.samples, k.steps));
    std::int64_t done = 0;
    for (int chunk = 0; chunk < chunks; ++chunk) {
        const std::int64_t target = k.steps * (chunk + 1) / chunks;
        const std::vector<double> before = state_of(sys);
        const double time_before = lpi_time(sys);
        const int status = lpi_step(sys, dt, target - done);
        if (status != LPI_OK) {
            const std::vector<double> after = state_of(sys);
            const double time_after = lpi_time(sys);
            out.status = status;
            out.message = lpi_last_error(sys);
            out.rolled_back =
                std::memcmp(before.data(), after.data(), before.size() * sizeof(double)) == 0 &&
                std::memcmp(&time_before, &time_after, sizeof(double)) == 0;
            break;
        }
        done = target;
        const std::vector<double> x = state_of(sys);
        if (!all_finite(x) || max_abs(x) > bound) out.bounded = false;
        const double e = energy_of(sys);
        out.absolute_energy_error = h0 == 0.0;
        const double de = std::fabs(e - h0) / (h0 != 0.0 ? std::fabs(h0) : 1.0);
        out.energy_error = std::max(out.energy_error, std::isfinite(de) ? de : INFINITY);
        measure(x, c, &s);
        for (std::size_t q = 0; q < c.size(); ++q) {
            s0[q] = std::max(s0[q], s[q]);  // the largest scale met so far
            long double scale = s0[q];
            if (!(scale > 0.0L)) scale = 1.0L;
            const double drift = static_cast<double>(std::fabs(c[q] - c0[q]) / scale);
            out.casimir_drift = std::max(out.casimir_drift, std::isfinite(drift) ? drift : INFINITY);
        }
    }
    out.steps_done = done;
    return out;
}

void print_usage(FILE *to) {
    std::fprintf(to,
                 "usage: lpi stress [--quick] [FILTER]\n"
                 "  Runs the stiff and extreme cases against every applicable method\n"
                 "  (--quick: seconds, shorter runs; otherwise minutes, with 10^7-step\n"
                 "  rigid-body and 10^6-step sine-Euler runs). FILTER keeps the cases whose\n"
                 "  name contains it. Exit status 1 when a property that must hold failed.\n");
}

}  // namespace

int stress_command(int argc, char **argv) {
    bool quick = false;
    std::string filter;
    Arguments args("lpi stress", argc, argv);
    while (!args.done()) {
        const std::string arg = args.next();
        if (arg == "--quick") {
            args.flag(arg);
            quick = true;
        } else if (args.help(arg)) {
            print_usage(stdout);
            return 0;
        } else {
            args.operand(arg, "FILTER");
            if (!filter.empty()) args.fail("one FILTER only ('" + filter + "' and '" + arg + "')");
            filter = arg;
        }
    }
    const std::vector<Case> cases = build_cases(quick);
    if (std::none_of(cases.begin(), cases.end(), [&](const Case &k) { return k.name.find(filter) != std::string::npos; }))
        args.fail("no case name contains '" + filter + "'");
    std::printf("liepoisson %s: stress cases (%s)\n", lpi_version_string(), quick ? "quick" : "full");
    std::printf("energy error and Casimir drift are relative maxima over the samples (the energy\n"
                "error |H - H(0)| itself where H(0) = 0, marked 'abs');\n"
                "bounded: finite and max|x| <= 1e3 max|x(0)| at every sample ('-': the run failed\n"
                "before its first sample); must-hold failures are marked '!!'\n");
    int violations = 0, runs = 0;
    for (const Case &k : cases) {
        if (!filter.empty() && k.name.find(filter) == std::string::npos) continue;
        if (k.period > 0.0)
            std::printf("\n== %s (fastest period %.3g)\n", k.name.c_str(), k.period);
        else
            std::printf("\n== %s\n", k.name.c_str());
        std::printf("   %-9s %-9s %-22s %-22s %-7s %-10s %-10s %s\n", k.period > 0.0 ? "dt/period" : "dt", "steps",
                    "method", "status", "bounded", "max dH/H", "C drift", "");
        const std::vector<bool> accepted = accepted_methods(k.create);
        for (double factor : k.factors) {
            const double dt = k.period > 0.0 ? factor * k.period : factor;
            for (int m = 0; m < lpi_method_count(); ++m) {
                const std::string method = lpi_method_name(m);
                if (!k.methods.empty() &&
                    std::find(k.methods.begin(), k.methods.end(), method) == k.methods.end())
                    continue;
                if (!accepted[static_cast<std::size_t>(m)]) continue;  // e.g. isomp off sine-Euler
                const bool poisson = lpi_method_is_poisson(m) == 1;
                const Outcome o = run_case(k, method, dt);
                ++runs;
                std::string verdict;
                if (o.status != LPI_OK && !o.rolled_back) verdict += " !! state not rolled back";
                if (o.status == LPI_ERR_INTERNAL) verdict += " !! internal error";
                if (poisson && o.status != LPI_OK && o.status != k.allowed_failure) verdict += " !! Poisson method failed";
                const double tolerance =
                    (k.drift_floor +
                     kDriftPerFlow * static_cast<double>(o.flows_per_step) * static_cast<double>(o.steps_done)) *
                    (o.bounded ? 1.0 : kUnboundedSlack);
                if (poisson && !(o.casimir_drift <= tolerance)) verdict += " !! Casimir drift";
                if (!verdict.empty()) ++violations;
                std::string status = lpi_status_name(o.status);
                if (o.status != LPI_OK) status += o.rolled_back ? " (rolled back)" : "";
                // A run that failed before its first sample measured nothing;
                // one that failed later is bounded or not over what it ran.
                const bool measured = o.steps_done > 0;
                const std::string energy_error =
                    measured ? format("%.2e%s", o.energy_error, o.absolute_energy_error ? " abs" : "")
                             : "-";
                const std::string drift = measured ? format("%.2e", o.casimir_drift) : "-";
                std::printf("   %-9.0e %-9lld %-22s %-22s %-7s %-10s %-10s%s\n", factor,
                            static_cast<long long>(o.steps_done), method.c_str(), status.c_str(),
                            !measured ? "-" : o.bounded ? "yes" : "no", energy_error.c_str(),
                            drift.c_str(), verdict.c_str());
                if (o.status != LPI_OK) std::printf("      %s\n", o.message.c_str());
                std::fflush(stdout);
            }
        }
    }
    std::printf("\n%d runs, %d with a must-hold failure\n", runs, violations);
    return violations == 0 ? 0 : 1;
}

}  // namespace lpi_cli

