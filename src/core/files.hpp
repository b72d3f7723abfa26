// Files the library writes and reads (checkpoints, FFTW wisdom): written
// atomically, read only when they are regular files, so that no call can
// hang on a FIFO, replace a device, or leave a partial file behind. Also the
// in-place growth lpi run uses for the files each checkpoint extends. Each
// object holds thread cancellation off while it lives (cancellation.hpp).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "cancellation.hpp"

namespace lpi {

// The reason an errno value names ("No such file or directory").
std::string io_reason(int error);

// What a writer knows of a file it wrote, so that it grows that file in place
// later only if it is still the same file, as it left it: device and inode
// (not moved or replaced), size and modification time (not written since).
struct FileIdentity {
    bool known = false;
    unsigned long long device = 0, inode = 0, size = 0;
    long long modified_s = 0, modified_ns = 0;
    bool operator==(const FileIdentity &o) const {
        return known && o.known && device == o.device && inode == o.inode && size == o.size &&
               modified_s == o.modified_s && modified_ns == o.modified_ns;
    }
};

// Atomic write: a temporary file under a short name of its own in the
// target's directory, fsync, rename over the target, fsync of the directory.
// The target is path, or the file a symbolic link at path names (the link
// is kept); an existing target keeps its permission bits. LPI_ERR_IO (naming
// path, with the reason) when the target is a directory, a device, a FIFO or
// a link to nothing, or on any failure (a write past RLIMIT_FSIZE too: EFBIG,
// never the SIGXFSZ that would end the process); path then keeps its old
// contents and no temporary file is left behind.
// Returns what the file written is (FileIdentity).
FileIdentity write_file_atomically(const std::string &path, const unsigned char *bytes, std::size_t size);

// The steps of write_file_atomically, for a writer that fills the temporary
// file itself, by write() or by its name (gnuplot), or that replaces
// several files together (sync() each, then commit() each). The constructor
// checks the target and creates the temporary, empty, beside it; commit()
// puts it in place; the destructor removes a temporary not committed, so a
// failure anywhere leaves the old file. Every failure is LPI_ERR_IO with the
// messages of write_file_atomically.
class FileReplacement {
public:
    explicit FileReplacement(const std::string &path);
    ~FileReplacement();
    FileReplacement(const FileReplacement &) = delete;
    FileReplacement &operator=(const FileReplacement &) = delete;

    const std::string &path() const { return path_; }
    // The temporary file, for a writer that opens it by name (and truncates
    // it or writes it whole: sync() gives it its permissions).
    const std::string &temporary() const { return temp_; }
    // Appends to the temporary file.
    void write(const unsigned char *bytes, std::size_t size);
    // Closes this object's descriptor of the temporary (a writer by name
    // needs none, and many files may then be prepared at once).
    void close_descriptor();
    // Gives the temporary the old file's permission bits and flushes it to disk.
    void sync();
    // sync() when not done yet, then the rename over the target. Returns
    // what the file in place is.
    FileIdentity commit();

private:
    [[noreturn]] void abandon(const std::string &what, int error);

    CancellationHeldOff held_off_;  // first: from the constructor through the destructor
    std::string path_, target_, dir_, temp_;
    int fd_ = -1;
    bool exists_ = false;
    unsigned permissions_ = 0;
    bool synced_ = false, committed_ = false;
    FileIdentity identity_;
};

// A file its writer grows in place instead of replacing it whole (a record
// that only ever gains rows: a whole rewrite at each of n saves costs n^2):
// bytes appended at its end, and a few overwritten within it (a header that
// states the length), then flushed. Only the file `known` names, unchanged
// since (FileIdentity); otherwise possible() is false, nothing is touched,
// and the writer replaces the file whole. Until commit(), a failure, or the
// destructor, puts the old contents back: the file is cut to its old size
// and the bytes overwritten are restored, so a failed growth leaves the old
// file, as a failed replacement does. Only a kill can leave more: the old
// contents and, after them, bytes they do not account for (a reader of the
// file must take the old contents and leave the rest; the header is written
// last). Failures are LPI_ERR_IO with write_file_atomically's messages; a
// growth past RLIMIT_FSIZE is refused before anything is written (EFBIG).
class FileGrowth {
public:
    FileGrowth(const std::string &path, const FileIdentity &known);
    ~FileGrowth();
    FileGrowth(const FileGrowth &) = delete;
    FileGrowth &operator=(const FileGrowth &) = delete;

    bool possible() const { return fd_ >= 0; }
    // The file's size when it was opened (where the appended bytes start).
    unsigned long long old_size() const { return old_size_; }
    // Appends to the file (after what earlier calls appended).
    void append(const unsigned char *bytes, std::size_t size);
    // Overwrites bytes within the old contents.
    void overwrite(unsigned long long offset, const unsigned char *bytes, std::size_t size);
    // Flushes what is written to disk.
    void sync();
    // sync() when not done yet; the file keeps what was written. Returns
    // what the file now is.
    FileIdentity commit();

private:
    [[noreturn]] void abandon(const std::string &what, int error);
    void restore();

    CancellationHeldOff held_off_;  // first: from the constructor through the destructor
    std::string path_;
    int fd_ = -1;
    unsigned long long old_size_ = 0, end_ = 0;
    struct Overwritten {
        unsigned long long offset;
        std::string old_bytes;
    };
    std::vector<Overwritten> overwritten_;
    bool synced_ = true;  // nothing written yet
};

// A file opened for reading that is known to be a regular file (opened
// without blocking, so a FIFO given by mistake is refused, not waited on):
// LPI_ERR_IO naming path when it cannot be opened, is a directory or is no
// regular file. Closed on destruction.
class RegularFileReader {
public:
    explicit RegularFileReader(const std::string &path);
    ~RegularFileReader();
    RegularFileReader(const RegularFileReader &) = delete;
    RegularFileReader &operator=(const RegularFileReader &) = delete;

    std::size_t size() const { return size_; }
    // Reads up to n bytes; fewer only at the end of the file.
    std::size_t read(unsigned char *data, std::size_t n);
    // The rest of the file, read in whole chunks until it ends or more than
    // limit bytes are read (then the file is longer than limit: size() can
    // understate it, a file of /proc reports 0 and may never end).
    std::string read_rest(std::size_t limit = static_cast<std::size_t>(-1) - 1);

private:
    CancellationHeldOff held_off_;  // first: from the constructor through the destructor
    std::string path_;
    int fd_ = -1;
    std::size_t size_ = 0;
};

}  // namespace lpi
