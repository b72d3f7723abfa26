// The algebra of second and fourth moments of a distribution f(q, p)
// (McLachlan 1993, section 2): x = (<q^2>, <qp>, <p^2>, <q^4>, <q^3 p>,
// <q^2 p^2>, <q p^3>, <p^4>), indices 0..7 here, x1..x8 in the paper.
//
// The nonlinear piece H(x1 x3) has a closed-form flow. With u = x1 x3 and
// mu = H'(u) constant along it and lambda = 4 x2 mu (the paper's lambda
// carries the factor mu in its matrix too), x1 -> e^{lambda t} x1,
// x3 -> e^{-lambda t} x3, x2 fixed, and the fourth moments obey the paper's
// time-dependent tridiagonal system. Scaling x_{ab} = e^{(a-b) lambda t/2} y_{ab}
// (the paper's diagonal change of variables) makes it constant: y' = B y, and B
// is the action on quartic moments <Q^a P^b> of the traceless plane matrix
//   M = [[-lambda/2, 2 mu b], [-2 mu a, lambda/2]],  a = x3(0), b = x1(0)
// (checked entry by entry against the paper's matrix). So exp(tB) is the
// fourth symmetric power of exp(tM) = c I + s M (c, s from cosh/cos of
// sqrt(|det M|) t), and the whole flow is the symmetric power of the plane map
// F = diag(e^{lambda t/2}, e^{-lambda t/2}) exp(tM), det F = 1: elementary
// functions only, and I, K (invariants of binary quartics under SL(2)) are
// kept to round-off.
#include <algorithm>
#include <cmath>

#include "../core/error.hpp"
#include "../core/text.hpp"
#include "../core/system.hpp"
#include "generic.hpp"
#include "moments_algebra.hpp"

