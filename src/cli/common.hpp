// Small helpers shared by the lpi subcommands. The command uses only the
// public C API, as any user program would.
#pragma once

#include <liepoisson.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <functional>
#include <sys/stat.h>
#include <cstring>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace lpi_cli {

constexpr double kPi = 3.14159265358979323846;

// Uniform in [0, 1) from splitmix64: a small, well-mixed deterministic
// generator (the same numbers on every machine).
inline double uniform_random(std::uint64_t &state) {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    z ^= z >> 31;
    return static_cast<double>(z >> 11) * 0x1.0p-53;
}

// printf into a std::string.
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

inline double cpu_seconds() {
    timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Exits with the library's message: the command (never the library) stops.
inline void check(int status, const lpi_system *sys, const char *what) {
    if (status == LPI_OK) return;
    std::fprintf(stderr, "lpi: %s failed: %s (%s)\n", what, lpi_last_error(sys),
                 lpi_status_name(status));
    std::exit(1);
}

// Closes a file written with stdio: false when a write or the close failed
// (a full disk may show only at the final flush, in fclose).
inline bool close_written(FILE *f) {
    const bool written = std::ferror(f) == 0;
    return std::fclose(f) == 0 && written;
}

// Says on standard error why an output was not written (`why` names the
// file and the reason: output.hpp); false.
inline bool cannot_write(const std::string &why) {
    std::fprintf(stderr, "lpi: %s\n", why.c_str());
    return false;
}

// Makes the output directory `dir` (one level), or finds it there: "" or why
// not. Checked before anything is computed, so that a command whose output
// cannot be written fails at once instead of after its work.
inline std::string make_output_dir(const std::string &dir) {
    if (mkdir(dir.c_str(), 0777) != 0 && errno != EEXIST) return dir + ": " + std::strerror(errno);
    struct stat st;
    if (stat(dir.c_str(), &st) != 0) return dir + ": " + std::strerror(errno);
    if (!S_ISDIR(st.st_mode)) return dir + " exists and is not a directory";
    return "";
}

// The number rules of the options (Arguments below), for any text lpi reads
// as a number, an option's value or a field of a file it reads back. A
// decimal number is the whole text (no "10x", "", " 5"), decimal (no
// "0x10"), finite (no "nan", "inf") and within the range of a double (no
// "1e400"); "" or what is wrong with `text`.
inline std::string decimal_problem(const std::string &text, double &v) {
    const char *begin = text.c_str();
    char *end = nullptr;
    errno = 0;
    v = std::strtod(begin, &end);
    // strtod alone would also read hexadecimal ("0x10"), which the
    // characters allowed here rule out.
    if (text.empty() || text.find_first_not_of("0123456789+-.eE") != std::string::npos || end == begin ||
        *end != '\0')
        return "'" + text + "' is not a decimal number";
    if (!std::isfinite(v)) return text + " is not finite";
    if (errno == ERANGE) return text + " is out of the range of a double";
    return "";
}

inline std::string range_text(int64_t lo, int64_t hi) {
    if (hi == INT64_MAX) return " (at least " + std::to_string(lo) + ")";
    return " (" + std::to_string(lo) + " to " + std::to_string(hi) + ")";
}

// A whole number in [lo, hi]: digits, or a decimal number that is whole
// ("1e6" is, "2.9" is not). "" or what is wrong with `text`.
inline std::string whole_problem(const std::string &text, int64_t lo, int64_t hi, int64_t &v) {
    const char *begin = text.c_str();
    char *end = nullptr;
    errno = 0;
    long long n = std::strtoll(begin, &end, 10);
    const bool digits_only = !text.empty() && !std::isspace(static_cast<unsigned char>(text[0])) &&
                             end != begin && *end == '\0';
    if (digits_only && errno == ERANGE) return text + " is out of range" + range_text(lo, hi);
    if (!digits_only) {
        double d = 0.0;
        const std::string why = decimal_problem(text, d);
        if (!why.empty()) return why;
        if (d != std::trunc(d)) return "'" + text + "' is not a whole number";
        if (!(std::fabs(d) < 0x1p63)) return text + " is out of range" + range_text(lo, hi);
        n = static_cast<long long>(d);
    }
    if (n < lo || n > hi) return text + " is out of range" + range_text(lo, hi);
    v = n;
    return "";
}

// One strict reader of a command's arguments, used by every command for every
// option: a value must be the whole text, numbers as decimal_problem and
// whole_problem say, and an option may be given once. Anything else stops
// the command with a message and exit status 2.
class Arguments {
public:
    Arguments(std::string command, int argc, char **argv)
        : command_(std::move(command)), argc_(argc), argv_(argv) {}

    bool done() const { return next_ >= argc_; }
    // The options given with a value so far (for options a scene does not take).
    const std::set<std::string> &given() const { return seen_; }
    // The next argument (an option name or an operand).
    std::string next() { return argv_[next_++]; }

    // Whether `arg` asks for the command's usage.
    static bool is_help(const std::string &arg) { return arg == "--help" || arg == "-h"; }

    // Whether `arg` (just read by next()) asks for the command's usage, which
    // then is all it does: an argument after it would be ignored, so it is
    // refused.
    bool help(const std::string &arg) {
        if (!is_help(arg)) return false;
        if (!done()) fail("takes no argument after " + arg + " ('" + argv_[next_] + "')");
        return true;
    }

    // A flag (an option without a value), given once like every option.
    void flag(const std::string &option) {
        if (!seen_.insert(option).second) fail(option + " is given twice");
    }

    // `arg`, which matched none of the command's options, as an operand (a
    // scene, a filter): neither an option nor empty.
    std::string operand(const std::string &arg, const std::string &what) {
        refuse_unknown_option(arg);
        if (arg.empty()) fail("an empty argument is not a " + what);
        return arg;
    }

    // Stops the command when `arg`, which matched none of its options, looks
    // like an option ("-x"): it is then no operand either.
    void refuse_unknown_option(const std::string &arg) const {
        if (!arg.empty() && arg[0] == '-') fail("unknown option '" + arg + "' (" + command_ + " --help lists them)");
    }

    [[noreturn]] void fail(const std::string &message) const {
        std::fprintf(stderr, "%s: %s\n", command_.c_str(), message.c_str());
        std::exit(2);
    }

    // The value of `option` (just read by next()): the following argument,
    // non-empty, and no option ("--out --help" wrote into ./--help; a file
    // of such a name is still ./--help).
    std::string value(const std::string &option) {
        if (!seen_.insert(option).second) fail(option + " is given twice");
        if (done()) fail(option + " needs a value");
        const std::string text = argv_[next_++];
        if (text.empty()) fail(option + ": the value is empty");
        if (text.size() > 2 && text.compare(0, 2, "--") == 0)
            fail(option + " needs a value, not the option '" + text + "' (a file of that name is ./" + text + ")");
        return text;
    }

    // A whole number in [lo, hi].
    int64_t integer(const std::string &option, int64_t lo, int64_t hi) {
        return whole_number(option, value(option), lo, hi);
    }

    // A finite number > 0.
    double positive(const std::string &option) { return positive_number(option, value(option)); }

    // `count` finite numbers > 0, separated by commas ("1,2,3").
    std::vector<double> positives(const std::string &option, std::size_t count) {
        const std::string text = value(option);
        std::vector<double> out;
        std::size_t from = 0;
        for (;;) {
            const std::size_t comma = text.find(',', from);
            out.push_back(positive_number(option, text.substr(from, comma - from)));
            if (comma == std::string::npos) break;
            from = comma + 1;
        }
        if (out.size() != count)
            fail(option + ": '" + text + "' is not " + std::to_string(count) + " numbers separated by commas");
        return out;
    }

    int64_t whole_number(const std::string &option, const std::string &text, int64_t lo, int64_t hi) const {
        int64_t v = 0;
        const std::string why = whole_problem(text, lo, hi, v);
        if (!why.empty()) fail(option + ": " + why);
        return v;
    }

    double positive_number(const std::string &option, const std::string &text) const {
        double v = 0.0;
        const std::string why = decimal_problem(text, v);
        if (!why.empty()) fail(option + ": " + why);
        if (!(v > 0.0)) fail(option + ": " + text + " is not > 0");
        return v;
    }

private:
    std::string command_;
    int argc_;
    char **argv_;
    int next_ = 0;
    std::set<std::string> seen_;
};

// Owns one handle.
class Handle {
public:
    Handle() = default;
    explicit Handle(lpi_system *sys) : sys_(sys) {}
    Handle(const Handle &) = delete;
    Handle &operator=(const Handle &) = delete;
    Handle(Handle &&other) noexcept : sys_(other.sys_) { other.sys_ = nullptr; }
    Handle &operator=(Handle &&other) noexcept {
        std::swap(sys_, other.sys_);
        return *this;
    }
    ~Handle() { lpi_destroy(sys_); }
    lpi_system *get() const { return sys_; }
    lpi_system **out() { return &sys_; }

private:
    lpi_system *sys_ = nullptr;
};

// The registered methods a system accepts (the matrix-form baselines, for
// instance, apply to sine-Euler only), probed once on one system from `create`.
inline std::vector<bool> accepted_methods(const std::function<Handle()> &create) {
    Handle probe = create();
    std::vector<bool> accepted(static_cast<std::size_t>(lpi_method_count()));
    for (int i = 0; i < lpi_method_count(); ++i)
        accepted[static_cast<std::size_t>(i)] = lpi_set_method(probe.get(), lpi_method_name(i)) == LPI_OK;
    return accepted;
}

inline std::vector<double> state_of(const lpi_system *sys) {
    std::vector<double> x(lpi_dim(sys));
    check(lpi_get_state(sys, x.data(), x.size()), sys, "get state");
    return x;
}

inline std::vector<double> casimirs_of(const lpi_system *sys) {
    std::vector<double> c(lpi_casimir_count(sys));
    check(lpi_casimirs(sys, c.data(), c.size()), sys, "casimirs");
    return c;
}

inline double energy_of(const lpi_system *sys) {
    double h = 0.0;
    check(lpi_energy(sys, &h), sys, "energy");
    return h;
}

// The most steps a run takes: below 2^62, where a step's time and index still
// tell each other apart (a resumed run finds its step as time / dt).
constexpr int64_t kMaxSteps = (int64_t(1) << 62) - 1;

// The number of steps of `dt` in `span`, rounded: below 2^62, where a run's
// step counts and their sums stay exact in 64 bits; past that (a huge time
// or a tiny step) the command stops with a message and exit status 2.
inline int64_t step_count(double span, double dt, const std::string &what) {
    const double steps = span / dt;
    if (!(steps >= 0.0 && steps < 0x1p62)) {
        std::fprintf(stderr, "%s: %g / %g is too many steps (%g; at most 2^62)\n", what.c_str(), span, dt, steps);
        std::exit(2);
    }
    return std::llround(steps);
}

// Drift of a sine-Euler spectrum: the largest change of an eigenvalue of W
// relative to the largest |eigenvalue|. Relative to each eigenvalue itself,
// an eigenvalue near zero would turn round-off into an arbitrarily large
// "drift"; this measure is bounded by |dW| / |W| (Weyl), so it reads the same
// for every field.
inline double spectrum_drift(const std::vector<double> &spectrum, const std::vector<double> &spectrum0) {
    double scale = 0.0, change = 0.0;
    for (std::size_t i = 0; i < spectrum0.size(); ++i) {
        scale = std::max(scale, std::fabs(spectrum0[i]));
        change = std::max(change, std::fabs(spectrum[i] - spectrum0[i]));
    }
    return scale > 0.0 ? change / scale : change;
}

// Casimir drift: separate Casimirs (|m|^2; the moments' I and K) each
// relative to itself, a spectrum as above.
inline double casimir_drift(bool spectrum, const std::vector<double> &c, const std::vector<double> &c0) {
    if (spectrum) return spectrum_drift(c, c0);
    double drift = 0.0;
    for (std::size_t i = 0; i < c.size(); ++i)
        drift = std::max(drift, std::fabs(c[i] - c0[i]) / std::max(std::fabs(c0[i]), 1e-300));
    return drift;
}

}  // namespace lpi_cli
