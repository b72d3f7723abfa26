// Atomic writes and checked reads (see the header).
#include "files.hpp"

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <new>
#include <system_error>

#include "error.hpp"
#include "text.hpp"

namespace lpi {

std::string io_reason(int error) { return std::generic_category().message(error); }

namespace {

// The directory part of path, for the temporary file and the final fsync.
std::string directory_of(const std::string &path) {
    const std::size_t slash = path.find_last_of('/');
    return slash == std::string::npos ? "." : slash == 0 ? "/" : path.substr(0, slash);
}

// A new, empty file in `dir` under a short name of its own (".lpi-" and 12
// characters): legal wherever the target's name is, even a name of NAME_MAX
// bytes to which no suffix could be added. O_EXCL with `mode`, which the
// umask restricts further.
int create_temporary(const std::string &dir, std::string &temp, mode_t mode) {
    static std::atomic<unsigned> counter{0};
    for (int attempt = 0;; ++attempt) {
        char name[32];
        std::snprintf(name, sizeof name, ".lpi-%06x%06x", static_cast<unsigned>(::getpid()) & 0xFFFFFFu,
                      counter.fetch_add(1) & 0xFFFFFFu);
        temp = dir + "/" + name;
        const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, mode);
        if (fd >= 0 || errno != EEXIST || attempt == 100) return fd;
    }
}

// What a save replaces: path itself, or the file a symbolic link there
// names, so that the link survives (a rename over path would replace the
// link with a file and leave its target stale). Only a regular file is
// replaced: a rename over a device or a FIFO would destroy it.
struct SaveTarget {
    std::string path;
    bool exists = false;
    mode_t permissions = 0;
};

SaveTarget save_target(const std::string &path) {
    auto refuse = [&path](const std::string &why) { fail(LPI_ERR_IO, "cannot save " + quoted(path) + ": " + why); };
    SaveTarget target{path};
    struct stat st;
    if (::stat(path.c_str(), &st) != 0) {
        const int error = errno;
        struct stat link;
        if (error == ENOENT && ::lstat(path.c_str(), &link) == 0 && S_ISLNK(link.st_mode))
            refuse("it is a symbolic link to a missing file");
        if (error != ENOENT) refuse(io_reason(error));
        return target;  // a new file
    }
    if (S_ISDIR(st.st_mode)) refuse("it is a directory");
    if (!S_ISREG(st.st_mode)) refuse("it is not a regular file (a device, a FIFO or a socket)");
    target.exists = true;
    target.permissions = st.st_mode & 07777;
    struct stat link;
    if (::lstat(path.c_str(), &link) == 0 && S_ISLNK(link.st_mode)) {
        char *resolved = ::realpath(path.c_str(), nullptr);
        if (!resolved) refuse("cannot resolve the symbolic link: " + io_reason(errno));
        target.path = resolved;
        std::free(resolved);
    }
    return target;
}

// Whether `size` more bytes appended to fd stay within RLIMIT_FSIZE. A write
// past it raises SIGXFSZ, whose default action ends the process and leaves
// the temporary file behind: such a write is refused beforehand, with the
// EFBIG the write gives where the signal is ignored.
bool within_file_size_limit(int fd, std::size_t size) {
    struct rlimit limit;
    if (::getrlimit(RLIMIT_FSIZE, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return true;
    struct stat st;
    if (::fstat(fd, &st) != 0) return true;  // the write itself says what is wrong
    const auto end = static_cast<std::uint64_t>(st.st_size);
    return end <= limit.rlim_cur && size <= limit.rlim_cur - end;
}

FileIdentity identity_of(int fd) {
    FileIdentity id;
    struct stat st;
    if (::fstat(fd, &st) != 0) return id;
    id.known = true;
    id.device = static_cast<unsigned long long>(st.st_dev);
    id.inode = static_cast<unsigned long long>(st.st_ino);
    id.size = static_cast<unsigned long long>(st.st_size);
    id.modified_s = static_cast<long long>(st.st_mtim.tv_sec);
    id.modified_ns = static_cast<long long>(st.st_mtim.tv_nsec);
    return id;
}

// Writes all of bytes at offset (pwrite until done); false with errno set.
bool write_all_at(int fd, const unsigned char *bytes, std::size_t size, unsigned long long offset) {
    std::size_t done = 0;
    while (done < size) {
        const ssize_t n = ::pwrite(fd, bytes + done, size - done, static_cast<off_t>(offset + done));
        if (n < 0) {
            if (errno == EINTR) continue;
            return false;
        }
        if (n == 0) {  // nothing written and no error: no room (as coreutils' full_write reads it)
            errno = ENOSPC;
            return false;
        }
        done += static_cast<std::size_t>(n);
    }
    return true;
}

}  // namespace

FileReplacement::FileReplacement(const std::string &path) : path_(path) {
    const SaveTarget target = save_target(path);
    target_ = target.path;
    exists_ = target.exists;
    permissions_ = target.permissions;
    dir_ = directory_of(target_);
    // Never more readable than the file it replaces while the new contents
    // are written (a reader who opens it then keeps reading after sync()'s
    // chmod): the old file's bits for group and others, the owner's read and
    // write for writers by name; a new file takes 0666, as open(2) gives.
    const mode_t mode = exists_ ? (static_cast<mode_t>(permissions_) & 0066) | 0600 : 0666;
    fd_ = create_temporary(dir_, temp_, mode);
    if (fd_ < 0)
        fail(LPI_ERR_IO, "cannot save " + quoted(path) + ": cannot create a file in " + quoted(dir_) + ": " + io_reason(errno));
}

FileReplacement::~FileReplacement() {
    if (fd_ >= 0) ::close(fd_);
    if (!committed_) ::unlink(temp_.c_str());
}

// Until the rename, the target is untouched: a failure leaves the old file.
void FileReplacement::abandon(const std::string &what, int error) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    ::unlink(temp_.c_str());
    committed_ = true;  // nothing left to remove
    fail(LPI_ERR_IO, "cannot save " + quoted(path_) + ": " + what + ": " + io_reason(error));
}

void FileReplacement::write(const unsigned char *bytes, std::size_t size) {
    if (fd_ < 0) fd_ = ::open(temp_.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
    if (fd_ < 0) abandon("cannot write " + quoted(temp_), errno);
    if (size > 0 && !within_file_size_limit(fd_, size)) abandon("cannot write " + quoted(temp_), EFBIG);
    std::size_t done = 0;
    while (done < size) {
        const ssize_t n = ::write(fd_, bytes + done, size - done);
        if (n < 0) {
            if (errno == EINTR) continue;
            abandon("cannot write " + quoted(temp_), errno);
        }
        if (n == 0) abandon("cannot write " + quoted(temp_), ENOSPC);  // no progress: see write_all_at
        done += static_cast<std::size_t>(n);
    }
}

void FileReplacement::close_descriptor() {
    const int fd = fd_;
    fd_ = -1;
    if (fd >= 0 && ::close(fd) != 0) abandon("cannot close " + quoted(temp_), errno);
}

void FileReplacement::sync() {
    // Read-only suffices for fchmod and fsync, whatever the file's mode.
    if (fd_ < 0) fd_ = ::open(temp_.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0) abandon("cannot open " + quoted(temp_), errno);
    if (exists_ && ::fchmod(fd_, static_cast<mode_t>(permissions_)) != 0)
        abandon("cannot give " + quoted(temp_) + " the permissions of the old file", errno);
    if (::fsync(fd_) != 0) abandon("cannot flush " + quoted(temp_), errno);
    identity_ = identity_of(fd_);  // the rename keeps the inode and the times
    close_descriptor();
    synced_ = true;
}

FileIdentity FileReplacement::commit() {
    if (!synced_) sync();
    if (::rename(temp_.c_str(), target_.c_str()) != 0)
        abandon("cannot rename " + quoted(temp_) + " to " + (target_ == path_ ? "it" : quoted(target_)), errno);
    committed_ = true;
    // Make the rename itself durable. Best effort: the file is complete and in
    // place either way, and some file systems cannot sync a directory.
    const int dfd = ::open(dir_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd >= 0) {
        ::fsync(dfd);
        ::close(dfd);
    }
    return identity_;
}

FileIdentity write_file_atomically(const std::string &path, const unsigned char *bytes, std::size_t size) {
    FileReplacement file(path);
    file.write(bytes, size);
    return file.commit();
}

FileGrowth::FileGrowth(const std::string &path, const FileIdentity &known) : path_(path) {
    if (!known.known) return;
    // O_NONBLOCK: whatever is there now, opening it must not wait (a FIFO).
    const int fd = ::open(path.c_str(), O_RDWR | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) return;  // gone or not writable: the writer replaces it and says why
    const FileIdentity now = identity_of(fd);
    if (!(now == known)) {
        ::close(fd);
        return;
    }
    fd_ = fd;
    old_size_ = end_ = now.size;
}

FileGrowth::~FileGrowth() {
    if (fd_ < 0) return;
    restore();
    ::close(fd_);
}

// Best effort: what the file held before, whatever failed on the way here.
void FileGrowth::restore() {
    for (auto o = overwritten_.rbegin(); o != overwritten_.rend(); ++o)
        write_all_at(fd_, reinterpret_cast<const unsigned char *>(o->old_bytes.data()), o->old_bytes.size(),
                     o->offset);
    if (end_ != old_size_ || !overwritten_.empty()) {
        ::ftruncate(fd_, static_cast<off_t>(old_size_));
        ::fsync(fd_);
    }
    overwritten_.clear();
    end_ = old_size_;
}

void FileGrowth::abandon(const std::string &what, int error) {
    restore();
    ::close(fd_);
    fd_ = -1;
    fail(LPI_ERR_IO, "cannot save " + quoted(path_) + ": " + what + ": " + io_reason(error));
}

void FileGrowth::append(const unsigned char *bytes, std::size_t size) {
    if (size > 0 && !within_file_size_limit(fd_, size)) abandon("cannot write it", EFBIG);
    if (!write_all_at(fd_, bytes, size, end_)) {
        const int error = errno;
        end_ += size;  // whatever part was written is cut off again
        abandon("cannot write it", error);
    }
    end_ += size;
    synced_ = false;
}

void FileGrowth::overwrite(unsigned long long offset, const unsigned char *bytes, std::size_t size) {
    if (offset > old_size_ || size > old_size_ - offset) abandon("an overwrite past its old end", EINVAL);
    Overwritten old{offset, std::string(size, '\0')};
    std::size_t done = 0;
    while (done < size) {
        const ssize_t n = ::pread(fd_, &old.old_bytes[done], size - done, static_cast<off_t>(offset + done));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) abandon("cannot read it", n < 0 ? errno : EIO);
        done += static_cast<std::size_t>(n);
    }
    overwritten_.push_back(std::move(old));
    if (!write_all_at(fd_, bytes, size, offset)) abandon("cannot write it", errno);
    synced_ = false;
}

void FileGrowth::sync() {
    if (::fsync(fd_) != 0) abandon("cannot flush it", errno);
    synced_ = true;
}

FileIdentity FileGrowth::commit() {
    if (!synced_) sync();
    const FileIdentity now = identity_of(fd_);
    overwritten_.clear();
    old_size_ = end_;
    ::close(fd_);
    fd_ = -1;
    return now;
}

RegularFileReader::RegularFileReader(const std::string &path) : path_(path) {
    // O_NONBLOCK: a FIFO given by mistake must not hang the call.
    fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd_ < 0) fail(LPI_ERR_IO, "cannot open " + quoted(path) + ": " + io_reason(errno));
    struct stat st;
    const bool known = ::fstat(fd_, &st) == 0;
    const int error = errno;
    if (!known || !S_ISREG(st.st_mode)) {
        ::close(fd_);
        if (!known) fail(LPI_ERR_IO, "cannot stat " + quoted(path) + ": " + io_reason(error));
        if (S_ISDIR(st.st_mode)) fail(LPI_ERR_IO, quoted(path) + " is a directory");
        fail(LPI_ERR_IO, quoted(path) + " is not a regular file");
    }
    if (static_cast<std::uint64_t>(st.st_size) > std::numeric_limits<std::size_t>::max()) {
        ::close(fd_);
        throw std::bad_alloc();
    }
    size_ = static_cast<std::size_t>(st.st_size);
}

RegularFileReader::~RegularFileReader() { ::close(fd_); }

std::size_t RegularFileReader::read(unsigned char *data, std::size_t n) {
    std::size_t done = 0;
    while (done < n) {
        const ssize_t got = ::read(fd_, data + done, n - done);
        if (got < 0) {
            if (errno == EINTR) continue;
            fail(LPI_ERR_IO, "cannot read " + quoted(path_) + ": " + io_reason(errno));
        }
        if (got == 0) break;
        done += static_cast<std::size_t>(got);
    }
    return done;
}

std::string RegularFileReader::read_rest(std::size_t limit) {
    std::string text;
    unsigned char chunk[65536];
    for (;;) {
        const std::size_t got = read(chunk, sizeof chunk);
        text.append(reinterpret_cast<const char *>(chunk), got);
        if (got < sizeof chunk || text.size() > limit) return text;
    }
}

}  // namespace lpi
