#include <algorithm>
#include <cmath>
#include <string>

#include "../core/error.hpp"
#include "../core/exact_sums.hpp"
#include "../core/text.hpp"
#include "models.hpp"

namespace lpi {

void compensated_add(double &x, double &carry, double increment) {
    // x + carry is a double-double: x + increment is split exactly into its
    // rounding and its error, the carry joins the error, and the pair is
    // renormalised; the only rounding is at u^2 |x|. Kahan's form (the carry
    // folded into the increment first, y = fl(increment + carry)) rounded at
    // the increment's last place, and where that sum fell on a tie, a tiny
    // increment added to the carry before decided the tie with its own
    // sign: the rigid body's axes split with inertias 1e16 or more apart,
    // whose third rotation stays below round-off, drifted |m|^2 by 1.6e-16
    // in 1000 steps (50 standard errors).
    double sum, error;
    two_sum(x, increment, sum, error);
    two_sum(sum, error + carry, x, carry);
}

namespace {

// The increments ((c - 1) x_i + s x_j, (c - 1) x_j - s x_i) of the rotation
// of the pair of double-doubles x + carry, each part's terms formed apart.
// From the rounded x + carry instead, a carry of half an ulp put the sum on
// a tie, which the tiny increments the carry had taken decided with their
// own sign: the axes split's drift of |m|^2 (compensated_add) came back at a
// fortieth of its size.
void pair_increments(const double *x, const double *carry, int i, int j, double c_minus_1, double s,
                     double &di, double &dj) {
    di = (c_minus_1 * x[i] + s * x[j]) + (c_minus_1 * carry[i] + s * carry[j]);
    dj = (c_minus_1 * x[j] - s * x[i]) + (c_minus_1 * carry[j] - s * carry[i]);
}

// The rotation of a pair too large for its increments (up to 2 |x|): applied
// to [x, carry] scaled by 1/4, exactly, and scaled back.
[[gnu::cold, gnu::noinline]] void rotate_large_pair(double *x, double *carry, int i, int j,
                                                    double c_minus_1, double s) {
    double xs[2] = {0.25 * x[i], 0.25 * x[j]}, cs[2] = {0.25 * carry[i], 0.25 * carry[j]};
    double di, dj;
    pair_increments(xs, cs, 0, 1, c_minus_1, s, di, dj);
    compensated_add(xs[0], cs[0], di);
    compensated_add(xs[1], cs[1], dj);
    x[i] = 4.0 * xs[0], carry[i] = 4.0 * cs[0];
    x[j] = 4.0 * xs[1], carry[j] = 4.0 * cs[1];
}

}  // namespace

void rotate_pair(double *x, double *carry, int i, int j, double angle) {
    // The increment (c - 1) x + s y, with c - 1 = -2 sin^2(a/2), is small for
    // small angles, so its own rounding errors are scaled down by the angle.
    const double h = std::sin(0.5 * angle);
    const double c_minus_1 = -2.0 * h * h;
    const double s = std::sin(angle);
    double di, dj;
    pair_increments(x, carry, i, j, c_minus_1, s, di, dj);
    // Above DBL_MAX / 3 an increment may overflow where the rotated pair
    // does not (a state of 8e307 failed a step as non-finite).
    if (!std::isfinite(di) || !std::isfinite(dj)) return rotate_large_pair(x, carry, i, j, c_minus_1, s);
    compensated_add(x[i], carry[i], di);
    compensated_add(x[j], carry[j], dj);
}

}  // namespace lpi

namespace lpi {

void CompensatedModel::value(const double *state, double *x) const {
    const std::size_t n = dim();
    for (std::size_t i = 0; i < n; ++i) x[i] = state[i] + state[n + i];
}

void CompensatedModel::to_public(const double *state, double *x) const { value(state, x); }

void CompensatedModel::from_public(const double *x, double *state) const {
    Model::from_public(x, state);  // validates and copies x
    std::fill(state + dim(), state + 2 * dim(), 0.0);
}

void CompensatedModel::vector_field(const double *state, double *rate) const {
    double x[kMaxCompensatedDim];
    value(state, x);
    public_vector_field(x, rate);
    std::fill(rate + dim(), rate + 2 * dim(), 0.0);
}

}  // namespace lpi

namespace lpi {

namespace {

// The carry of a compensated model ([x, carry]) is the rounding remainder
// of x: at most half an ulp of its component when a flow writes it
// (compensated_add). The non-splitting baselines (rk4, implicit-midpoint)
// leave it as it is while x moves, so it is bounded against the largest
// component, with a margin of 2^21 over what the flows leave: 2^-32 of it.
constexpr double kMaxRelativeCarry = 0x1p-32;

}  // namespace

void check_compensated_state(const Model &model, const double *state) {
    const std::size_t n = model.dim();
    double largest = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        const double value = state[i] + state[n + i];
        if (!std::isfinite(value))
            fail(LPI_ERR_INVALID, "state entry " + std::to_string(i) +
                                      " overflows when its compensation carry is added");
        largest = std::fmax(largest, std::fabs(value));
    }
    for (std::size_t i = 0; i < n; ++i)
        if (std::fabs(state[n + i]) > kMaxRelativeCarry * largest)
            fail(LPI_ERR_INVALID, "the compensation carry of state entry " + std::to_string(i) +
                                      " is " + number_text(state[n + i]) +
                                      ", no rounding remainder of a state whose largest entry (with its carry) "
                                      "is " + number_text(largest));
}

}  // namespace lpi
