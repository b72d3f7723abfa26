// lpi: the liepoisson command.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "report.hpp"
#include "run.hpp"
#include "scenes.hpp"
#include "stress.hpp"

using namespace lpi_cli;

namespace {

void print_usage(FILE *to) {
    std::fprintf(to,
                 "usage: lpi report [SCENE...] [--out DIR] [--N N] [--T T]\n"
                 "           error against CPU time for every applicable method over a sweep of\n"
                 "           step sizes; prints a table and writes CSV and PNG files to DIR\n"
                 "           (default ./lpi-report). Without SCENE: the default scenes.\n"
                 "           --N sets the sine-Euler scenes' N (odd, default 31); --T the\n"
                 "           sine-euler-long scene's final time (default 2000).\n"
                 "       lpi run SCENE [options]   integrate one scene; lpi run --help for the options\n"
                 "       lpi stress [--quick] [FILTER]\n"
                 "           stiff and extreme cases against every applicable method: bounded,\n"
                 "           energy error, Casimir drift and status per case, step and method\n"
                 "       lpi --version | --help\n"
                 "scenes:\n");
    for (const Scene &s : builtin_scenes())
        std::fprintf(to, "  %-14s %s%s\n", s.name.c_str(), s.description.c_str(),
                     s.in_default_report ? "" : " (not in the default report)");
}

int report_command(int argc, char **argv) {
    ReportOptions options;
    SceneOptions scene_options;
    std::vector<std::string> names;
    for (int a = 0; a < argc; ++a) {
        if (std::strcmp(argv[a], "--out") == 0 && a + 1 < argc) {
            options.out_dir = argv[++a];
        } else if (std::strcmp(argv[a], "--N") == 0 && a + 1 < argc) {
            scene_options.sine_euler_n = std::atoi(argv[++a]);
        } else if (std::strcmp(argv[a], "--T") == 0 && a + 1 < argc) {
            scene_options.long_run_time = std::strtod(argv[++a], nullptr);
        } else if (std::strcmp(argv[a], "--help") == 0) {
            print_usage(stdout);
            return 0;
        } else if (argv[a][0] == '-') {
            std::fprintf(stderr, "lpi report: unknown option '%s'\n", argv[a]);
            return 2;
        } else {
            names.push_back(argv[a]);
        }
    }
    const std::vector<Scene> all = builtin_scenes(scene_options);
    std::vector<const Scene *> chosen;
    for (const std::string &name : names) {
        auto it = std::find_if(all.begin(), all.end(), [&](const Scene &s) { return s.name == name; });
        if (it == all.end()) {
            std::fprintf(stderr, "lpi report: unknown scene '%s' (lpi --help lists them)\n", name.c_str());
            return 2;
        }
        chosen.push_back(&*it);
    }
    if (chosen.empty())
        for (const Scene &s : all)
            if (s.in_default_report) chosen.push_back(&s);
    std::printf("liepoisson %s: error against CPU time, one core, measured in this run\n",
                lpi_version_string());
    for (const Scene *s : chosen) run_report(*s, options);
    std::printf("\nCSV and PNG files are in %s/\n", options.out_dir.c_str());
    return 0;
}

}  // namespace

int main(int argc, char **argv) {
    if (argc < 2) {
        print_usage(stderr);
        return 2;
    }
    const std::string command = argv[1];
    if (command == "--help" || command == "-h" || command == "help") {
        print_usage(stdout);
        return 0;
    }
    if (command == "--version") {
        std::printf("lpi (liepoisson) %s\n", lpi_version_string());
        return 0;
    }
    if (command == "report") return report_command(argc - 2, argv + 2);
    if (command == "run") return run_command(argc - 2, argv + 2);
    if (command == "stress") return stress_command(argc - 2, argv + 2);
    std::fprintf(stderr, "lpi: unknown command '%s'\n", command.c_str());
    print_usage(stderr);
    return 2;
}
