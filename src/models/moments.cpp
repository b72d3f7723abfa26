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
#include "../core/system.hpp"
#include "generic.hpp"

namespace lpi {

namespace {

// {x_i, x_j} = c x_k for i < j, read off the paper's 8x8 J (0-based).
struct Bracket {
    std::int32_t i, j, k;
    double c;
};
constexpr Bracket kMomentBrackets[] = {
    {0, 1, 0, 2},  {0, 2, 1, 4},  {0, 4, 3, 2},  {0, 5, 4, 4},  {0, 6, 5, 6},
    {0, 7, 6, 8},  {1, 2, 2, 2},  {1, 3, 3, -4}, {1, 4, 4, -2}, {1, 6, 6, 2},
    {1, 7, 7, 4},  {2, 3, 4, -8}, {2, 4, 5, -6}, {2, 5, 6, -4}, {2, 6, 7, -2},
};

// I and K are evaluated in long double: with x87 extended precision its
// exponent range (1e4932) holds the products of entries up to 1e308, so a
// finite state never gives a NaN from inf - inf, and a Casimir whose value
// is representable is returned even when its terms are not (entries near
// 1e150: K ~ 1e450 terms); one that is not representable becomes +-inf,
// which lpi_casimirs reports as LPI_ERR_OVERFLOW naming the Casimir.
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

class ProductPiece final : public Piece {
public:
    ProductPiece(std::string label, const StructureConstants &constants, lpi_scalar_fn h,
                 lpi_scalar_fn dh, void *user)
        : Piece(std::move(label)), constants_(constants), h_(h), dh_(dh), user_(user) {}

    void flow(double t, double *x) override {
        const double b = x[0], a = x[2];
        if (!std::isfinite(a * b))
            fail(LPI_ERR_OVERFLOW, "x1 x3 = " + std::to_string(b) + " * " + std::to_string(a) +
                                       " overflows in " + label());
        const double mu = derivative(a * b);
        const double lambda = 4.0 * x[1] * mu;

        // exp(tM) = c I + s M with M^2 = delta I, delta = -det M = 4 mu^2 (x2^2 - ab).
        // Everything is formed as a difference from the identity (c - 1 from
        // half-angle formulas, expm1 for the scalings) so that the map is
        // applied as x + increment with errors relative to the increment:
        // rounding F itself would bias det F away from 1 by the same amount
        // every step, and I, K (weights 4 and 6 in det F) would drift.
        const double delta = 4.0 * mu * mu * (x[1] * x[1] - a * b);
        double c_minus_1 = 0.0, s = t;
        if (delta > 0.0) {
            const double r = std::sqrt(delta), h = std::sinh(0.5 * r * t);
            c_minus_1 = 2.0 * h * h;
            s = std::sinh(r * t) / r;
        } else if (delta < 0.0) {
            const double r = std::sqrt(-delta), h = std::sin(0.5 * r * t);
            c_minus_1 = -2.0 * h * h;
            s = std::sin(r * t) / r;
        }
        const double grow_minus_1 = std::expm1(0.5 * lambda * t);
        const double shrink_minus_1 = std::expm1(-0.5 * lambda * t);
        // D = F - I, F = diag(e^{lambda t/2}, e^{-lambda t/2}) (c I + s M).
        const double D[2][2] = {
            {grow_minus_1 + (1.0 + grow_minus_1) * (c_minus_1 - 0.5 * s * lambda),
             (1.0 + grow_minus_1) * s * 2.0 * mu * b},
            {(1.0 + shrink_minus_1) * s * (-2.0 * mu * a),
             shrink_minus_1 + (1.0 + shrink_minus_1) * (c_minus_1 + 0.5 * s * lambda)}};

        // Row r of Sym^4(F) - I: coefficients on q^(4-k) p^k of
        // (q + D0.(q,p))^(4-r) (p + D1.(q,p))^r minus the monomial q^(4-r) p^r,
        // expanded as (monomial + E)(unit + d) = monomial*unit + (monomial*d + E*unit + E*d).
        double increment[5];
        for (int r = 0; r < 5; ++r) {
            double E[6] = {0, 0, 0, 0, 0, 0}, next[6];
            int exponent = 0;  // of p in the exact monomial part
            for (int f = 0; f < 4; ++f) {
                const bool unit_p = f >= 4 - r;
                const double *d = D[unit_p ? 1 : 0];
                for (int k = 0; k < 6; ++k) {
                    const double shifted = k > 0 ? E[k - 1] : 0.0;
                    next[k] = (unit_p ? shifted : E[k]) + E[k] * d[0] + shifted * d[1];
                }
                next[exponent] += d[0];
                next[exponent + 1] += d[1];
                exponent += unit_p ? 1 : 0;
                std::copy(next, next + 6, E);
            }
            double sum = 0.0;
            for (int k = 0; k < 5; ++k) sum += E[k] * x[3 + k];
            increment[r] = sum;
        }
        for (int r = 0; r < 5; ++r) x[3 + r] += increment[r];
        x[0] = b + b * std::expm1(lambda * t);
        x[2] = a + a * std::expm1(-lambda * t);
    }

    double energy(const double *x) const override {
        double value = 0.0;
        const int rc = h_(x[0] * x[2], &value, user_);
        check(rc, value, "H");
        return value;
    }

    void add_vector_field(const double *x, double *rate) const override {
        const double mu = derivative(x[0] * x[2]);
        const std::uint32_t sigma[2] = {0, 2};
        const double g[2] = {mu * x[2], mu * x[0]};
        add_poisson_times(constants_, sigma, 2, g, x, rate);
    }

private:
    double derivative(double u) const {
        double value = 0.0;
        const int rc = dh_(u, &value, user_);
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

std::unique_ptr<GenericModel> make_moments() {
    constexpr std::size_t count = sizeof kMomentBrackets / sizeof kMomentBrackets[0];
    std::int32_t i[count], j[count], k[count];
    double c[count];
    for (std::size_t e = 0; e < count; ++e) {
        i[e] = kMomentBrackets[e].i;
        j[e] = kMomentBrackets[e].j;
        k[e] = kMomentBrackets[e].k;
        c[e] = kMomentBrackets[e].c;
    }
    auto model = std::make_unique<GenericModel>(
        std::make_unique<StructureConstants>(8, count, i, j, k, c), "moments");
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
