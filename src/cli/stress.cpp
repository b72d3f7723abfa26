// lpi stress: the stiff and extreme cases of every system against every
// applicable method. Per case, step and method it prints whether the run stayed
// bounded, the largest relative energy error and Casimir drift seen at the
// checkpoints, and the outcome status; a failed lpi_step is checked to have
// left the state as it was, bit for bit.
//
// What must hold (the exit status is 1 otherwise):
//  - a Poisson method never fails on finite input (status LPI_OK) unless the
//    exact flow of a piece itself overflows, and keeps every Casimir to
//    round-off: relative drift at most a floor plus kDriftPerFlow per exact
//    piece flow (a linear bound, the worst case of accumulated round-off; for
//    generic systems times ||t A|| / 5.4, the error growth of scaling and
//    squaring), judged on runs that stayed bounded;
//  - every failure (rk4 beyond its stability limit, implicit-midpoint not
//    converging) is a documented status with the state rolled back bit for bit.
//
// Casimir drift is |C(t) - C(0)| / max S, where S is the magnitude of C's
// terms (the scale of its round-off), maximised over the checkpoints so far
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

#include "common.hpp"

namespace lpi_cli {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Extra measured quantities a case may compute itself (moments).
using CasimirMeasure = std::function<void(const std::vector<double> &x, std::vector<long double> &c,
                                          std::vector<long double> &scale)>;

struct Case {
    std::string name;
    std::function<Handle()> create;  // configured system with its initial state
    double period = 1.0;             // fastest period; steps are multiples of it
    std::vector<double> factors;     // dt = factor * period
    std::int64_t steps = 1000;
    std::vector<std::string> methods;  // empty: every method
    CasimirMeasure measure;            // empty: lpi_casimirs, scale from kind below
    bool spectrum_scale = false;       // scale = max |C_k(0)| (eigenvalues)
    int checkpoints = 20;
    // Casimir round-off allowed to a Poisson method: floor (the measurement's
    // own round-off) + per_flow * flows * growth(factor), growth = 1 except
    // for the generic Pade path (each squaring doubles its error).
    double drift_floor = 1e-15;
    bool pade_growth = false;
    // A status a Poisson method may return here (rolled back) instead of
    // stepping: LPI_ERR_NONFINITE where the exact flow of a piece overflows,
    // LPI_ERR_INVALID where a generic flow needs too many squarings.
    int allowed_failure = LPI_OK;
};

constexpr double kDriftPerFlow = 1e-15;  // about 4.5 unit round-offs per flow

struct Outcome {
    int status = LPI_OK;
    bool rolled_back = true;   // meaningful when status != LPI_OK
    bool bounded = true;
    double energy_error = 0.0;
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

