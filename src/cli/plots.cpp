#include "plots.hpp"

#include <cstdlib>

#include "common.hpp"

namespace lpi_cli {

// Index of a registered method, -1 if none has that name.
int method_index(const std::string &method) {
    for (int i = 0; i < lpi_method_count(); ++i)
        if (method == lpi_method_name(i)) return i;
    return -1;
}

bool is_poisson(const std::string &method) { return lpi_method_is_poisson(method_index(method)) == 1; }

bool have_gnuplot() { return std::system("command -v gnuplot >/dev/null 2>&1") == 0; }

bool run_gnuplot(const std::string &script) {
    return std::system(("gnuplot '" + script + "' 2>/dev/null").c_str()) == 0;
}

// The i-th method's colour in a plot: twenty that read apart on white
// (Okabe and Ito's, then Kelly's colours of maximum contrast).
std::string plot_colour(std::size_t i) {
    static const char *const colours[] = {"#0072b2", "#d55e00", "#009e73", "#cc79a7", "#56b4e9",
                                          "#e69f00", "#000000", "#875692", "#be0032", "#848482",
                                          "#8db600", "#654522", "#604e97", "#f99379", "#2b3d26",
                                          "#a1caf1", "#b3446c", "#c2b280", "#882d17", "#dcd300"};
    return std::string("rgb '") + colours[i % 20] + "'";
}

// The i-th method's marker: gnuplot's fifteen shapes (filled ones first),
// then five glyphs; twenty in all, as many as the colours.
std::string plot_marker(std::size_t i) {
    static const char *const markers[] = {"7", "5", "9", "11", "13", "15", "6", "4", "8", "10",
                                          "12", "14", "1", "2", "3", "'★'", "'♣'", "'♠'", "'♥'", "'#'"};
    return std::string("pt ") + markers[i % 20];
}

// The i-th method of a plot: its own colour and marker; the baselines (not
// Poisson maps) dashed, so the two families read apart at a glance.
std::string plot_style(std::size_t i, const std::string &method) {
    return "lc " + plot_colour(i) + " " + plot_marker(i) + " dt " + (is_poisson(method) ? "1" : "2");
}

// A method's legend entry: its order and stages (a step's cost in leapfrog
// steps), which is what tells the curves apart.
std::string method_label(const std::string &method) {
    const int i = method_index(method);
    const int stages = lpi_method_stages(i);
    return method + " (order " + std::to_string(lpi_method_order(i)) + ", " + std::to_string(stages) +
           (stages == 1 ? " stage)" : " stages)");
}

// Starts a gnuplot script: CSV input, a grid, the key outside.
FILE *open_plot_script(const std::string &path) {
    FILE *f = std::fopen(path.c_str(), "w");
    if (!f) cannot_write(path);
    else
        std::fprintf(f, "set datafile separator ','\nset grid xtics ytics mxtics mytics lw 0.5, lw 0.2\n"
                        "set key below center horizontal maxcols 3 samplen 3\nset xlabel offset 0,0.5\nset bmargin 12\nset tics out nomirror\nset border 3\n");
    return f;
}

Plot finish_plot(FILE *f, const std::string &path) {
    if (!close_written(f)) {
        cannot_write(path);
        return Plot::not_written;
    }
    return run_gnuplot(path) ? Plot::drawn : Plot::gnuplot_failed;
}

}  // namespace lpi_cli