namespace lpi {

namespace {

// I and K are evaluated in long double: with x87 extended precision its
// exponent range (1e4932) holds the products of entries up to 1e308, so a
// finite state never gives a NaN from inf - inf, and a Casimir is returned
// even when its terms overflow a double (entries near 1e150: K ~ 1e450
// terms), with an error of 2^-64 of its largest term. Where that error
// itself passes DBL_MAX (terms beyond about 3e327), a small value can come
// out +-inf, as one that is not representable does: lpi_casimirs reports
// LPI_ERR_OVERFLOW naming the Casimir (lpi_moments_create(3) says so).
// Where long double is double, the same code is the plain double formula.
template <class Real>
Real invariant_I(const Real *x) {
    return x[3] * x[7] - 4 * x[4] * x[6] + 3 * x[5] * x[5];
}
template <class Real>
Real invariant_K(const Real *x) {
    // det [[x4,x5,x6],[x5,x6,x7],[x6,x7,x8]] (paper numbering)
    const Real a = x[3], b = x[4], c = x[5], d = x[6], e = x[7];
    return a * (c * e - d * d) - b * (b * e - d * c) + c * (b * d - c * c);
}

int casimir_I(std::size_t, const double *x, double *out, void *) {
    long double wide[8];
    std::copy(x, x + 8, wide);
    *out = static_cast<double>(invariant_I(wide));
    return 0;
}

int casimir_K(std::size_t, const double *x, double *out, void *) {
    long double wide[8];
    std::copy(x, x + 8, wide);
    *out = static_cast<double>(invariant_K(wide));
    return 0;
}

// Powers 0..4 of the entries of a plane map F = [[a, b], [c, d]], given as
// F = I + D (with a^n - 1, d^n - 1 from a^n - 1 = (a - 1)(1 + a + ... +
// a^(n-1))) or, far from the identity, as F itself (no differences).
struct PlanePowers {
    double a[5], b[5], c[5], d[5], a_minus_1[5], d_minus_1[5];
    explicit PlanePowers(const double D[2][2]) {
        fill(1.0 + D[0][0], D[0][1], D[1][0], 1.0 + D[1][1]);
        a_minus_1[0] = d_minus_1[0] = 0.0;
        for (int n = 1; n < 5; ++n) {
            a_minus_1[n] = a_minus_1[n - 1] * a[1] + D[0][0];
            d_minus_1[n] = d_minus_1[n - 1] * d[1] + D[1][1];
        }
    }
    static PlanePowers of_map(const double F[2][2]) { return PlanePowers(F[0][0], F[0][1], F[1][0], F[1][1]); }

private:
    PlanePowers(double fa, double fb, double fc, double fd) { fill(fa, fb, fc, fd); }
    void fill(double fa, double fb, double fc, double fd) {
        a[0] = b[0] = c[0] = d[0] = 1.0;
        for (int n = 1; n < 5; ++n) {
            a[n] = a[n - 1] * fa;
            b[n] = b[n - 1] * fb;
            c[n] = c[n - 1] * fc;
            d[n] = d[n - 1] * fd;
        }
    }
};

constexpr double kBinomial[5][5] = {
    {1, 0, 0, 0, 0}, {1, 1, 0, 0, 0}, {1, 2, 1, 0, 0}, {1, 3, 3, 1, 0}, {1, 4, 6, 4, 1}};

// The coefficients of row R of Sym^4(F) on the fourth moments y = (<q^4>,
// <q^3 p>, ..., <p^4>): those on q^(4-k) p^k of (a q + b p)^(4-R) (c q +
// d p)^R, without the one term a^(4-R) d^R of the diagonal when Increment
// (the caller adds it as a difference from 1). (Templates: the loops have
// fixed bounds and unroll.)
template <int R, bool Increment>
void fourth_power_row(const PlanePowers &p, double row[5]) {
    constexpr int N = 4 - R;
    // (a q + b p)^N: C(N, j) a^(N-j) b^j on q^(N-j) p^j; (c q + d p)^R:
    // C(R, i) c^(R-i) d^i on q^(R-i) p^i.
    for (int j = 0; j <= N; ++j) {
        const double first = kBinomial[N][j] * p.a[N - j] * p.b[j];
        for (int i = 0; i <= R; ++i)
            if (!Increment || j > 0 || i < R) row[j + i] += first * kBinomial[R][i] * p.c[R - i] * p.d[i];
    }
}

// Row R of Sym^4(F) - I applied to y. Every coefficient is a sum of products
// with a factor b or c, except the diagonal's a^(4-R) d^R, which enters as
// a^(4-R) d^R - 1: the increment is accurate relative to itself.
template <int R>
double fourth_power_increment(const PlanePowers &p, const double *y) {
    constexpr int N = 4 - R;
    double row[5] = {0.0, 0.0, 0.0, 0.0, 0.0};
    fourth_power_row<R, true>(p, row);
    row[R] += p.a_minus_1[N] + p.d_minus_1[R] + p.a_minus_1[N] * p.d_minus_1[R];
    double sum = 0.0;
    for (int k = 0; k < 5; ++k) sum += row[k] * y[k];
    return sum;
}

// Row R of Sym^4(F) applied to y, F given itself: for a flow far from the
// identity, where the increment form (F - I, a^n - 1) would round a
// contracted moment away.
template <int R>
double fourth_power_of_map(const PlanePowers &p, const double *y) {
    double row[5] = {0.0, 0.0, 0.0, 0.0, 0.0};
    fourth_power_row<R, false>(p, row);
    double sum = 0.0;
    for (int k = 0; k < 5; ++k) sum += row[k] * y[k];
    return sum;
}

// y <- Sym^4(F) y, F given itself.
void apply_fourth_power_of_map(const double F[2][2], double *y) {
    const PlanePowers powers = PlanePowers::of_map(F);
    const double result[5] = {fourth_power_of_map<0>(powers, y), fourth_power_of_map<1>(powers, y),
                              fourth_power_of_map<2>(powers, y), fourth_power_of_map<3>(powers, y),
                              fourth_power_of_map<4>(powers, y)};
    std::copy(result, result + 5, y);
}

// y <- Sym^4(F) y, rounded once.
void apply_fourth_power(const double D[2][2], double *y) {
    const PlanePowers powers(D);
    const double increment[5] = {
        fourth_power_increment<0>(powers, y), fourth_power_increment<1>(powers, y),
        fourth_power_increment<2>(powers, y), fourth_power_increment<3>(powers, y),
        fourth_power_increment<4>(powers, y)};
    for (int r = 0; r < 5; ++r) y[r] += increment[r];
}

class ProductPiece final : public Piece {
public:
    ProductPiece(std::string label, const StructureConstants &constants, lpi_scalar_fn h,
                 lpi_scalar_fn dh, void *user)
        : Piece(std::move(label)), constants_(constants), h_(h), dh_(dh), user_(user) {}

