#include "plots.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <memory>

#include "output.hpp"
#include "run_watch.hpp"

extern char **environ;

namespace lpi_cli {

// Index of a registered method, -1 if none has that name.
int method_index(const std::string &method) {
    for (int i = 0; i < lpi_method_count(); ++i)
        if (method == lpi_method_name(i)) return i;
    return -1;
}

bool is_poisson(const std::string &method) { return lpi_method_is_poisson(method_index(method)) == 1; }

// The PATH lookup execvp makes, without a shell.
bool have_gnuplot() {
    const char *path = std::getenv("PATH");
    const std::string dirs = path ? path : "/usr/bin:/bin";
    for (std::size_t from = 0;;) {
        const std::size_t colon = dirs.find(':', from);
        const std::string dir = dirs.substr(from, colon - from);
        const std::string file = (dir.empty() ? "." : dir) + "/gnuplot";
        struct stat st;
        if (stat(file.c_str(), &st) == 0 && S_ISREG(st.st_mode) && access(file.c_str(), X_OK) == 0) return true;
        if (colon == std::string::npos) return false;
        from = colon + 1;
    }
}

namespace {

// Runs `gnuplot SCRIPT` in `dir`: no shell, so no name is ever parsed as a
// command; its output discarded, what it says on standard error kept for the
// message of a failure. "" when it succeeded, else why not. A SIGINT or
// SIGTERM that lpi run catches (interrupted_by) ends gnuplot: it is looked
// for at least every 0.1 s, so a signal that came just before a blocking
// read is not missed.
std::string run_gnuplot(const std::string &dir, const std::string &script) {
    int pipe_fds[2];
    if (pipe2(pipe_fds, O_CLOEXEC) != 0) return std::string("cannot run gnuplot: ") + std::strerror(errno);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], 2);
    posix_spawn_file_actions_addchdir_np(&actions, dir.c_str());
    std::string program = "gnuplot", argument = script;
    char *argv[] = {&program[0], &argument[0], nullptr};
    pid_t pid = 0;
    const int spawned = posix_spawnp(&pid, "gnuplot", &actions, nullptr, argv, environ);
    posix_spawn_file_actions_destroy(&actions);
    close(pipe_fds[1]);
    std::string said;
    if (spawned == 0) {
        char chunk[4096];
        bool ended = false;
        for (;;) {
            if (interrupted_by && !ended) kill(pid, SIGTERM), ended = true;
            pollfd ready{pipe_fds[0], POLLIN, 0};
            const int polled = poll(&ready, 1, 100);
            if (polled == 0 || (polled < 0 && errno == EINTR)) continue;
            const ssize_t n = polled < 0 ? -1 : read(pipe_fds[0], chunk, sizeof chunk);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) break;
            said.append(chunk, static_cast<std::size_t>(n));
        }
    }
    close(pipe_fds[0]);
    if (spawned != 0) return std::string("cannot run gnuplot: ") + std::strerror(spawned);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return "";
    while (!said.empty() && (said.back() == '\n' || said.back() == ' ')) said.pop_back();
    while (!said.empty() && said.front() == '\n') said.erase(0, 1);
    if (WIFSIGNALED(status)) return "gnuplot was killed by signal " + std::to_string(WTERMSIG(status));
    return said.empty() ? "gnuplot exited with status " + std::to_string(WEXITSTATUS(status)) : said;
}

// Replaces every `from` in `text` by `to`.
void replace_all(std::string &text, const std::string &from, const std::string &to) {
    for (std::size_t at = 0; (at = text.find(from, at)) != std::string::npos; at += to.size())
        text.replace(at, from.size(), to);
}

// A name as a gnuplot string ('' inside single quotes is one quote); a
// control character (a line break would end the command) is refused.
bool gnuplot_string(const std::string &name, std::string &quoted) {
    quoted = "'";
    for (char c : name) {
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) return false;
        quoted += c == '\'' ? std::string("''") : std::string(1, c);
    }
    quoted += "'";
    return true;
}

