#include "rigid_body_exact.hpp"

#include <algorithm>
#include <cmath>

#include "elliptic.hpp"

namespace lpi {

// Relabel the axes (a, b, c) so that m_c never vanishes and m_a, m_b oscillate:
// c is the axis of largest inertia below the separatrix (2H < |m|^2 / I_mid),
// of smallest inertia above it. In those labels (Landau & Lifshitz, Mechanics,
// section 37)
//   m_a = A_a cn(u), m_b = A_b sn(u), m_c = sigma A_c dn(u), u = u0 + lambda t,
// with A_a, A_c from |m|^2 and 2H, and the parameter and rate from the
// equations of motion. An odd relabelling reverses time (the cross product
// changes sign), which lambda absorbs.
void rigid_body_exact(const double inertia[3], const double m0[3], double t, double out[3]) {
    const double M2 = m0[0] * m0[0] + m0[1] * m0[1] + m0[2] * m0[2];
    const double E = m0[0] * m0[0] / inertia[0] + m0[1] * m0[1] / inertia[1] +
                     m0[2] * m0[2] / inertia[2];  // twice the energy
    int order[3] = {0, 1, 2};
    std::sort(order, order + 3, [&](int x, int y) { return inertia[x] < inertia[y]; });
    const int lo = order[0], mid = order[1], hi = order[2];

    int a, b, c;
    if (E <= M2 / inertia[mid]) {
        a = lo, b = mid, c = hi;
    } else {
        a = hi, b = mid, c = lo;
    }
    const double wa = 1.0 / inertia[a], wb = 1.0 / inertia[b], wc = 1.0 / inertia[c];
    // Parity of (a, b, c) as a permutation of (0, 1, 2).
    const bool even = (b == (a + 1) % 3);

    const double span = wa - wc;  // nonzero unless the body is a sphere
    if (span == 0.0 || M2 == 0.0) {
        std::copy(m0, m0 + 3, out);  // every vector is a steady rotation
        return;
    }
    const double Aa2 = std::max(0.0, (E - M2 * wc) / span);
    const double Ac2 = std::max(0.0, (M2 * wa - E) / span);
    const double Aa = std::sqrt(Aa2), Ac = std::sqrt(Ac2);
    if (Aa == 0.0 || Ac == 0.0) {
        std::copy(m0, m0 + 3, out);  // steady rotation about axis c (or a)
        return;
    }
    double m = Aa2 * (wa - wb) / (Ac2 * (wb - wc));
    m = std::clamp(m, 0.0, 1.0);
    const double Ab = std::sqrt(Aa2 + m * Ac2);
    const double sigma = m0[c] < 0.0 ? -1.0 : 1.0;
    // From dm_b/dt = m_c m_a (w_a - w_c) in even labels: Ab lambda = sigma Ac Aa (w_a - w_c).
    double lambda = sigma * Ac * Aa * span / Ab;
    if (!even) lambda = -lambda;

    // Phase: sn(u0) = m_b / A_b, cn(u0) = m_a / A_a, i.e. amplitude phi0.
    const double phi0 = std::atan2(m0[b] / Ab, m0[a] / Aa);
    const double u0 = elliptic_f(phi0, m);
    const JacobiSnCnDn f = jacobi_sncndn(u0 + lambda * t, m);
    out[a] = Aa * f.cn;
    out[b] = Ab * f.sn;
    out[c] = sigma * Ac * f.dn;
}

}  // namespace lpi
