// Numbers and the caller's strings in error messages, formatted one way
// everywhere.
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

// A string the caller passed (a name, a path) in single quotes, as it can
// be read in a one-line message: control characters as \n, \t or \xNN
// (a name that differs from a known one only by them then shows where),
// and at most `limit` bytes of it, "..." marking the cut.
inline std::string quoted(const std::string &text, std::size_t limit = 4096) {
    std::string out = "'";
    for (std::size_t i = 0; i < text.size() && i < limit; ++i) {
        const unsigned char c = static_cast<unsigned char>(text[i]);
        if (c == '\n') {
            out += "\\n";
        } else if (c == '\t') {
            out += "\\t";
        } else if (c < 0x20 || c == 0x7f) {
            char escape[8];
            std::snprintf(escape, sizeof escape, "\\x%02x", c);
            out += escape;
        } else {
            out += static_cast<char>(c);
        }
    }
    if (text.size() > limit) out += "...";
    return out + "'";
}

}  // namespace lpi