// What is wrong with an image gnuplot drew into `path` (`image` its name,
// which says its format), or "": gnuplot exits 0 also when it could not
// write the file (a full disk), so the image itself must be whole. A PNG
// ends with its IEND chunk, an SVG with </svg> (and white space).
std::string unfinished(const std::string &path, const std::string &image) {
    std::string bytes;
    const std::string unreadable = read_input(path, bytes);
    if (!unreadable.empty()) return unreadable;
    if (bytes.empty()) return "it is empty";
    auto ends_with = [](const std::string &text, const std::string &end) {
        return text.size() >= end.size() && text.compare(text.size() - end.size(), end.size(), end) == 0;
    };
    if (ends_with(image, ".png")) {
        if (bytes.compare(0, 8, std::string("\x89PNG\r\n\x1a\n", 8)) != 0) return "it is no PNG";
        if (!ends_with(bytes, std::string("\0\0\0\0IEND\xae\x42\x60\x82", 12)))
            return "the PNG is cut short (no IEND chunk at its end)";
    } else if (ends_with(image, ".svg")) {
        const std::size_t last = bytes.find_last_not_of(" \t\r\n");
        if (last == std::string::npos || !ends_with(bytes.substr(0, last + 1), "</svg>"))
            return "the SVG is cut short (no </svg> at its end)";
    }
    return "";
}

// An image's and a data file's mark in a script's text until draw() names it.
std::string mark(std::size_t i) { return "\x01" + std::to_string(i) + "\x01"; }
std::string data_mark(std::size_t i) { return "\x02" + std::to_string(i) + "\x02"; }

// The files' contents into temporaries beside them, each closed, none in place.
std::vector<std::unique_ptr<FileReplacement>> prepared(const std::string &dir,
                                                       const std::vector<std::pair<std::string, std::string>> &files) {
    std::vector<std::unique_ptr<FileReplacement>> out;
    for (const auto &[file, text] : files) {
        out.push_back(std::make_unique<FileReplacement>(dir + "/" + file));
        out.back()->write(reinterpret_cast<const unsigned char *>(text.data()), text.size());
        out.back()->close_descriptor();
    }
    return out;
}

}  // namespace

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

// A method's legend entry: its order and, for a splitting method, its stages
// (a step's cost in leapfrog steps), which is what tells the curves apart. A
// baseline's one "stage" says nothing of its cost, which the plot shows.
std::string method_label(const std::string &method) {
    const int i = method_index(method);
    const std::string order = method + " (order " + std::to_string(lpi_method_order(i));
    if (!is_poisson(method)) return order + ")";
    const int stages = lpi_method_stages(i);
    return order + ", " + std::to_string(stages) + (stages == 1 ? " stage)" : " stages)");
}

std::string csv_plot_preamble() {
    return "set datafile separator ','\nset grid xtics ytics mxtics mytics lw 0.5, lw 0.2\n"
           "set key below center horizontal maxcols 3 samplen 3\nset xlabel offset 0,0.5\nset bmargin 12\n"
           "set tics out nomirror\nset border 3\n";
}

std::string PlotScript::output(const std::string &image) {
    images_.push_back(image);
    return "set output " + mark(images_.size() - 1) + "\n";
}

void PlotScript::add_figure(const std::string &base, int width, int height, const std::string &commands) {
    text_ += format("set terminal pngcairo size %d,%d enhanced font ',11'\n", width, height) +
             output(base + ".png") + commands;
    text_ += format("set terminal svg size %d,%d enhanced font 'Helvetica,11' background '#ffffff'\n", width,
                    height) +
             output(base + ".svg") + commands + "set output\n";
}

std::string PlotScript::data(const std::string &file, std::string text) {
    data_.push_back({file, std::move(text)});
    return data_mark(data_.size() - 1);
}

std::string PlotScript::save_data() const {
    std::vector<std::pair<std::string, std::string>> files;
    for (const DataFile &d : data_) files.push_back({d.file, d.text});
    return failure_of([&] {
        for (auto &file : prepared(dir_, files)) file->commit();
    });
}

std::string PlotScript::with_names(const std::vector<std::string> &images,
                                   const std::vector<std::string> &data) const {
    std::string text = text_;
    for (std::size_t i = images.size(); i-- > 0;) replace_all(text, mark(i), images[i]);
    for (std::size_t i = data.size(); i-- > 0;) replace_all(text, data_mark(i), data[i]);
    return text;
}

