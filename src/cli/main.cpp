// lpi: the liepoisson command.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <exception>
#include <new>
#include <string>
#include <vector>

#include "output.hpp"
#include "plots.hpp"
#include "run_watch.hpp"
#include "processes.hpp"
#include "report.hpp"
#include "run.hpp"
#include "scenes.hpp"
#include "stress.hpp"

using namespace lpi_cli;

namespace {

// The options of lpi report that configure scenes (it takes no other).
const char *const kReportSceneOptions[] = {"--N", "--T"};

// Each scene with, in brackets, the options that configure it: for lpi
// report (`report`), those of them report takes only.
void print_scenes(FILE *to, bool report) {
    std::fprintf(to, report ? "scenes: [the options of lpi report that configure them]\n"
                            : "scenes: [the options that configure them; lpi report takes --N and --T only]\n");
    for (const Scene &s : builtin_scenes()) {
        std::string notes;
        if (s.run_own) notes += " (lpi run only)";
        else if (!s.create) notes += " (lpi report only)";
        if (!s.in_default_report && !s.run_own) notes += " (not in the default report)";
        std::string options;
        for (const std::string &option : s.options)
            if (!report || std::find(std::begin(kReportSceneOptions), std::end(kReportSceneOptions), option) !=
                               std::end(kReportSceneOptions))
                options += (options.empty() ? " [" : " ") + option;
        if (!options.empty()) options += "]";
        std::fprintf(to, "  %-16s %s%s%s\n", s.name.c_str(), s.description.c_str(), options.c_str(),
                     notes.c_str());
    }
}

void print_usage(FILE *to) {
    std::fprintf(to,
                 "usage: lpi report [SCENE...] [--out DIR] [--N N] [--T T]\n"
                 "           error against CPU time for every applicable method over a sweep of\n"
                 "           step sizes; lpi report --help for more\n"
                 "       lpi run SCENE [options]   integrate one scene; lpi run --help for the options\n"
                 "       lpi stress [--quick] [FILTER]\n"
                 "           stiff and extreme cases against every applicable method: bounded,\n"
                 "           energy error, Casimir drift and status per case, step and method\n"
                 "       lpi methods   the integration methods: name, order, stages, reference\n"
                 "       lpi --version | --help (-h, help)\n"
                 "exit status: 0 success, 1 a failure, 2 a bad option, 130 (143) interrupted by\n"
                 "SIGINT (SIGTERM) (lpi run, lpi report)\n");
    print_scenes(to, false);
}

void print_report_usage(FILE *to) {
    std::fprintf(to,
                 "usage: lpi report [SCENE...] [--out DIR] [--N N] [--T T]\n"
                 "  For each SCENE (without one: the default scenes), every applicable method\n"
                 "  over a sweep of step sizes: a work-precision table (error at the final\n"
                 "  time, energy error and Casimir drift against CPU time, one core, measured\n"
                 "  in this run), then the CPU time each method needs for a given error.\n"
                 "  --out DIR   write DIR/SCENE.csv, DIR/SCENE_energy.csv and, with gnuplot,\n"
                 "              the plots there as PNG and SVG (default ./lpi-report)\n"
                 "  --N N       the sine-Euler scenes' N (odd >= 3, default 31)\n"
                 "  --T T       the sine-euler-long scene's final time (default 2000)\n");
    print_scenes(to, true);
}

int report_command(int argc, char **argv) {
    ReportOptions options;
    SceneOptions scene_options;
    std::vector<std::string> names;
    Arguments args("lpi report", argc, argv);
    while (!args.done()) {
        const std::string arg = args.next();
        if (arg == "--out") {
            options.out_dir = args.value(arg);
        } else if (arg == "--N") {
            scene_options.sine_euler_n = static_cast<int>(args.integer(arg, 3, 2147483647));
            if (scene_options.sine_euler_n % 2 == 0) args.fail("--N must be odd");
        } else if (arg == "--T") {
            scene_options.long_run_time = args.positive(arg);
        } else if (args.help(arg)) {
            print_report_usage(stdout);
            return 0;
        } else {
            names.push_back(args.operand(arg, "SCENE"));
        }
    }
    const std::vector<Scene> all = builtin_scenes(scene_options);
    std::vector<const Scene *> chosen;
    for (const std::string &name : names) {
        auto it = std::find_if(all.begin(), all.end(), [&](const Scene &s) { return s.name == name; });
        if (it == all.end()) args.fail("unknown scene '" + name + "' (lpi --help lists them)");
        if (it->run_own) args.fail("'" + name + "' is run by lpi run " + name + ", not reported");
        // Twice, it ran twice, the second run writing over the first's files.
        if (std::find(chosen.begin(), chosen.end(), &*it) != chosen.end()) args.fail("scene '" + name + "' named twice");
        chosen.push_back(&*it);
    }
    if (chosen.empty())
        for (const Scene &s : all)
            if (s.in_default_report) chosen.push_back(&s);
    // --N and --T configure scenes: one of those reported must take them.
    for (const std::string &option : args.given())
        if (configures_scenes(option) &&
            std::none_of(chosen.begin(), chosen.end(), [&](const Scene *s) {
                return std::find(s->options.begin(), s->options.end(), option) != s->options.end();
            }))
            args.fail(option + ": no scene reported takes it (lpi --help lists each scene's options)");
    // A --T below a sweep's largest step makes its steps T each, one step a
    // run: the sweep's rows repeat one another and its plot has nothing to show.
    for (const Scene *s : chosen)
        if (!s->steps.empty() &&
            std::find(s->options.begin(), s->options.end(), "--T") != s->options.end()) {
            const double largest = *std::max_element(s->steps.begin(), s->steps.end());
            if (s->final_time < largest)
                args.fail(format("--T %g: %s sweeps steps up to %g, which --T must reach", s->final_time,
                                 s->name.c_str(), largest));
        }
    // Every run of every scene reported is a count of steps below 2^62 (a
    // --T of 1e300 is not): checked before any scene runs.
    for (const Scene *s : chosen)
        for (double dt : s->steps)
            step_count(s->final_time, std::min(dt, s->final_time), "lpi report " + s->name + ": --T");
    const std::string no_dir = make_output_dir(options.out_dir);
    if (!no_dir.empty()) {
        std::fprintf(stderr, "lpi report: --out %s\n", no_dir.c_str());
        return 1;
    }
    // Every scene writes DIR/SCENE.csv first: one that cannot be written (a
    // directory lpi may not write in) fails now, before the work, as lpi run does.
    for (const Scene *s : chosen) {
        const std::string why = output_problem(options.out_dir + "/" + s->name + ".csv");
        if (!why.empty()) {
            std::fprintf(stderr, "lpi report: %s\n", why.c_str());
            return 1;
        }
    }
    std::printf("liepoisson %s: error against CPU time, one core, measured in this run\n",
                lpi_version_string());
    // A scene whose files were not written fails the command; the others still run.
    int status = 0;
    catch_interrupts();
    for (const Scene *s : chosen) {
        try {
            if (!run_report(*s, options)) status = 1;
        } catch (const Interrupted &) {
            std::printf("\ninterrupted: %s was not finished, and its files in %s/ are the last report's\n",
                        s->name.c_str(), options.out_dir.c_str());
            return 128 + interrupted_by;
        }
    }
    if (status == 0)
        std::printf("\n%s files are in %s/%s\n", have_gnuplot() ? "CSV, PNG and SVG" : "CSV", options.out_dir.c_str(),
                    have_gnuplot() ? "" : " (no images: gnuplot not found)");
    return status;
}

int methods_command(int argc, char **argv) {
    Arguments args("lpi methods", argc, argv);
    while (!args.done()) {
        const std::string arg = args.next();
        if (args.help(arg)) {
            std::printf("usage: lpi methods\n  the integration methods (lpi run --method NAME): name, order,\n"
                        "  stages (for a splitting method the leapfrog steps it composes, its cost in\n"
                        "  leapfrog steps; 1 for the others, whose cost lpi report measures), Poisson\n"
                        "  (keeps Casimirs to round-off), reference\n");
            return 0;
        }
        args.fail("takes no argument ('" + arg + "')");
    }
    std::printf("%-22s %5s %6s %7s  %s\n", "method", "order", "stages", "Poisson", "reference");
    for (int i = 0; i < lpi_method_count(); ++i)
        std::printf("%-22s %5d %6d %7s  %s\n", lpi_method_name(i), lpi_method_order(i), lpi_method_stages(i),
                    lpi_method_is_poisson(i) == 1 ? "yes" : "no", lpi_method_reference(i));
    return 0;
}

// Refuses any argument after a command that takes none (--version, --help).
void takes_no_argument(const std::string &command, int argc, char **argv) {
    Arguments args("lpi " + command, argc, argv);
    if (!args.done()) args.fail("takes no argument ('" + args.next() + "')");
}

int lpi_command(int argc, char **argv) {
    if (argc < 2) {
        print_usage(stderr);
        return 2;
    }
    const std::string command = argv[1];
    if (command == "--help" || command == "-h" || command == "help") {
        takes_no_argument(command, argc - 2, argv + 2);
        print_usage(stdout);
        return 0;
    }
    if (command == "--version") {
        takes_no_argument(command, argc - 2, argv + 2);
        std::printf("lpi (liepoisson) %s\n", lpi_version_string());
        return 0;
    }
    if (process_count() > 1 && command != "run") {
        std::fprintf(stderr, "lpi %s runs on one process; under mpirun only lpi run spreads its work\n",
                     command.c_str());
        return 2;
    }
    if (command == "report") return report_command(argc - 2, argv + 2);
    if (command == "run") return run_command(argc - 2, argv + 2);
    if (command == "stress") return stress_command(argc - 2, argv + 2);
    if (command == "methods") return methods_command(argc - 2, argv + 2);
    std::fprintf(stderr, "lpi: unknown command '%s'\n", command.c_str());
    print_usage(stderr);
    return 2;
}

}  // namespace

// Every command ends here (a failure may exit earlier, never with status 0):
// what escapes as a C++ exception (memory for a size the options ask for) is
// a failure with a message, not an abort, and so is standard output that
// could not be written (a full disk, a closed pipe).
int main(int argc, char **argv) {
    // A write past the file-size limit (ulimit -f) then fails with EFBIG,
    // which lpi reports, instead of raising SIGXFSZ, which would end it
    // without a message (standard output redirected to a file, gnuplot's images).
    std::signal(SIGXFSZ, SIG_IGN);
    start_processes(&argc, &argv);
    int status = 1;
    try {
        status = lpi_command(argc, argv);
    } catch (const std::bad_alloc &) {
        std::fprintf(stderr, "lpi: out of memory (the sizes asked for are too large)\n");
        return 1;
    } catch (const std::exception &e) {
        std::fprintf(stderr, "lpi: %s\n", e.what());
        return 1;
    }
    if (!close_written(stdout)) {
        std::fprintf(stderr, "lpi: writing the standard output failed: %s\n", std::strerror(errno));
        if (status == 0) status = 1;
    }
    // Rank 0 alone prints and draws: every process exits with its status.
    return agreed_failure(status);
}
