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
#include <cmath>

#include "../core/error.hpp"
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

int casimir_I(std::size_t, const double *x, double *out, void *) {
    *out = x[3] * x[7] - 4.0 * x[4] * x[6] + 3.0 * x[5] * x[5];
    return 0;
}

int casimir_K(std::size_t, const double *x, double *out, void *) {
    // det [[x4,x5,x6],[x5,x6,x7],[x6,x7,x8]] (paper numbering)
    const double a = x[3], b = x[4], c = x[5], d = x[6], e = x[7];
    *out = a * (c * e - d * d) - b * (b * e - d * c) + c * (b * d - c * c);
    return 0;
}

class ProductPiece final : public Piece {
public:
    ProductPiece(std::string label, const StructureConstants &constants, lpi_scalar_fn h,
                 lpi_scalar_fn dh, void *user)
        : Piece(std::move(label)), constants_(constants), h_(h), dh_(dh), user_(user) {}

    void flow(double t, double *x) override {
        const double b = x[0], a = x[2];
        const double mu = derivative(a * b);
        const double lambda = 4.0 * x[1] * mu;
        const double grow = std::exp(0.5 * lambda * t), shrink = std::exp(-0.5 * lambda * t);

        // exp(tM) = c I + s M with M^2 = delta I, delta = -det M = 4 mu^2 (x2^2 - ab).
        const double delta = 4.0 * mu * mu * (x[1] * x[1] - a * b);
        double c = 1.0, s = t;
        if (delta > 0.0) {
            const double r = std::sqrt(delta);
            c = std::cosh(r * t);
            s = std::sinh(r * t) / r;
        } else if (delta < 0.0) {
            const double r = std::sqrt(-delta);
            c = std::cos(r * t);
            s = std::sin(r * t) / r;
        }
        const double F[2][2] = {{grow * (c - s * 0.5 * lambda), grow * s * 2.0 * mu * b},
                                {shrink * s * (-2.0 * mu * a), shrink * (c + s * 0.5 * lambda)}};

        // Row r of Sym^4(F): coefficients on q^(4-c) p^c of
        // (F11 q + F12 p)^(4-r) (F21 q + F22 p)^r.
        double y[5];
        for (int r = 0; r < 5; ++r) {
            double poly[5] = {1, 0, 0, 0, 0};
            int degree = 0;
            for (int f = 0; f < 4; ++f) {
                const double *row = f < 4 - r ? F[0] : F[1];
                for (int k = degree + 1; k > 0; --k) poly[k] = poly[k] * row[0] + poly[k - 1] * row[1];
                poly[0] *= row[0];
                ++degree;
            }
            double sum = 0.0;
            for (int k = 0; k < 5; ++k) sum += poly[k] * x[3 + k];
            y[r] = sum;
        }
        for (int r = 0; r < 5; ++r) x[3 + r] = y[r];
        x[0] = grow * grow * b;
        x[2] = shrink * shrink * a;
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
    model->add_casimir(casimir_I, nullptr);
    model->add_casimir(casimir_K, nullptr);
    return model;
}

void add_moments_product_piece(GenericModel &model, lpi_scalar_fn h, lpi_scalar_fn dh,
                               void *user) {
    if (std::string(model.kind()) != "moments")
        fail(LPI_ERR_UNSUPPORTED, std::string("the product piece H(x1 x3) belongs to the moment "
                                              "algebra; this is a ") + model.kind() + " system");
    if (!h) fail(LPI_ERR_NULL, "the H callback is NULL");
    if (!dh) fail(LPI_ERR_NULL, "the H' callback is NULL");
    model.add_piece(std::make_unique<ProductPiece>(model.next_piece_name() + " (product H(x1 x3))",
                                                   model.constants(), h, dh, user));
}

}  // namespace lpi
