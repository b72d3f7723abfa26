// Jacobi elliptic functions and their inverse, for the exact free rigid body.
// The modulus is given by its complement kc = k' = sqrt(1 - k^2) in [0, 1]:
// near the separatrix kc is small and the caller knows it to full relative
// accuracy from the data, which 1 - k^2 formed from k^2 would have lost (the
// period, about 2 log(4 / kc), depends on kc itself).
#pragma once

namespace lpi {

struct JacobiSnCnDn {
    double sn, cn, dn;
};

// sn, cn, dn of (u | k) by the arithmetic-geometric mean and the descending
// Landen transformation (Abramowitz & Stegun 16.4), after reducing u modulo
// the period 4K. Absolute accuracy a few ulps for |u| up to a few K; kc = 0
// gives the hyperbolic limits tanh, sech, sech, kc = 1 sin, cos, 1.
JacobiSnCnDn jacobi_sncndn(double u, double kc);

// The argument u in [-2K, 2K] whose sn, cn, dn are the given values (which
// satisfy sn^2 + cn^2 = 1 and dn^2 = cn^2 + kc^2 sn^2 to round-off, dn > 0).
// From the incomplete integral F = sn R_F(cn^2, dn^2, 1) (Carlson), which
// stays accurate where sn is close to 1 and cn, dn are tiny (beside the
// separatrix, near the middle axis): the small values enter themselves, never
// as 1 - sn. cn < 0 needs kc > 0 (the branch beyond K).
double jacobi_argument(double sn, double cn, double dn, double kc);

}  // namespace lpi
