// Helpers for the gnuplot figures of lpi: log axes over whole decades, every
// figure written as PNG and as SVG beside it, and each method's style.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <string>
#include <vector>

#include "common.hpp"

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

// Index of a registered method, -1 if none has that name.
int method_index(const std::string &method);
// Whether the registered method of that name is a Poisson map.
bool is_poisson(const std::string &method);
// Whether gnuplot is on the PATH: without it the figures are left out, and
// the commands say so (lpi(1)).
bool have_gnuplot();

// The i-th method's colour in a plot: twenty that read apart on white
// (Okabe and Ito's, then Kelly's colours of maximum contrast).
std::string plot_colour(std::size_t i);

// The i-th method's marker: gnuplot's fifteen shapes (filled ones first),
// then five glyphs; twenty in all, as many as the colours.
std::string plot_marker(std::size_t i);

// The i-th method of a plot: its own colour and marker; the baselines (not
// Poisson maps) dashed, so the two families read apart at a glance.
std::string plot_style(std::size_t i, const std::string &method);

// A method's legend entry: its order and, for a splitting method, its stages
// (a step's cost in leapfrog steps).
std::string method_label(const std::string &method);

// A gnuplot script, the data files it reads that the command writes with it,
// and the images it draws, in one output directory. gnuplot runs there,
// without a shell, so every file a script names is a name inside that
// directory, lpi's own (the directory the user gave never enters a script).
// The data files are written and the images drawn into temporary files
// beside them, and all are put in place (output.hpp) with the script, saved
// as DIR/NAME to be rerun there by hand, only when gnuplot succeeded and
// every image is whole (gnuplot's exit status does not tell a write that
// failed): a failure keeps every old file, and the command fails, naming the
// file. So a directory never holds one run's data beside another's images.
class PlotScript {
public:
    PlotScript(std::string dir, std::string name) : dir_(std::move(dir)), name_(std::move(name)) {}
    // Appends commands.
    PlotScript &operator+=(const std::string &commands) {
        text_ += commands;
        return *this;
    }
    // "set output '...'" for `image`, a name in the directory.
    std::string output(const std::string &image);
    // A data file (a name in the directory, its text) for the script to
    // read: what to write in the script where it names the file (quoted).
    std::string data(const std::string &file, std::string text);
    // Without gnuplot: puts the data files alone in place. "" or why not.
    std::string save_data() const;
    // Commands drawn twice, as BASE.png, then BASE.svg beside it.
    void add_figure(const std::string &base, int width, int height, const std::string &commands);
    // Saves the script, runs gnuplot and puts the images in place: "" or why
    // not (naming the file).
    std::string draw() const;
    // Writes the script alone, naming the images it draws (drawn later, or
    // by hand): "" or why not.
    std::string save_script() const;

private:
    // The text with each image's and each data file's mark replaced by the
    // quoted names given.
    std::string with_names(const std::vector<std::string> &images, const std::vector<std::string> &data) const;
    std::string dir_, name_, text_;
    std::vector<std::string> images_;
    struct DataFile {
        std::string file, text;
    };
    std::vector<DataFile> data_;
};

// The start of a script that plots lpi's CSV files: a grid, the key outside.
std::string csv_plot_preamble();

}  // namespace lpi_cli
