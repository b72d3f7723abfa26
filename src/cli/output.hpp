// Every file lpi writes (CSV, data, gnuplot scripts and images) goes through
// the library's own writer, src/core/files.* (compiled into lpi as well: the
// shared library does not export it): a temporary file
// beside the target, fsync, rename; or, for what lpi run grows with each
// checkpoint, FileGrowth in place. A failure keeps the old file and says
// why; the permission bits of a file replaced are kept, a new one gets the
// umask's; a symbolic link is followed and kept; a directory, FIFO or device
// at the target is refused, not replaced. Files are read the same way, as
// regular files only (a FIFO is refused, not waited on).
#pragma once

#include <string>

#include "../core/error.hpp"
#include "../core/files.hpp"

namespace lpi_cli {

using lpi::FileGrowth;
using lpi::FileIdentity;
using lpi::FileReplacement;
using lpi::RegularFileReader;

// Runs `write` (which throws lpi::Error or std::exception with a message
// naming the file and the reason): "" when it succeeded, else the message.
template <class Write>
std::string failure_of(Write &&write) {
    try {
        write();
        return "";
    } catch (const lpi::Error &e) {
        return e.what();
    }
}

// Replaces the file at `path` with `text`: "" or why not ("cannot save
// 'PATH': REASON").
inline std::string write_output(const std::string &path, const std::string &text) {
    return failure_of([&] {
        lpi::write_file_atomically(path, reinterpret_cast<const unsigned char *>(text.data()), text.size());
    });
}

// A file that only ever gains bytes at its end (a CSV's rows): grown in place
// by `tail` where it is the file lpi left (`written`, FileGrowth), else
// replaced whole by `whole()`; `written` then describes it. "" or why not
// (the file then keeps its old contents).
template <class Whole>
std::string grow_output(const std::string &path, FileIdentity &written, const std::string &tail, Whole &&whole) {
    return failure_of([&] {
        FileGrowth growth(path, written);
        if (growth.possible()) {
            growth.append(reinterpret_cast<const unsigned char *>(tail.data()), tail.size());
            written = growth.commit();
            return;
        }
        const std::string text = whole();
        written = lpi::write_file_atomically(path, reinterpret_cast<const unsigned char *>(text.data()), text.size());
    });
}

// Whether `path` could be replaced (its directory takes a new file, and it is
// no directory, FIFO or device): "" or why not. Asked before the work, so
// that a command whose output cannot be written fails at once.
inline std::string output_problem(const std::string &path) {
    return failure_of([&] { FileReplacement probe(path); });
}

// The whole of the regular file at `path` into `text`: "" or why not (a
// missing file: "cannot open 'PATH': No such file or directory").
inline std::string read_input(const std::string &path, std::string &text) {
    return failure_of([&] { text = RegularFileReader(path).read_rest(); });
}

}  // namespace lpi_cli