    const int chunks = static_cast<int>(std::min<std::int64_t>(k.checkpoints, k.steps));
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

// ---- the systems ------------------------------------------------------------

Handle rigid_body(double I1, double I2, double I3, std::vector<double> m) {
    Handle h;
    check(lpi_rigid_body_create(h.out(), I1, I2, I3), nullptr, "create rigid body");
    check(lpi_set_state(h.get(), m.data(), m.size()), h.get(), "set state");
    return h;
}

// Fastest period of the rigid body: 2 pi / max_k |m| / I_k (a bound on every
// rotation rate of the body).
double rigid_period(double I1, double I2, double I3, const std::vector<double> &m) {
    const double norm = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
    return 2.0 * kPi / (norm / std::min({I1, I2, I3}));
}

Case rigid_case(const std::string &name, double I1, double I2, double I3, std::vector<double> m,
                const std::vector<double> &factors, std::int64_t steps) {
    Case k;
    k.name = name;
    k.create = [=] { return rigid_body(I1, I2, I3, m); };
    k.period = rigid_period(I1, I2, I3, m);
    k.factors = factors;
    k.steps = steps;
    return k;
}

// so(3) as a generic system with every structure constant times `scale`
// (still a Lie algebra); pieces m_k^2 / (2 I_k), Casimir |m|^2.
const double kGenericInertia[3] = {1.0, 2.0, 3.0};
int axis_grad(size_t, const double *x, double *g, void *user) {
    g[0] = x[0] / *static_cast<const double *>(user);
    return 0;
}
int axis_energy(size_t, const double *x, double *h, void *user) {
    *h = 0.5 * x[0] * x[0] / *static_cast<const double *>(user);
    return 0;
}
int norm2_casimir(size_t dim, const double *x, double *out, void *) {
    *out = 0.0;
    for (size_t q = 0; q < dim; ++q) *out += x[q] * x[q];
    return 0;
}

Handle generic_so3(double scale) {
    const std::int32_t i[] = {0, 0, 1}, j[] = {1, 2, 2}, kk[] = {2, 1, 0};
    const double c[] = {-scale, scale, -scale};
    Handle h;
    check(lpi_generic_create(h.out(), 3, 3, i, j, kk, c), nullptr, "create generic system");
    for (std::int32_t a = 0; a < 3; ++a)
        check(lpi_add_piece(h.get(), 1, &a, axis_grad, axis_energy,
                            const_cast<double *>(&kGenericInertia[a])),
              h.get(), "add piece");
    check(lpi_add_casimir(h.get(), norm2_casimir, nullptr), h.get(), "add casimir");
    const std::vector<double> m = {1.0, 0.5, -0.3};
    check(lpi_set_state(h.get(), m.data(), m.size()), h.get(), "set state");
    return h;
}

// Moments: the harmonic ensemble H = (<q^2> + <p^2>) / 2 split as
// V(x1, x4) + T(x3, x8) with V = x1/2, T = x3/2 (exact flows: rotations of
// the (q, p) plane, bounded at every scale), optionally + P(x1 x3),
// P(u) = u/50 + u^2/100.
int v_grad(size_t, const double *, double *g, void *) {
    g[0] = 0.5;
    g[1] = 0.0;
    return 0;
}
int v_energy(size_t, const double *x, double *h, void *) {
    *h = 0.5 * x[0];
    return 0;
}
int p_h(double u, double *out, void *) {
    *out = 0.02 * u + 0.01 * u * u;
    return 0;
}
int p_dh(double u, double *out, void *) {
    *out = 0.02 + 0.02 * u;
    return 0;
}

// Moments of a Gaussian in (q, p) squeezed by `squeeze` and scaled by `size`:
// <q^2> = size l^2, <p^2> = size / l^2, <q^4> = 3 size^2 l^4, <q^2 p^2> = size^2,
// <p^4> = 3 size^2 / l^4 (l = squeeze), odd moments 0. I = 12 size^4, K = 8 size^6.
Handle moments(double squeeze, double size, bool product) {
    Handle h;
    check(lpi_moments_create(h.out()), nullptr, "create moments");
    const std::int32_t v[] = {0, 3}, t[] = {2, 7};
    check(lpi_add_piece(h.get(), 2, v, v_grad, v_energy, nullptr), h.get(), "add piece");
    check(lpi_add_piece(h.get(), 2, t, v_grad, v_energy, nullptr), h.get(), "add piece");
    if (product)
        check(lpi_moments_add_product_piece(h.get(), p_h, p_dh, nullptr), h.get(),
              "add product piece");
    const double l2 = squeeze * squeeze;
    const std::vector<double> x = {size * l2,
                                   0.0,
                                   size / l2,
                                   3.0 * size * size * l2 * l2,
                                   0.0,
                                   size * size,
                                   0.0,
                                   3.0 * size * size / (l2 * l2)};
    check(lpi_set_state(h.get(), x.data(), x.size()), h.get(), "set state");
    return h;
}

void moment_invariants(const std::vector<double> &xd, std::vector<long double> &c,
                       std::vector<long double> &scale) {
    long double x[8];
    for (int q = 0; q < 8; ++q) x[q] = xd[q];
    const long double a = x[3], b = x[4], cc = x[5], d = x[6], e = x[7];
    c = {a * e - 4 * b * d + 3 * cc * cc,
         a * (cc * e - d * d) - b * (b * e - d * cc) + cc * (b * d - cc * cc)};
    scale = {std::fabs(a * e) + 4 * std::fabs(b * d) + 3 * cc * cc,
             std::fabs(a * cc * e) + std::fabs(a * d * d) + std::fabs(b * b * e) +
                 2 * std::fabs(b * d * cc) + std::fabs(cc * cc * cc)};
}

Handle pendulum(std::vector<double> x) {
    Handle h;
    check(lpi_pendulum_create(h.out()), nullptr, "create pendulum");
    check(lpi_set_state(h.get(), x.data(), x.size()), h.get(), "set state");
    return h;
}

// Sine-Euler fields (modes in FFT order, interleaved re, im, Hermitian).
int rep(int a, int N) { return a <= N / 2 ? a : a - N; }

std::vector<double> sine_field(int N, unsigned seed, const std::function<bool(int, int)> &keep) {
    std::vector<double> w(2 * static_cast<std::size_t>(N) * N, 0.0);
    unsigned state = seed;
    auto uniform = [&] {
        state = state * 1664525u + 1013904223u;
        return static_cast<double>(state >> 8) / 16777216.0 - 0.5;
    };
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b) {
            const int ma = (N - a) % N, mb = (N - b) % N;
            if (a * N + b >= ma * N + mb) continue;  // set each pair once
            if (!keep(rep(a, N), rep(b, N))) continue;
            const double re = uniform(), im = uniform();
            w[2 * (a * N + b)] = re, w[2 * (a * N + b) + 1] = im;
            w[2 * (ma * N + mb)] = re, w[2 * (ma * N + mb) + 1] = -im;
        }
    return w;
}

Handle sine_euler(int N, const std::vector<double> &w) {
    Handle h;
    check(lpi_sine_euler_create(h.out(), N), nullptr, "create sine-Euler");
    check(lpi_sine_euler_set_modes(h.get(), w.data(), w.size()), h.get(), "set modes");
    return h;
}

bool have_sine_euler() {
    lpi_system *probe = nullptr;
    const int status = lpi_sine_euler_create(&probe, 3);
    lpi_destroy(probe);
    return status == LPI_OK;
}

// ---- the matrix of cases ------------------------------------------------------

std::vector<Case> build_cases(bool quick) {
    std::vector<Case> cases;
    const std::vector<double> wide = {1e-8, 1e-3, 0.1, 1.0, 1e3};
    const std::int64_t n = quick ? 200 : 10000;

    cases.push_back(rigid_case("rigid-body ratio 1e8", 1.0, 1e4, 1e8, {1.0, 1.0, 1.0}, wide, n));
    cases.push_back(rigid_case("rigid-body ratio 1e8 (spin on the light axis)", 1e-4, 1.0, 1e4,
                               {1e-3, 1.0, 1.0}, wide, n));
    cases.push_back(rigid_case("rigid-body near-symmetric I1 = I2 (1 + 1e-12)", 2.0 * (1.0 + 1e-12),
                               2.0, 3.0, {1.0, 0.5, -0.3}, wide, n));
    cases.push_back(rigid_case("rigid-body middle axis", 1.0, 2.0, 3.0, {1e-10, 1.0, 1e-10}, wide, n));
    // |m|^2 / I2 = m1^2 / I1 + m3^2 / I3 with m2 = 0: m3 = sqrt(3) m1 for I = (1, 2, 3).
    cases.push_back(rigid_case("rigid-body separatrix", 1.0, 2.0, 3.0, {1.0, 0.0, std::sqrt(3.0)},
                               wide, n));
    {
        Case k = rigid_case("rigid-body long run", 1.0, 2.0, 3.0, {1.0, 0.5, -0.3}, {0.01},
                            quick ? 100000 : 10000000);
        k.methods = {"leapfrog"};
        k.checkpoints = 100;
        cases.push_back(k);
    }
    {
        // H = p^2/2 - cos(theta) just below the separatrix value 1.
        Case k;
        k.name = "pendulum near the separatrix";
        k.create = [] { return pendulum({0.0, -1.0, std::sqrt(4.0 - 2e-10)}); };
        k.period = 2.0 * kPi;
        k.factors = {1e-3, 0.1, 1.0, 1e3};
        k.steps = n;
        cases.push_back(k);
    }
    {
        // Entries from 3e-150 to 3e150; I = 12, K = 8. The linear pieces only:
        // the product piece's flow is hyperbolic at rate 4 x2 H'(x1 x3), and
        // x1 x3 reaches 1e150 as the ensemble rotates (see the next case).
        Case k;
        k.name = "moments squeezed, entries 1e-150...1e150";
        k.create = [] { return moments(std::pow(10.0, 37.5), 1.0, false); };
        k.period = 2.0 * kPi;
        k.factors = {1e-3, 0.1, 1.0, 1e3};
        k.steps = quick ? 100 : n;
        k.measure = moment_invariants;
        // Round-off made while the ensemble is turned by 45 degrees (all
        // entries ~ 1e150) stays in the state: checkpoints must see those
        // phases, so their spacing is not commensurate with the period.
        k.checkpoints = 97;
        // Kick-drift splitting of the oscillator is linearly unstable for
        // substeps beyond 2 (dt = 1 period, or less for compositions with
        // large substeps): the numerical map itself grows until it
        // overflows, which is reported and rolled back.
        k.allowed_failure = LPI_ERR_NONFINITE;
        cases.push_back(k);
        k.name = "moments huge, entries near 1e150 (K ~ 1e450)";
        k.create = [] { return moments(1.0, 1e75, false); };
        cases.push_back(k);
        // With the product piece the exact flow overflows within a step: the
        // step must fail cleanly.
        k.name = "moments huge with the product piece (exact flow overflows)";
        k.create = [] { return moments(1.0, 1e75, true); };
        k.factors = {1e-3, 1.0};
        k.steps = 10;
        k.allowed_failure = LPI_ERR_NONFINITE;
        cases.push_back(k);
    }
    for (double scale : {1e100, 1e-100}) {
        Case k;
        char name[96];
        std::snprintf(name, sizeof name, "generic so(3), structure constants %.0e", scale);
        k.name = name;
        k.create = [=] { return generic_so3(scale); };
        k.period = 2.0 * kPi / scale;
        k.factors = {1e-3, 0.1, 1.0, 1e3};
        k.steps = quick ? 100 : n;
        k.pade_growth = true;
        cases.push_back(k);
    }
    {
        // Far beyond what scaling and squaring can do to round-off: refused.
        Case k;
        k.name = "generic so(3), constants 1e100, dt = 1 (|tA| ~ 1e100)";
        k.create = [] { return generic_so3(1e100); };
        k.period = 1.0;
        k.factors = {1.0};
        k.steps = 10;
        k.allowed_failure = LPI_ERR_INVALID;
        cases.push_back(k);
    }
    if (have_sine_euler()) {
        auto add = [&](const std::string &name, int N, std::vector<double> w,
                       const std::vector<double> &factors, std::int64_t steps,
                       std::vector<std::string> methods) {
            Case k;
            k.name = name;
            k.create = [=] { return sine_euler(N, w); };
            k.factors = factors;
            k.steps = steps;
            k.methods = std::move(methods);
            k.spectrum_scale = true;
            k.drift_floor = 1e-15 * N;  // eigenvalues of an N x N matrix
            k.checkpoints = static_cast<int>(std::min<std::int64_t>(steps, 10));
            cases.push_back(k);
        };
        auto any = [](int, int) { return true; };
        add("sine-Euler N = 3", 3, sine_field(3, 7, any), {1e-3, 1.0, 1e3}, quick ? 100 : 1000, {});
        const int N = 21;
        add("sine-Euler N = 21, energy in the highest modes", N,
            sine_field(N, 11, [&](int a, int b) { return a * a + b * b >= 80; }), {1e-2, 1.0, 1e3},
            quick ? 20 : 200, {});
        add("sine-Euler N = 21, zero field", N, std::vector<double>(2 * N * N, 0.0), {1.0, 1e3}, 10, {});
        add("sine-Euler N = 21, single line (steady)", N,
            sine_field(N, 13, [](int a, int b) { return 5 * a - 2 * b == 0; }), {1e-2, 1e3}, 20, {});
        // One step at N = 1021 is (N + 1) N FFTs of length N: tens of seconds
        // on one core, so the full mode only.
        if (!quick)
            add("sine-Euler N = 1021, a few steps", 1021, sine_field(1021, 17, any), {1e-2, 1e3}, 1,
                {"leapfrog"});
        add("sine-Euler N = 7, dt = 0.05 as in the paper, long run", 7, sine_field(7, 2024, any), {0.05},
            quick ? 10000 : 1000000, {"leapfrog"});
        cases.back().checkpoints = 10;
    }
    return cases;
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
            quick = true;
        } else if (arg == "--help" || arg == "-h") {
            print_usage(stdout);
            return 0;
        } else if (!arg.empty() && arg[0] == '-') {
            args.fail("unknown option '" + arg + "'");
        } else if (!filter.empty()) {
            args.fail("one FILTER only ('" + filter + "' and '" + arg + "')");
        } else {
            filter = arg;
        }
    }
    const std::vector<Case> cases = build_cases(quick);
    if (std::none_of(cases.begin(), cases.end(), [&](const Case &k) { return k.name.find(filter) != std::string::npos; }))
        args.fail("no case name contains '" + filter + "'");
    std::printf("liepoisson %s: stress cases (%s)\n", lpi_version_string(), quick ? "quick" : "full");
    std::printf("energy error and Casimir drift are relative maxima over the checkpoints;\n"
                "bounded: finite and max|x| <= 1e3 max|x(0)|; must-hold failures are marked '!!'\n");
    int violations = 0, runs = 0;
    for (const Case &k : cases) {
        if (!filter.empty() && k.name.find(filter) == std::string::npos) continue;
        std::printf("\n== %s (fastest period %.3g)\n", k.name.c_str(), k.period);
        std::printf("   %-9s %-9s %-22s %-22s %-7s %-10s %-10s %s\n", "dt/period", "steps",
                    "method", "status", "bounded", "max dH/H", "C drift", "");
        const std::vector<bool> accepted = accepted_methods(k.create);
        for (double factor : k.factors) {
            const double dt = factor * k.period;
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
                const double growth = k.pade_growth ? std::max(1.0, 2.0 * kPi * factor / 5.4) : 1.0;
                const double tolerance =
                    k.drift_floor + kDriftPerFlow * growth *
                                        static_cast<double>(o.flows_per_step) *
                                        static_cast<double>(o.steps_done);
                // An unbounded run (an unstable composition of the moment
                // algebra's shears) meets larger terms inside its steps than
                // the checkpoints show: its drift is printed, not judged.
                if (poisson && o.bounded && !(o.casimir_drift <= tolerance))
                    verdict += " !! Casimir drift";
                if (!verdict.empty()) ++violations;
                std::string status = lpi_status_name(o.status);
                if (o.status != LPI_OK) status += o.rolled_back ? " (rolled back)" : "";
                std::printf("   %-9.0e %-9lld %-22s %-22s %-7s %-10.2e %-10.2e%s\n", factor,
                            static_cast<long long>(o.steps_done), method.c_str(), status.c_str(),
                            o.bounded ? "yes" : "no", o.energy_error, o.casimir_drift,
                            verdict.c_str());
                if (o.status != LPI_OK) std::printf("      %s\n", o.message.c_str());
                std::fflush(stdout);
            }
        }
    }
    std::printf("\n%d runs, %d with a must-hold failure\n", runs, violations);
    return violations == 0 ? 0 : 1;
}

}  // namespace lpi_cli
