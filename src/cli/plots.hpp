// Helpers for the gnuplot figures of lpi: log axes over whole decades, every
// figure written as PNG and as SVG beside it, and each method's style.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <string>

namespace lpi_cli {

// A log axis over the whole decades around [lo, hi] (the positive finite
// data), labelled 10^k at every decade, or every 2nd, 3rd ... when there are
// many: each label once, none between decades.
inline std::string decade_axis(const char *axis, double lo, double hi) {
    if (!(lo > 0.0) || !(hi >= lo) || !std::isfinite(hi)) return "";
    int first = static_cast<int>(std::floor(std::log10(lo) + 1e-9));
    int last = static_cast<int>(std::ceil(std::log10(hi) - 1e-9));
    if (last <= first) last = first + 1;
    const int stride = (last - first + 7) / 8;
    first = static_cast<int>(std::floor(static_cast<double>(first) / stride)) * stride;
    last = static_cast<int>(std::ceil(static_cast<double>(last) / stride)) * stride;
    char text[256];
    std::snprintf(text, sizeof text,
                  "set logscale %s 10\nset %srange [1e%d:1e%d]\nset %stics 1e%d, 1e%d, 1e%d\n"
                  "set m%stics %d\nset format %s '10^{%%L}'\n",
                  axis, axis, first, last, axis, first, stride, last, axis, stride == 1 ? 10 : stride, axis);
    return text;
}

// The positive finite values' range, for decade_axis.
struct Range {
    double lo = INFINITY, hi = 0.0;
    void add(double v) {
        if (v > 0.0 && std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
    }
};

// Writes a figure's commands twice: BASE.png, then BASE.svg beside it.
inline void emit_figure(FILE *f, const std::string &base, int width, int height, const std::string &commands) {
    std::fprintf(f, "set terminal pngcairo size %d,%d enhanced font ',11'\nset output '%s.png'\n%s",
                 width, height, base.c_str(), commands.c_str());
    std::fprintf(f, "set terminal svg size %d,%d enhanced font 'Helvetica,11' background '#ffffff'\n"
                    "set output '%s.svg'\n%sset output\n",
                 width, height, base.c_str(), commands.c_str());
}

inline std::string format(const char *pattern, ...) __attribute__((format(printf, 1, 2)));
inline std::string format(const char *pattern, ...) {
    va_list args, again;
    va_start(args, pattern);
    va_copy(again, args);
    const int n = std::vsnprintf(nullptr, 0, pattern, args);
    va_end(args);
    std::string text(static_cast<std::size_t>(std::max(n, 0)) + 1, '\0');
    std::vsnprintf(&text[0], text.size(), pattern, again);
    va_end(again);
    text.resize(static_cast<std::size_t>(std::max(n, 0)));
    return text;
}

// Index of a registered method, -1 if none has that name.
int method_index(const std::string &method);
// Whether the registered method of that name is a Poisson map.
bool is_poisson(const std::string &method);
// Whether gnuplot is on the PATH: without it the figures are left out.
bool have_gnuplot();
// Runs a gnuplot script (its messages silenced); whether it succeeded.
bool run_gnuplot(const std::string &script);

// The i-th method's colour in a plot: twenty that read apart on white
// (Okabe and Ito's, then Kelly's colours of maximum contrast).
std::string plot_colour(std::size_t i);

// The i-th method's marker: gnuplot's fifteen shapes (filled ones first),
// then five glyphs; twenty in all, as many as the colours.
std::string plot_marker(std::size_t i);

// The i-th method of a plot: its own colour and marker; the baselines (not
// Poisson maps) dashed, so the two families read apart at a glance.
std::string plot_style(std::size_t i, const std::string &method);

// A method's legend entry: its order and stages (a step's cost in leapfrog
// steps), which is what tells the curves apart.
std::string method_label(const std::string &method);

// What became of a figure: drawn; gnuplot failed (a note: its script and
// data are there to rerun); or its script was not written (a failed file).
enum class Plot { drawn, gnuplot_failed, not_written };

// Starts a gnuplot script: CSV input, a grid, the key outside. Null, having
// said so, when it cannot be created.
FILE *open_plot_script(const std::string &path);

// Closes the script `f` written to `path` and runs it.
Plot finish_plot(FILE *f, const std::string &path);

}  // namespace lpi_cli
