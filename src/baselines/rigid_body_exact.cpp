#include "rigid_body_exact.hpp"

#include <algorithm>
#include <cmath>

#include "../core/error.hpp"
#include "../core/text.hpp"
#include "elliptic.hpp"

namespace lpi {

namespace {

// Just enough double-double arithmetic to form one difference of products
// to relative accuracy ~u^2 of its terms (Dekker; Ogita, Rump & Oishi 2005).
struct DoubleDouble {
    double hi, lo;
};
DoubleDouble exact_product(double a, double b) {
    const double p = a * b;
    return {p, std::fma(a, b, -p)};
}
DoubleDouble exact_difference(double a, double b) {
    const double s = a - b, bb = s - a;
    return {s, (a - (s - bb)) - (b + bb)};
}
DoubleDouble product(DoubleDouble x, DoubleDouble y) {
    DoubleDouble p = exact_product(x.hi, y.hi);
    p.lo += x.hi * y.lo + x.lo * y.hi;
    const double hi = p.hi + p.lo;
    return {hi, p.lo - (hi - p.hi)};
}
double rounded_difference(DoubleDouble x, DoubleDouble y) {
    const DoubleDouble d = exact_difference(x.hi, y.hi);
    return d.hi + (d.lo + (x.lo - y.lo));
}

// Two equal moments I_p = I_q (p, q, r cyclic): m_r is constant and (m_p, m_q)
// turns at the rate Omega = m_r (1/I_r - 1/I_p). With m_r = 0 (m in the plane
// of the equal axes, or a sphere) Omega = 0 and m is returned bit for bit.
void symmetric_top(const double I[3], const double m[3], int r, double t, double out[3]) {
    const int p = (r + 1) % 3, q = (r + 2) % 3;
    const double omega = m[r] * ((I[p] - I[r]) / (I[r] * I[p]));
    const double c = std::cos(omega * t), s = std::sin(omega * t);
    out[p] = m[p] * c + m[q] * s;
    out[q] = m[q] * c - m[p] * s;
    out[r] = m[r];
}

// Distinct moments. Relabel the axes (a, b, c), b the middle one, so that m_c
// never vanishes: c is the axis of largest inertia below the separatrix, of
// smallest above it. Then (Landau & Lifshitz, Mechanics, section 37)
//   m_a = A_a cn(u), m_b = A_b sn(u), m_c = sigma A_c dn(u), u = u0 + lambda t,
// modulus k. Every quantity is formed from the data without cancellation:
//   A_a^2 = m_a^2 + d_bc m_b^2,  A_c^2 = m_c^2 + d_ab m_b^2,  A_b = A_a / sqrt(d_bc),
// with d_bc = (w_b - w_c) / (w_a - w_c), d_ab = 1 - d_bc, w = 1/I from
// differences of the I themselves; kc^2 = 1 - k^2 = |S| / (P_c A_c^2) where
//   S = P_hi m_hi^2 - P_lo m_lo^2,  P_hi = I_lo (I_hi - I_mid),  P_lo = I_hi (I_mid - I_lo)
// is I_lo I_mid I_hi times the distance from the separatrix (its sign says the
// side, P_c is the weight of m_c in it). S is a true cancellation beside the
// separatrix, and the period there depends on log kc, so S is formed in
// double-double. S = 0 is the separatrix itself: the heteroclinic orbit
//   m_a = sigma_a A_a sech u, m_b = A_b tanh u, m_c = sigma A_c sech u.
// An odd relabelling reverses time (the cross product changes sign), which
// lambda absorbs. Two zero components (a steady rotation) are caught before.
void triaxial_body(const double I[3], const double m[3], double t, double out[3]) {
    int order[3] = {0, 1, 2};
    std::sort(order, order + 3, [&](int x, int y) { return I[x] < I[y]; });
    const int lo = order[0], mid = order[1], hi = order[2];

    // The pair (m_lo, m_hi) is scaled by a power of two so that its squares
    // neither underflow nor lose bits near the middle axis.
    const int pair_exponent = std::ilogb(std::max(std::fabs(m[lo]), std::fabs(m[hi])));
    const double m_lo = std::ldexp(m[lo], -pair_exponent), m_hi = std::ldexp(m[hi], -pair_exponent);
    const DoubleDouble P_hi = product({I[lo], 0.0}, exact_difference(I[hi], I[mid]));
    const DoubleDouble P_lo = product({I[hi], 0.0}, exact_difference(I[mid], I[lo]));
    const double S = rounded_difference(product(exact_product(m_hi, m_hi), P_hi),
                                        product(exact_product(m_lo, m_lo), P_lo));

    const bool circles_hi = S >= 0.0;
    const int a = circles_hi ? lo : hi, b = mid, c = circles_hi ? hi : lo;
    const double P_c = circles_hi ? P_hi.hi + P_hi.lo : P_lo.hi + P_lo.lo;
    const double d_bc = I[a] * std::fabs(I[b] - I[c]) / (I[b] * std::fabs(I[a] - I[c]));
    const double d_ab = I[c] * std::fabs(I[a] - I[b]) / (I[b] * std::fabs(I[a] - I[c]));
    const double span = (I[c] - I[a]) / (I[a] * I[c]);  // w_a - w_c
    const double root_bc = std::sqrt(d_bc);
    const double A_a = std::hypot(m[a], root_bc * m[b]);
    const double A_b = A_a / root_bc;
    const double A_c = std::hypot(m[c], std::sqrt(d_ab) * m[b]);
    const double sigma = m[c] < 0.0 ? -1.0 : 1.0;
    const bool even = (b == (a + 1) % 3);
    // From dm_b/dt = m_a m_c (w_a - w_c) in even labels.
    double lambda = sigma * A_c * root_bc * span;
    if (!even) lambda = -lambda;

    if (S == 0.0) {
        const double sigma_a = m[a] < 0.0 ? -1.0 : 1.0;
        const double u = std::asinh(root_bc * m[b] / std::fabs(m[a])) + sigma_a * lambda * t;
        const double sech = 1.0 / std::cosh(u);
        out[a] = sigma_a * A_a * sech;
        out[b] = A_b * std::tanh(u);
        out[c] = sigma * A_c * sech;
        return;
    }
    // kc <= 1 exactly; rounding may leave it an ulp above.
    const double kc =
        std::min(1.0, std::ldexp(std::sqrt(std::fabs(S) / P_c), pair_exponent) / A_c);
    const JacobiArgument u0 = jacobi_argument(root_bc * m[b] / A_a, m[a] / A_a, std::fabs(m[c]) / A_c);
    const JacobiSnCnDn f = jacobi_sncndn(u0.offset + lambda * t, kc);
    const double shift = u0.half_period ? -1.0 : 1.0;  // sn, cn of u + 2K
    out[a] = shift * A_a * f.cn;
    out[b] = shift * A_b * f.sn;
    out[c] = sigma * A_c * f.dn;
}

}  // namespace

void rigid_body_exact(const double inertia[3], const double m0[3], double t, double out[3]) {
    std::copy(m0, m0 + 3, out);
    const int zeros = (m0[0] == 0.0) + (m0[1] == 0.0) + (m0[2] == 0.0);
    if (zeros >= 2) return;  // at rest, or a steady rotation about an axis
    // The other steady rotations, a sphere's and those in the plane of two
    // equal moments (the top's rate is m_r times a difference of 1/I), are
    // returned before the scaling below, which rounds a component far
    // smaller than the largest (to a subnormal), and needs the inertias'
    // ratio as a double.
    for (int r = 0; r < 3; ++r) {
        const bool equal_pair = inertia[(r + 1) % 3] == inertia[(r + 2) % 3];
        if (equal_pair && (m0[r] == 0.0 || inertia[r] == inertia[(r + 1) % 3])) return;
    }

    // dm/dt = m x (m / I) is homogeneous: m -> 2^e m, I -> 2^f I maps the
    // solution at t to the one at 2^(e-f) t. Scaling to magnitudes near 1
    // keeps squares and products of large or small data finite and exact.
    const int m_exponent = std::ilogb(std::max({std::fabs(m0[0]), std::fabs(m0[1]), std::fabs(m0[2])}));
    const int i_exponent = std::ilogb(std::max({inertia[0], inertia[1], inertia[2]}));
    double I[3], m[3];
    for (int k = 0; k < 3; ++k) {
        I[k] = std::ldexp(inertia[k], -i_exponent);
        m[k] = std::ldexp(m0[k], -m_exponent);
    }
    const double scaled_t = std::ldexp(t, m_exponent - i_exponent);
    // Components below 2^-1074 of the largest vanish at this scale: what is
    // left is a steady rotation to far below round-off (they would need
    // t ~ 700 / rate to grow into view), and the amplitudes need two nonzero.
    if ((m[0] == 0.0) + (m[1] == 0.0) + (m[2] == 0.0) >= 2) return;

    // |m| is conserved, so the solution itself is always a double; what may
    // not be is, for inertias more than 2^1022 apart, the smallest scaled to
    // the largest, or (below) the phase, t times the body's rates.
    const double largest = std::max({inertia[0], inertia[1], inertia[2]});
    for (int k = 0; k < 3; ++k)
        if (!std::isnormal(I[k]))
            fail(LPI_ERR_OVERFLOW, "the ratio of the inertias " + number_text(largest) + " and " +
                                       number_text(inertia[k]) +
                                       " is beyond 2^1022: the exact solution needs it as a "
                                       "normal double");

    if (I[0] == I[1]) {
        symmetric_top(I, m, 2, scaled_t, out);
    } else if (I[1] == I[2]) {
        symmetric_top(I, m, 0, scaled_t, out);
    } else if (I[0] == I[2]) {
        symmetric_top(I, m, 1, scaled_t, out);
    } else {
        triaxial_body(I, m, scaled_t, out);
    }
    for (int k = 0; k < 3; ++k)
        if (!std::isfinite(out[k]))
            fail(LPI_ERR_NONFINITE, "t = " + number_text(t) + " times the body's rates (|m| / I) "
                                    "overflows a double: the phase of the solution is not representable");
    for (int k = 0; k < 3; ++k) out[k] = std::ldexp(out[k], m_exponent);
}

}  // namespace lpi
