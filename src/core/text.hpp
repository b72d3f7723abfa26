// Numbers in error messages, formatted one way everywhere.
#pragma once

#include <cstdio>
#include <string>

namespace lpi {

// x with `digits` significant digits (printf %g); the default 17 reads back
// as the same double.
inline std::string number_text(double x, int digits = 17) {
    char text[40];
    std::snprintf(text, sizeof text, "%.*g", digits, x);
    return text;
}

}  // namespace lpi