    // Formed in a copy and written only when every moment is finite: the
    // next piece's callback never sees an overflowed state.
    void flow(double t, double *x) override {
        constexpr int dim = MomentAlgebra::dim;
        double y[dim];
        std::copy(x, x + dim, y);
        advance(t, y);
        for (int i = 0; i < dim; ++i)
            if (!std::isfinite(y[i]))
                fail(LPI_ERR_NONFINITE,
                     label() + ": the exact flow overflows (component " + std::to_string(i) + ")");
        std::copy(y, y + dim, x);
    }

    double energy(const double *x) const override {
        double value = 0.0;
        const double u = product(x);
        const int rc = call_user([&] { return h_(u, &value, user_); },
                                 [&] { return "the H callback of " + label(); });
        check(rc, value, "H");
        return value;
    }

    void add_vector_field(const double *x, double *rate) const override {
        const double mu = derivative(product(x));
        const std::uint32_t sigma[2] = {0, 2};
        const double g[2] = {mu * x[2], mu * x[0]};
        add_poisson_times(constants_, sigma, 2, g, x, rate);
    }

private:
    // The flow depends on mu and t only through mu t: it runs with mu t for
    // mu and for 1 time unit, so that neither a negative t (which had kept
    // the far form's projectors from a contraction) nor a mu whose square
    // under- or overflows (mu = 1e-200 with t = 5e199 came out 7 times off)
    // changes which form is taken.
    void advance(double t_in, double *x) const {
        const double b = x[0], a = x[2];
        const double mu = derivative(product(x)) * t_in, t = 1.0;
        // An infinite mu t would make lambda = 4 x2 mu t a NaN where x2 = 0
        // (inf times 0), and the far form would work on NaNs.
        if (!std::isfinite(mu))
            fail(LPI_ERR_NONFINITE, label() + ": H'(x1 x3) t = " + number_text(derivative(product(x))) +
                                        " * " + number_text(t_in) + " overflows");
        // Everything from M's entries, each a rate of the flow: mu^2 and
        // x2^2 - ab apart under- or overflowed where the flow is ordinary
        // (x1, x2, x3 ~ 1e-200 with mu t ~ 1e200: delta inf * 0, taken as 0,
        // and the fourth moments came out 8x off with LPI_OK).
        const double lambda = 4.0 * (x[1] * mu);
        const double L = 0.5 * lambda, m01 = 2.0 * (mu * b), m10 = -2.0 * (mu * a);
        const double delta = L * L + m01 * m10;
        if (std::fabs(lambda * t) > kFarFromIdentity ||
            (delta > 0.0 && std::sqrt(delta) * t > kFarFromIdentity)) {
            flow_far_from_identity(lambda, m01, m10, delta, t, x);
            return;
        }

        // exp(tM) = c I + s M with M^2 = delta I, delta = -det M = 4 mu^2 (x2^2 - ab)
        // = L^2 + m01 m10.
        // Near the identity everything is formed as a difference from it (c
        // - 1 from half-angle formulas, expm1 for the scalings) so that the
        // map is applied as x + increment with errors relative to the
        // increment: rounding F itself would bias det F away from 1 by the
        // same amount every step, and I, K (weights 4 and 6 in det F) would
        // drift.
        double c_minus_1 = 0.0, s = t;
        if (delta > 0.0) {
            const double r = std::sqrt(delta), h = std::sinh(0.5 * r * t);
            c_minus_1 = 2.0 * h * h;
            s = 2.0 * h * std::sqrt(1.0 + h * h) / r;  // sinh(r t) / r
        } else if (delta < 0.0) {
            const double r = std::sqrt(-delta), h = std::sin(0.5 * r * t);
            c_minus_1 = -2.0 * h * h;
            s = 2.0 * h * std::cos(0.5 * r * t) / r;  // sin(r t) / r
        }
        // e^{lambda t/2} - 1 and e^{-lambda t/2} - 1 = -g / (1 + g) from one expm1.
        const double grow_minus_1 = std::expm1(0.5 * lambda * t);
        const double shrink_minus_1 = -grow_minus_1 / (1.0 + grow_minus_1);
        // D = F - I, F = diag(e^{lambda t/2}, e^{-lambda t/2}) (c I + s M).
        const double D[2][2] = {
            {grow_minus_1 + (1.0 + grow_minus_1) * (c_minus_1 - 0.5 * s * lambda),
             (1.0 + grow_minus_1) * s * m01},
            {(1.0 + shrink_minus_1) * s * m10,
             shrink_minus_1 + (1.0 + shrink_minus_1) * (c_minus_1 + 0.5 * s * lambda)}};
        apply_fourth_power(D, x + 3);
        x[0] = b + b * (grow_minus_1 * (2.0 + grow_minus_1));     // e^{lambda t} - 1
        x[2] = a + a * (shrink_minus_1 * (2.0 + shrink_minus_1));  // e^{-lambda t} - 1
    }

