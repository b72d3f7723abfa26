#include "checkpoint.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>
#include <system_error>

#include "../models/models.hpp"
#include "../models/sine_euler.hpp"
#include "error.hpp"

namespace lpi {

static_assert(std::numeric_limits<double>::is_iec559, "checkpoints store IEEE 754 doubles");

namespace {

constexpr unsigned char kMagic[8] = {0x89, 'L', 'P', 'I', 0x0D, 0x0A, 0x1A, 0x0A};
constexpr std::uint32_t kByteOrder = 0x01020304u;
constexpr std::uint32_t kByteOrderSwapped = 0x04030201u;
constexpr std::size_t kHeaderSize = 24;  // magic, byte order, version, total size
constexpr std::size_t kChecksumSize = 4;
constexpr std::uint32_t kMaxName = 256;  // kind, split and method names

class Writer {
public:
    template <class T> void put(T value) {
        unsigned char raw[sizeof(T)];
        std::memcpy(raw, &value, sizeof(T));
        bytes_.insert(bytes_.end(), raw, raw + sizeof(T));
    }
    void put_string(const std::string &s) {
        put(static_cast<std::uint32_t>(s.size()));
        bytes_.insert(bytes_.end(), s.begin(), s.end());
    }
    void put_doubles32(const std::vector<double> &v) {
        put(static_cast<std::uint32_t>(v.size()));
        for (double x : v) put(x);
    }
    std::vector<unsigned char> &bytes() { return bytes_; }

private:
    std::vector<unsigned char> bytes_;
};

// Reads the payload; every read is bounds-checked (a file with a valid
// checksum can still have been crafted).
class Reader {
public:
    Reader(const unsigned char *data, std::size_t size) : p_(data), end_(data + size) {}
    std::size_t left() const { return static_cast<std::size_t>(end_ - p_); }
    template <class T> T get(const char *what) {
        need(sizeof(T), what);
        T value;
        std::memcpy(&value, p_, sizeof(T));
        p_ += sizeof(T);
        return value;
    }
    std::string get_string(const char *what) {
        const auto n = get<std::uint32_t>(what);
        if (n > kMaxName)
            fail(LPI_ERR_FORMAT, std::string(what) + " is " + std::to_string(n) +
                                     " bytes long (at most " + std::to_string(kMaxName) + ")");
        need(n, what);
        std::string s(reinterpret_cast<const char *>(p_), n);
        p_ += n;
        return s;
    }
    std::vector<double> get_doubles(std::uint64_t n, const char *what) {
        if (n > left() / sizeof(double)) need(SIZE_MAX, what);
        std::vector<double> v(static_cast<std::size_t>(n));
        for (double &x : v) x = get<double>(what);
        return v;
    }

private:
    void need(std::size_t n, const char *what) {
        if (n > left())
            fail(LPI_ERR_FORMAT, std::string("the payload ends inside the ") + what +
                                     " (inconsistent contents)");
    }
    const unsigned char *p_;
    const unsigned char *end_;
};

std::uint32_t load_u32(const unsigned char *p) {
    std::uint32_t v;
    std::memcpy(&v, p, sizeof v);
    return v;
}

std::uint64_t load_u64(const unsigned char *p) {
    std::uint64_t v;
    std::memcpy(&v, p, sizeof v);
    return v;
}

std::string io_reason(int error) { return std::generic_category().message(error); }

// The models a checkpoint can name, rebuilt from their parameters. The
// state length is checked first: a crafted file must not make the library
// allocate a model far larger than the file.
std::unique_ptr<Model> make_model_for_checkpoint(const std::string &kind,
                                                 const std::vector<double> &p,
                                                 std::size_t state_length) {
    auto expect_state = [&](double expected) {
        if (static_cast<double>(state_length) != expected)
            fail(LPI_ERR_FORMAT, "the state has " + std::to_string(state_length) + " values, a " +
                                     kind + " system of these parameters has " +
                                     std::to_string(static_cast<std::uint64_t>(expected)));
    };
    auto need = [&](std::size_t n) {
        if (p.size() != n)
            fail(LPI_ERR_FORMAT, "a " + kind + " system has " + std::to_string(n) +
                                     " parameters, the checkpoint gives " + std::to_string(p.size()));
    };
    try {
        if (kind == "rigid-body") {
            need(3);
            expect_state(6);
            return make_rigid_body(p[0], p[1], p[2]);
        }
        if (kind == "pendulum") {
            need(0);
            expect_state(6);
            return make_pendulum();
        }
        if (kind == "sine-euler") {
            need(1);
            if (!(p[0] >= 0 && p[0] <= std::numeric_limits<std::int32_t>::max()) ||
                p[0] != std::floor(p[0]))
                fail(LPI_ERR_FORMAT, "sine-euler N is not an integer");
            expect_state(2.0 * p[0] * p[0]);
            return make_sine_euler(static_cast<int>(p[0]));
        }
    } catch (const Error &e) {
        // A build without FFTW cannot load sine-Euler: that is not a bad file.
        if (e.status() == LPI_ERR_UNSUPPORTED || e.status() == LPI_ERR_FORMAT) throw;
        fail(LPI_ERR_FORMAT, std::string("invalid ") + kind + " parameters: " + e.what());
    }
    fail(LPI_ERR_FORMAT, "unknown system kind '" + kind + "'");
}

}  // namespace

std::uint32_t crc32(const unsigned char *data, std::size_t size) {
    static const std::array<std::uint32_t, 256> table = [] {
        std::array<std::uint32_t, 256> t{};
        for (std::uint32_t n = 0; n < 256; ++n) {
            std::uint32_t c = n;
            for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
            t[n] = c;
        }
        return t;
    }();
    std::uint32_t c = 0xFFFFFFFFu;
    for (std::size_t i = 0; i < size; ++i) c = table[(c ^ data[i]) & 0xFFu] ^ (c >> 8);
    return c ^ 0xFFFFFFFFu;
}

std::vector<unsigned char> encode_checkpoint(const System &system) {
    const Model &model = system.model();
    const std::vector<double> parameters = model.checkpoint_parameters();  // may refuse
    Writer w;
    w.bytes().assign(kMagic, kMagic + sizeof kMagic);
    w.put(kByteOrder);
    w.put(kCheckpointVersion);
    w.put(std::uint64_t{0});  // total size, filled in below
    w.put_string(model.kind());
    w.put_doubles32(parameters);
    w.put_string(model.split());
    w.put_string(system.method().name);
    w.put_doubles32(system.method().gammas);
    w.put(system.implicit_settings().tolerance);
    w.put(static_cast<std::int32_t>(system.implicit_settings().max_iterations));
    w.put(system.time());
    const std::vector<double> &state = system.working_state();
    w.put(static_cast<std::uint64_t>(state.size()));
    for (double x : state) w.put(x);

    std::vector<unsigned char> &bytes = w.bytes();
    const std::uint64_t total = bytes.size() + kChecksumSize;
    std::memcpy(bytes.data() + 16, &total, sizeof total);
    w.put(crc32(bytes.data(), bytes.size()));
    return std::move(bytes);
}

Checkpoint decode_checkpoint(const unsigned char *data, std::size_t size) {
    // The header, in the order that gives the most useful message.
    const std::size_t magic_seen = size < sizeof kMagic ? size : sizeof kMagic;
    if (magic_seen > 0 && std::memcmp(data, kMagic, magic_seen) != 0)
        fail(LPI_ERR_FORMAT, "not a liepoisson checkpoint (wrong magic bytes)");
    if (size < kHeaderSize + kChecksumSize)
        fail(LPI_ERR_FORMAT, "truncated: " + std::to_string(size) +
                                 " bytes, shorter than a checkpoint header");
    const std::uint32_t order = load_u32(data + 8);
    if (order == kByteOrderSwapped)
        fail(LPI_ERR_FORMAT, "written on a machine of the other byte order (this build reads "
                             "checkpoints of its own byte order only)");
    if (order != kByteOrder) fail(LPI_ERR_FORMAT, "corrupted header (byte-order marker)");
    const std::uint32_t version = load_u32(data + 12);
    if (version > kCheckpointVersion)
        fail(LPI_ERR_FORMAT, "format version " + std::to_string(version) +
                                 " is newer than this library reads (up to " +
                                 std::to_string(kCheckpointVersion) + "); upgrade liepoisson");
    if (version == 0) fail(LPI_ERR_FORMAT, "corrupted header (format version 0)");
    const std::uint64_t total = load_u64(data + 16);
    if (total > size)
        fail(LPI_ERR_FORMAT, "truncated: " + std::to_string(size) + " of " +
                                 std::to_string(total) + " bytes");
    if (total < size)
        fail(LPI_ERR_FORMAT, std::to_string(size - total) + " unexpected bytes after the " +
                                 std::to_string(total) + "-byte checkpoint");
    const std::size_t body = size - kChecksumSize;
    if (crc32(data, body) != load_u32(data + body))
        fail(LPI_ERR_FORMAT, "checksum mismatch: the checkpoint is corrupted");

    Reader r(data + kHeaderSize, body - kHeaderSize);
    Checkpoint cp;
    const std::string kind = r.get_string("system kind");
    const std::vector<double> parameters =
        r.get_doubles(r.get<std::uint32_t>("parameter count"), "parameters");
    const std::string split = r.get_string("split name");
    cp.method = r.get_string("method name");
    cp.gammas = r.get_doubles(r.get<std::uint32_t>("weight count"), "weights");
    cp.implicit.tolerance = r.get<double>("implicit tolerance");
    cp.implicit.max_iterations = r.get<std::int32_t>("implicit iteration limit");
    cp.time = r.get<double>("time");
    cp.state = r.get_doubles(r.get<std::uint64_t>("state length"), "state");
    if (r.left() != 0)
        fail(LPI_ERR_FORMAT, std::to_string(r.left()) + " unread bytes at the end of the payload");

    cp.model = make_model_for_checkpoint(kind, parameters, cp.state.size());
    try {
        cp.model->set_split(split);
    } catch (const Error &e) {
        fail(LPI_ERR_FORMAT, e.what());
    }
    if (cp.state.size() != cp.model->state_size())
        fail(LPI_ERR_FORMAT, "the state has " + std::to_string(cp.state.size()) + " values, a " +
                                 kind + " system of these parameters has " +
                                 std::to_string(cp.model->state_size()));
    return cp;
}

void restore_checkpoint(System &system, const Checkpoint &cp) {
    try {
        system.set_implicit_settings(cp.implicit);
        if (cp.method == "custom") {
            system.set_composition(cp.gammas.data(), cp.gammas.size());
        } else {
            system.set_method(cp.method);
        }
        system.restore_working_state(cp.state, cp.time);
    } catch (const Error &e) {
        if (e.status() == LPI_ERR_NO_MEMORY) throw;
        fail(LPI_ERR_FORMAT, e.what());
    }
    // Bit-for-bit continuation needs the very same weights.
    const std::vector<double> &gammas = system.method().gammas;
    if (gammas.size() != cp.gammas.size() ||
        (!gammas.empty() &&
         std::memcmp(gammas.data(), cp.gammas.data(), gammas.size() * sizeof(double)) != 0))
        fail(LPI_ERR_FORMAT, "method '" + cp.method + "' has other weights in this build than "
                             "in the checkpoint; resuming would not continue the same trajectory");
}

void write_file_atomically(const std::string &path, const std::vector<unsigned char> &bytes) {
    static std::atomic<unsigned> counter{0};
    const std::string temp = path + ".tmp." + std::to_string(::getpid()) + "." +
                             std::to_string(counter.fetch_add(1));
    const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0)
        fail(LPI_ERR_IO, "cannot create '" + temp + "': " + io_reason(errno));
    auto abandon = [&](const std::string &what, int error) {
        ::close(fd);
        ::unlink(temp.c_str());
        fail(LPI_ERR_IO, what + " '" + temp + "': " + io_reason(error));
    };
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0) {
            if (errno == EINTR) continue;
            abandon("cannot write", errno);
        }
        done += static_cast<std::size_t>(n);
    }
    if (::fsync(fd) != 0) abandon("cannot flush", errno);
    if (::close(fd) != 0) {
        const int error = errno;
        ::unlink(temp.c_str());
        fail(LPI_ERR_IO, "cannot close '" + temp + "': " + io_reason(error));
    }
    if (::rename(temp.c_str(), path.c_str()) != 0) {
        const int error = errno;
        ::unlink(temp.c_str());
        fail(LPI_ERR_IO, "cannot rename '" + temp + "' to '" + path + "': " + io_reason(error));
    }
    // Make the rename itself durable. Best effort: the file is complete and in
    // place either way, and some file systems cannot sync a directory.
    const std::size_t slash = path.find_last_of('/');
    const std::string dir = slash == std::string::npos ? "." : slash == 0 ? "/" : path.substr(0, slash);
    const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd >= 0) {
        ::fsync(dfd);
        ::close(dfd);
    }
}

std::vector<unsigned char> read_file(const std::string &path) {
    // O_NONBLOCK: a FIFO given by mistake must not hang the call.
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) fail(LPI_ERR_IO, "cannot open '" + path + "': " + io_reason(errno));
    struct stat st;
    if (::fstat(fd, &st) != 0) {
        const int error = errno;
        ::close(fd);
        fail(LPI_ERR_IO, "cannot stat '" + path + "': " + io_reason(error));
    }
    if (!S_ISREG(st.st_mode)) {
        ::close(fd);
        fail(LPI_ERR_IO, "'" + path + "' is not a regular file");
    }
    std::vector<unsigned char> bytes;
    bytes.reserve(static_cast<std::size_t>(st.st_size));
    unsigned char chunk[65536];
    for (;;) {
        const ssize_t n = ::read(fd, chunk, sizeof chunk);
        if (n < 0) {
            if (errno == EINTR) continue;
            const int error = errno;
            ::close(fd);
            fail(LPI_ERR_IO, "cannot read '" + path + "': " + io_reason(error));
        }
        if (n == 0) break;
        bytes.insert(bytes.end(), chunk, chunk + n);
    }
    ::close(fd);
    return bytes;
}

}  // namespace lpi
