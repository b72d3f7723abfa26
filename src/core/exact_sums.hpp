// Error-free transformations: a sum or a product of two doubles as its
// rounded value plus the exact error of that rounding.
#pragma once

#include <cmath>

namespace lpi {

// a + b = sum + error exactly, sum = fl(a + b), whatever their sizes (Knuth).
inline void two_sum(double a, double b, double &sum, double &error) {
    sum = a + b;
    const double b_part = sum - a;
    error = (a - (sum - b_part)) + (b - b_part);
}

// a b = product + error exactly, product = fl(a b), unless it under- or
// overflows (std::fma rounds once, in hardware or in software).
inline void two_product(double a, double b, double &product, double &error) {
    product = a * b;
    error = std::fma(a, b, -product);
}

}  // namespace lpi