std::string PlotScript::save_script() const {
    std::vector<std::string> quoted(images_.size()), quoted_data(data_.size());
    for (std::size_t i = 0; i < images_.size(); ++i)
        if (!gnuplot_string(images_[i], quoted[i])) return "cannot name " + dir_ + "/" + images_[i];
    for (std::size_t i = 0; i < data_.size(); ++i)
        if (!gnuplot_string(data_[i].file, quoted_data[i])) return "cannot name " + dir_ + "/" + data_[i].file;
    const std::vector<std::pair<std::string, std::string>> files = {{name_, with_names(quoted, quoted_data)}};
    return failure_of([&] {
        for (auto &file : prepared(dir_, files)) file->commit();
    });
}

std::string PlotScript::draw() const {
    const std::string script = dir_ + "/" + name_;
    std::vector<std::string> quoted(images_.size()), quoted_data(data_.size());
    for (std::size_t i = 0; i < images_.size(); ++i)
        if (!gnuplot_string(images_[i], quoted[i])) return "cannot draw " + dir_ + "/" + images_[i];
    for (std::size_t i = 0; i < data_.size(); ++i)
        if (!gnuplot_string(data_[i].file, quoted_data[i])) return "cannot draw from " + dir_ + "/" + data_[i].file;
    // The data files and the script that names them, ready beside their
    // places; gnuplot runs a copy of the script that reads the data's and
    // draws each image into its temporary file: a temporary beside the
    // script, removed afterwards.
    std::vector<std::pair<std::string, std::string>> files;
    for (const DataFile &d : data_) files.push_back({d.file, d.text});
    files.push_back({name_, with_names(quoted, quoted_data)});
    std::vector<std::unique_ptr<FileReplacement>> written, drawn;
    std::unique_ptr<FileReplacement> run;
    std::vector<std::string> temporaries, data_temporaries;
    std::string why = failure_of([&] {
        written = prepared(dir_, files);
        for (const std::string &image : images_) {
            drawn.push_back(std::make_unique<FileReplacement>(dir_ + "/" + image));
            drawn.back()->close_descriptor();
            temporaries.push_back(drawn.back()->temporary());
        }
        run = std::make_unique<FileReplacement>(script);
    });
    if (!why.empty()) return why;
    // A temporary is in the directory, or beside the file a symbolic link
    // there names: as gnuplot sees it from the directory, its name or its path.
    auto seen_from_dir = [&](const std::string &path) {
        return path.compare(0, dir_.size() + 1, dir_ + "/") == 0 ? path.substr(dir_.size() + 1) : path;
    };
    for (std::size_t i = 0; i < temporaries.size(); ++i) {
        temporaries[i] = seen_from_dir(temporaries[i]);
        if (!gnuplot_string(temporaries[i], quoted[i])) return "cannot draw " + dir_ + "/" + images_[i];
    }
    for (std::size_t i = 0; i < data_.size(); ++i) {
        data_temporaries.push_back(seen_from_dir(written[i]->temporary()));
        if (!gnuplot_string(data_temporaries[i], quoted_data[i]))
            return "cannot draw from " + dir_ + "/" + data_[i].file;
    }
    const std::string text = with_names(quoted, quoted_data);
    why = failure_of([&] {
        run->write(reinterpret_cast<const unsigned char *>(text.data()), text.size());
        run->close_descriptor();
    });
    if (!why.empty()) return why;
    std::string said = run_gnuplot(dir_, seen_from_dir(run->temporary()));
    if (!said.empty()) {
        // Its messages name the files lpi names.
        replace_all(said, seen_from_dir(run->temporary()), name_);
        for (std::size_t i = 0; i < temporaries.size(); ++i) replace_all(said, temporaries[i], images_[i]);
        for (std::size_t i = 0; i < data_temporaries.size(); ++i)
            replace_all(said, data_temporaries[i], data_[i].file);
        return "gnuplot failed on " + script + ": " + said;
    }
    // Every image whole before any file is put in place: a failure keeps them all.
    for (std::size_t i = 0; i < drawn.size(); ++i) {
        const std::string wrong = unfinished(drawn[i]->temporary(), images_[i]);
        if (!wrong.empty())
            return "gnuplot did not draw " + dir_ + "/" + images_[i] + " (" + wrong +
                   "; a full disk?): the old files are kept";
    }
    return failure_of([&] {
        for (auto &file : written) file->sync();
        for (auto &image : drawn) image->sync();
        for (auto &file : written) file->commit();
        for (auto &image : drawn) image->commit();
    });
}

}  // namespace lpi_cli