    // 2 ln 2: beyond it x1 or x3 contracts by more than a quarter in one flow
    // (or, x2^2 > x1 x3, the eigenvalues +-r t of tM are that far from 0),
    // and the increment form above would keep of a contracted moment only the
    // accuracy of its old value, a relative error e^(|lambda| t) (e^(2 |lambda|
    // t) for <p^4>) times the round-off. Below it that loss is smaller than
    // what rounding the map itself costs I and K (measured: 8e-16 against
    // 2.7e-15 at lambda t = 0.69, 6.5e-15 against 1.7e-15 at 2.1).
    static constexpr double kFarFromIdentity = 1.3862943611198906;

    // The same flow applied as the map itself: x1 e^{lambda t}, x3
    // e^{-lambda t} and Sym^4(F) with F's entries formed directly, exp(tM)
    // through its spectral projectors P+- = (I +- M / r) / 2 where its
    // eigenvalues +-r are real and far apart (their diagonals without
    // cancellation: (r - |L|) / 2r = (r^2 - L^2) / (2r (r + |L|)), r^2 - L^2 =
    // m01 m10 = -4 mu^2 x1 x3).
    static void flow_far_from_identity(double lambda, double m01, double m10, double delta, double t,
                                       double *x) {
        const double L = 0.5 * lambda, a = x[2], b = x[0];
        const double r = std::sqrt(std::fabs(delta));
        double E[2][2];
        if (delta > 0.0 && r * t > kFarFromIdentity) {
            const double q = std::fabs(L);
            const double high = (r + q) / (2.0 * r), low = m01 * m10 / (2.0 * r * (r + q));
            const double p00 = L >= 0.0 ? low : high, p11 = L >= 0.0 ? high : low;
            const double grow = std::exp(r * t), shrink = std::exp(-r * t), odd = std::sinh(r * t) / r;
            E[0][0] = grow * p00 + shrink * p11;
            E[0][1] = odd * m01;
            E[1][0] = odd * m10;
            E[1][1] = grow * p11 + shrink * p00;
        } else {
            double c = 1.0, s = t;  // exp(tM) = c I + s M
            if (delta > 0.0) {
                c = std::cosh(r * t);
                s = std::sinh(r * t) / r;
            } else if (delta < 0.0) {
                c = std::cos(r * t);
                s = std::sin(r * t) / r;
            }
            E[0][0] = c - s * L;
            E[0][1] = s * m01;
            E[1][0] = s * m10;
            E[1][1] = c + s * L;
        }
        const double up = std::exp(L * t), down = std::exp(-L * t);
        const double F[2][2] = {{up * E[0][0], up * E[0][1]}, {down * E[1][0], down * E[1][1]}};
        apply_fourth_power_of_map(F, x + 3);
        x[0] = times_exponential(b, lambda * t);
        x[2] = times_exponential(a, -lambda * t);
    }

