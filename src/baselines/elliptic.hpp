// Jacobi elliptic functions and the elliptic integral of the first kind, for
// the exact free rigid body. Parameter m = k^2 in [0, 1].
#pragma once

namespace lpi {

struct JacobiSnCnDn {
    double sn, cn, dn;
};

// Carlson's symmetric integral R_F(x, y, z) (B. C. Carlson, Numer. Algorithms
// 10 (1995) 13, algorithm of section 2; DLMF 19.36.1).
double carlson_rf(double x, double y, double z);

// Complete integral K(m) = R_F(0, 1 - m, 1); m < 1.
double elliptic_k(double m);

// Incomplete integral F(phi | m) for any real phi (quasi-periodic extension:
// F(phi + n pi) = F(phi) + 2 n K); m < 1, or m = 1 with |phi| < pi/2.
double elliptic_f(double phi, double m);

// sn, cn, dn of (u | m), by the arithmetic-geometric mean and descending
// Landen transformation (Abramowitz & Stegun 16.4); m = 1 gives the
// hyperbolic limits tanh, sech, sech.
JacobiSnCnDn jacobi_sncndn(double u, double m);

}  // namespace lpi
