#include "elliptic.hpp"

#include <algorithm>
#include <cmath>

namespace lpi {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Carlson's symmetric integral R_F(x, y, z) (B. C. Carlson, Numer. Algorithms
// 10 (1995) 13, section 2; DLMF 19.36.1): duplication until the arguments agree
// to ~u^(1/6), then the fifth-order Taylor expansion.
double carlson_rf(double x, double y, double z) {
    for (int iteration = 0; iteration < 100; ++iteration) {
        const double mean = (x + y + z) / 3.0;
        const double dx = 1.0 - x / mean, dy = 1.0 - y / mean, dz = 1.0 - z / mean;
        if (std::max({std::fabs(dx), std::fabs(dy), std::fabs(dz)}) < 1e-3) {
            const double e2 = dx * dy - dz * dz, e3 = dx * dy * dz;
            return (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0) /
                   std::sqrt(mean);
        }
        const double sx = std::sqrt(x), sy = std::sqrt(y), sz = std::sqrt(z);
        const double lambda = sx * (sy + sz) + sy * sz;
        x = 0.25 * (x + lambda);
        y = 0.25 * (y + lambda);
        z = 0.25 * (z + lambda);
    }
    return std::nan("");
}

// R_F(x^2, y^2, z^2) from x, y, z >= 0: the first duplication step needs only
// the roots, so arguments too small to square (below ~1e-154) do not underflow.
double carlson_rf_of_squares(double x, double y, double z) {
    const double lambda = x * y + x * z + y * z;
    return carlson_rf(0.25 * (x * x + lambda), 0.25 * (y * y + lambda), 0.25 * (z * z + lambda));
}

// The arithmetic-geometric mean of (1, kc) with the c_n the Landen
// transformation needs: a_{n+1} = (a_n + b_n) / 2, b_{n+1} = sqrt(a_n b_n),
// c_{n+1} = (a_n - b_n) / 2, c_0 = k. K = pi / (2 a_N).
struct Agm {
    static constexpr int kMaxSteps = 40;  // kc = 1e-300 needs 13
    double a[kMaxSteps + 1], c[kMaxSteps + 1];
    int steps = 0;

    explicit Agm(double kc) {
        a[0] = 1.0;
        c[0] = std::sqrt((1.0 - kc) * (1.0 + kc));
        double b = kc;
        while (steps < kMaxSteps && c[steps] > 1e-16 * a[steps]) {
            a[steps + 1] = 0.5 * (a[steps] + b);
            c[steps + 1] = 0.5 * (a[steps] - b);
            b = std::sqrt(a[steps] * b);
            ++steps;
        }
    }
    double quarter_period() const { return kPi / (2.0 * a[steps]); }
};

}  // namespace

JacobiSnCnDn jacobi_sncndn(double u, double kc) {
    if (kc == 0.0) {
        const double sech = 1.0 / std::cosh(u);
        return {std::tanh(u), sech, sech};
    }
    const Agm agm(kc);
    u = std::remainder(u, 4.0 * agm.quarter_period());
    double phi = std::ldexp(agm.a[agm.steps] * u, agm.steps);
    for (int j = agm.steps; j > 0; --j)
        phi = 0.5 * (phi + std::asin(agm.c[j] / agm.a[j] * std::sin(phi)));
    const double sn = std::sin(phi), cn = std::cos(phi);
    // dn^2 = 1 - k^2 sn^2 = cn^2 + kc^2 sn^2: two nonnegative terms, no
    // cancellation where dn is small (near u = K beside the separatrix).
    return {sn, cn, std::hypot(cn, kc * sn)};
}

double jacobi_argument(double sn, double cn, double dn, double kc) {
    const double in_first_half = sn * carlson_rf_of_squares(std::fabs(cn), dn, 1.0);  // |u| <= K
    if (cn >= 0.0) return in_first_half;
    // u and 2K - u (or -2K - u) share sn and dn; cn changes sign.
    return std::copysign(2.0 * Agm(kc).quarter_period(), sn) - in_first_half;
}

}  // namespace lpi