    // u = x1 x3, the callbacks' argument: LPI_ERR_OVERFLOW where it
    // overflows (the energy, the vector field and the flow alike), so that no
    // callback is handed an infinite u.
    double product(const double *x) const {
        const double u = x[0] * x[2];
        if (!std::isfinite(u))
            fail(LPI_ERR_OVERFLOW, "x1 x3 = " + number_text(x[0]) + " * " + number_text(x[2]) +
                                       " overflows in " + label());
        return u;
    }

    double derivative(double u) const {
        double value = 0.0;
        const int rc = call_user([&] { return dh_(u, &value, user_); },
                                 [&] { return "the H' callback of " + label(); });
        check(rc, value, "H'");
        return value;
    }

    void check(int rc, double value, const char *what) const {
        if (rc != 0)
            fail(LPI_ERR_CALLBACK, std::string("the ") + what + " callback of " + label() +
                                       " returned " + std::to_string(rc));
        if (!std::isfinite(value))
            fail(LPI_ERR_CALLBACK, std::string("the ") + what + " callback of " + label() +
                                       " gave a non-finite value");
    }

    const StructureConstants &constants_;
    lpi_scalar_fn h_, dh_;
    void *user_;
};

}  // namespace

CompiledFlow moment_piece_flow(unsigned mask) {
    static constexpr compiled::Table<MomentAlgebra> table;
    return table.flow(mask);
}

std::unique_ptr<GenericModel> make_moments() {
    constexpr BracketColumns<MomentAlgebra> b;
    auto constants =
        std::make_unique<StructureConstants>(MomentAlgebra::dim, b.count, b.i, b.j, b.k, b.c);
    auto model = std::make_unique<GenericModel>(std::move(constants), "moments");
    model->set_compiled_flows(moment_piece_flow);
    model->add_builtin_casimir(casimir_I, "I = x4 x8 - 4 x5 x7 + 3 x6^2");
    model->add_builtin_casimir(casimir_K, "K = det [[x4,x5,x6],[x5,x6,x7],[x6,x7,x8]]");
    return model;
}

void add_moments_product_piece(System &system, lpi_scalar_fn h, lpi_scalar_fn dh, void *user) {
    GenericModel &model = generic_model_of(system);
    if (std::string(model.kind()) != "moments")
        fail(LPI_ERR_UNSUPPORTED, std::string("the product piece H(x1 x3) belongs to the moment "
                                              "algebra; this is a ") + model.kind() + " system");
    if (!h) fail(LPI_ERR_NULL, "the H callback is NULL");
    if (!dh) fail(LPI_ERR_NULL, "the H' callback is NULL");
    model.add_piece(std::make_unique<ProductPiece>(model.next_piece_name() + " (product H(x1 x3))",
                                                   model.constants(), h, dh, user));
    commit_new_piece(system, model);
}

}  // namespace lpi
