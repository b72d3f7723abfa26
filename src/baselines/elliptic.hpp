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

// sn, cn, dn of (u | k) by the descending Gauss transformation (Abramowitz &
// Stegun 16.12) in rational form, after taking whole half periods 2K out of u
// (sn and cn change sign with each) so that |u| <= K: no
// arcsine near 1, so accurate to a few ulps times |u| also as kc -> 0, where
// the arcsine form of the Landen recursion loses half the digits. kc = 0
// gives the hyperbolic limits tanh, sech, sech, kc = 1 sin, cos, 1.
JacobiSnCnDn jacobi_sncndn(double u, double kc);

// The argument u of given sn, cn, dn (sn^2 + cn^2 = 1 and dn^2 = cn^2 +
// kc^2 sn^2 to round-off, dn > 0), as offset + (half_period ? 2K : 0) with
// |offset| <= K. From the incomplete integral F = sn R_F(cn^2, dn^2, 1)
// (Carlson), which stays accurate where sn is close to 1 and cn, dn are tiny
// (beside the separatrix, near the middle axis): the small values enter
// themselves, never as 1 - sn. Keeping the half period apart lets the caller
// apply sn(u + 2K) = -sn(u), cn(u + 2K) = -cn(u) exactly, so that K, which
// carries its own rounding, never enters the phase at t = 0.
struct JacobiArgument {
    double offset;
    bool half_period;
};
JacobiArgument jacobi_argument(double sn, double cn, double dn);

}  // namespace lpi
