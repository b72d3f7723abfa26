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

// The descending Gauss transformation (Abramowitz & Stegun 16.12) from
// modulus k_j to k_{j+1} = (1 - kc_j) / (1 + kc_j), kc_{j+1} = 2 sqrt(kc_j) /
// (1 + kc_j), argument u / (1 + k_{j+1}), repeated until k is below 1e-8 and
// the functions are circular to round-off (14 steps from kc = 1e-300). K =
// (pi / 2) prod (1 + k_j).
struct GaussChain {
    static constexpr int kMaxSteps = 32;
    double k[kMaxSteps + 1], kc[kMaxSteps + 1];
    int steps = 0;
    double argument_scale = 1.0;  // prod_{j >= 1} (1 + k_j)

    explicit GaussChain(double complement) {
        kc[0] = complement;
        k[0] = std::sqrt((1.0 - complement) * (1.0 + complement));
        while (k[steps] > 1e-8 && steps < kMaxSteps) {
            k[steps + 1] = (1.0 - kc[steps]) / (1.0 + kc[steps]);
            kc[steps + 1] = 2.0 * std::sqrt(kc[steps]) / (1.0 + kc[steps]);
            argument_scale *= 1.0 + k[steps + 1];
            ++steps;
        }
    }
    double quarter_period() const { return 0.5 * kPi * argument_scale; }
};

}  // namespace

JacobiSnCnDn jacobi_sncndn(double u, double kc) {
    if (kc == 0.0) {
        const double sech = 1.0 / std::cosh(u);
        return {std::tanh(u), sech, sech};
    }
    // u = r + 2K q with |r| <= K; sn(r + 2K) = -sn(r), cn(r + 2K) = -cn(r).
    const GaussChain chain(kc);
    const double half_period = 2.0 * chain.quarter_period();
    const double q = std::nearbyint(u / half_period);
    const double v = std::fma(-q, half_period, u) / chain.argument_scale;  // in [-pi/2, pi/2]
    double sn = std::sin(v), cn = std::cos(v), dn = std::hypot(cn, chain.kc[chain.steps] * sn);
    // Back up the chain (A&S 16.12.2-4):
    //   sn = (1 + k) s / (1 + k s^2), cn = c d / (1 + k s^2),
    //   dn = (1 - k s^2) / (1 + k s^2) = sqrt(cn^2 + kc^2 sn^2),
    // with s, c, d at modulus k and kc that of the level reached. sn keeps its
    // absolute accuracy (the map contracts near |sn| = 1). The product keeps
    // the relative accuracy of a tiny cn (near u = K beside the separatrix),
    // but where cn is near 1 it would double the error of 1 - cn at every
    // level: there cn = sqrt(1 - sn^2). dn takes the rational form unless
    // 1 - k s^2 cancels; then the two nonnegative terms.
    for (int j = chain.steps; j > 0; --j) {
        const double ks2 = chain.k[j] * sn * sn, denominator = 1.0 + ks2;
        cn = cn * dn / denominator;
        dn = (1.0 - ks2) / denominator;
        sn = (1.0 + chain.k[j]) * sn / denominator;
        if (std::fabs(cn) > std::fabs(sn)) cn = std::copysign(std::sqrt((1.0 - sn) * (1.0 + sn)), cn);
        if (ks2 > 0.5) dn = std::hypot(cn, chain.kc[j - 1] * sn);
    }
    const bool odd = std::fmod(q, 2.0) != 0.0;
    return {odd ? -sn : sn, odd ? -cn : cn, dn};
}

JacobiArgument jacobi_argument(double sn, double cn, double dn) {
    // F(am | k) = sn R_F(cn^2, dn^2, 1) for |u| <= K; u and 2K - u share sn
    // and dn while cn changes sign, and 2K - u = (-u) + 2K.
    const double first_half = sn * carlson_rf_of_squares(std::fabs(cn), dn, 1.0);
    if (cn >= 0.0) return {first_half, false};
    return {-first_half, true};
}

}  // namespace lpi
