#include "elliptic.hpp"

#include <algorithm>
#include <cmath>

namespace lpi {

double carlson_rf(double x, double y, double z) {
    // Duplication until the arguments agree to ~u^(1/6), then the fifth-order
    // Taylor expansion (Carlson 1995, eq. 2.2-2.4).
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

double elliptic_k(double m) { return carlson_rf(0.0, 1.0 - m, 1.0); }

double elliptic_f(double phi, double m) {
    const double pi = 3.14159265358979323846;
    const double turns = std::nearbyint(phi / pi);
    const double rest = phi - turns * pi;  // in [-pi/2, pi/2]
    const double s = std::sin(rest), c = std::cos(rest);
    const double partial = s * carlson_rf(c * c, 1.0 - m * s * s, 1.0);
    return turns == 0.0 ? partial : partial + 2.0 * turns * elliptic_k(m);
}

JacobiSnCnDn jacobi_sncndn(double u, double m) {
    if (m >= 1.0) {
        const double sech = 1.0 / std::cosh(u);
        return {std::tanh(u), sech, sech};
    }
    if (m <= 0.0) return {std::sin(u), std::cos(u), 1.0};
    // Reduce u modulo the real period 4K so the AGM sees a moderate argument.
    const double K = elliptic_k(m);
    u = std::remainder(u, 4.0 * K);
    double a[16], c[16];
    a[0] = 1.0;
    double b = std::sqrt(1.0 - m);
    c[0] = std::sqrt(m);
    int n = 0;
    while (n < 15 && std::fabs(c[n]) > 1e-16 * a[n]) {
        a[n + 1] = 0.5 * (a[n] + b);
        c[n + 1] = 0.5 * (a[n] - b);
        b = std::sqrt(a[n] * b);
        ++n;
    }
    double phi = std::ldexp(a[n] * u, n), previous = phi;
    for (int j = n; j > 0; --j) {
        previous = phi;
        phi = 0.5 * (phi + std::asin(c[j] / a[j] * std::sin(phi)));
    }
    // dn = cos(phi_0) / cos(phi_1 - phi_0) (A&S 16.4.3) keeps its accuracy
    // where 1 - m sn^2 would cancel.
    const double sn = std::sin(phi), cn = std::cos(phi);
    return {sn, cn, n > 0 ? cn / std::cos(previous - phi) : std::sqrt(1.0 - m * sn * sn)};
}

}  // namespace lpi
