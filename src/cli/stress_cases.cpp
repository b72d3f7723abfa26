#include "stress_cases.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "fields.hpp"
#include "systems.hpp"

namespace lpi_cli {

namespace {

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
// the (q, p) plane, bounded at every scale), optionally + P(x1 x3)
// (product_energy, systems.hpp).
int v_grad(size_t, const double *, double *g, void *) {
    g[0] = 0.5;
    g[1] = 0.0;
    return 0;
}
int v_energy(size_t, const double *x, double *h, void *) {
    *h = 0.5 * x[0];
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
        check(lpi_moments_add_product_piece(h.get(), product_energy, product_derivative, nullptr), h.get(),
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

}  // namespace

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
        k.samples = 100;
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
        // entries ~ 1e150) stays in the state: samples must see those
        // phases, so their spacing is not commensurate with the period.
        k.samples = 97;
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
        cases.push_back(k);
    }
    {
        // Far beyond what scaling and squaring can do to round-off: refused.
        Case k;
        k.name = "generic so(3), constants 1e100, dt = 1 (|tA| ~ 1e100)";
        k.create = [] { return generic_so3(1e100); };
        k.factors = {1.0};
        k.steps = 10;
        k.allowed_failure = LPI_ERR_INVALID;
        cases.push_back(k);
    }
    if (sine_euler_unavailable().empty()) {
        auto add = [&](const std::string &name, int N, std::vector<double> w,
                       const std::vector<double> &factors, std::int64_t steps,
                       std::vector<std::string> methods) {
            Case k;
            k.name = name;
            k.create = [=] { return sine_euler(N, [&w](int) { return w; }); };
            k.factors = factors;
            k.steps = steps;
            k.methods = std::move(methods);
            k.spectrum_scale = true;
            k.drift_floor = 1e-15 * N;  // eigenvalues of an N x N matrix
            k.samples = static_cast<int>(std::min<std::int64_t>(steps, 10));
            cases.push_back(k);
        };
        auto any = [](int, int) { return true; };
        add("sine-Euler N = 3", 3, uniform_random_field(3, 7, any), {1e-3, 1.0, 1e3}, quick ? 100 : 1000, {});
        const int N = 21;
        add("sine-Euler N = 21, energy in the highest modes", N,
            uniform_random_field(N, 11, [&](int a, int b) { return a * a + b * b >= 80; }), {1e-2, 1.0, 1e3},
            quick ? 20 : 200, {});
        add("sine-Euler N = 21, zero field", N, std::vector<double>(2 * N * N, 0.0), {1.0, 1e3}, 10, {});
        add("sine-Euler N = 21, single line (steady)", N,
            uniform_random_field(N, 13, [](int a, int b) { return 5 * a - 2 * b == 0; }), {1e-2, 1e3}, 20, {});
        // One step at N = 1021 is (N + 1) N FFTs of length N: tens of seconds
        // on one core, so the full mode only.
        if (!quick)
            add("sine-Euler N = 1021, a few steps", 1021, uniform_random_field(1021, 17, any), {1e-2, 1e3}, 1,
                {"leapfrog"});
        add("sine-Euler N = 7, dt = 0.05 as in the paper, long run", 7, uniform_random_field(7, 2024, any), {0.05},
            quick ? 10000 : 1000000, {"leapfrog"});
        cases.back().samples = 10;
    }
    return cases;
}

}  // namespace lpi_cli
