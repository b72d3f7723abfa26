#include "checkpoint.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

#include "error.hpp"
#include "files.hpp"
#include "text.hpp"

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
    void put_doubles32(const std::vector<double> &v, const char *what) {
        // A count of 2^32 or more would be written modulo 2^32: a file that
        // saves but never loads (sine-Euler N >= 37838 with its own
        // Hamiltonian has 1 + 3 N^2 parameters).
        if (v.size() > std::numeric_limits<std::uint32_t>::max())
            fail(LPI_ERR_UNSUPPORTED, "cannot checkpoint " + std::to_string(v.size()) + " " + what +
                                          ": format version " + std::to_string(kCheckpointVersion) +
                                          " stores at most 2^32 - 1");
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
        // Every name this library writes is printable ASCII: a NUL or a
        // control byte would also end up inside error messages.
        for (unsigned char c : s)
            if (c < 0x20 || c > 0x7E)
                fail(LPI_ERR_FORMAT, std::string(what) + " holds the byte " + std::to_string(c) +
                                         " (names are printable ASCII)");
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

// Checks the header (the first head_size <= 24 bytes of a checkpoint of
// `size` bytes): magic, byte order, version, and the announced total size
// against the actual one.
void check_header(const unsigned char *head, std::size_t head_size, std::uint64_t size) {
    // In the order that gives the most useful message.
    const std::size_t magic_seen = head_size < sizeof kMagic ? head_size : sizeof kMagic;
    if (magic_seen > 0 && std::memcmp(head, kMagic, magic_seen) != 0)
        fail(LPI_ERR_FORMAT, "not a liepoisson checkpoint (wrong magic bytes)");
    if (head_size < kHeaderSize || size < kHeaderSize + kChecksumSize)
        fail(LPI_ERR_FORMAT, "truncated: " + std::to_string(size) +
                                 " bytes, shorter than a checkpoint header");
    const std::uint32_t order = load_u32(head + 8);
    if (order == kByteOrderSwapped)
        fail(LPI_ERR_FORMAT, "written on a machine of the other byte order (this build reads "
                             "checkpoints of its own byte order only)");
    if (order != kByteOrder) fail(LPI_ERR_FORMAT, "corrupted header (byte-order marker)");
    const std::uint32_t version = load_u32(head + 12);
    if (version > kCheckpointVersion)
        fail(LPI_ERR_FORMAT, "format version " + std::to_string(version) +
                                 " is newer than this library reads (up to " +
                                 std::to_string(kCheckpointVersion) + "); upgrade liepoisson");
    if (version == 0) fail(LPI_ERR_FORMAT, "corrupted header (format version 0)");
    const std::uint64_t total = load_u64(head + 16);
    if (total > size)
        fail(LPI_ERR_FORMAT, "truncated: " + std::to_string(size) + " of " +
                                 std::to_string(total) + " bytes");
    if (total < size)
        fail(LPI_ERR_FORMAT, std::to_string(size - total) + " unexpected bytes after the " +
                                 std::to_string(total) + "-byte checkpoint");
}

// The registered kind of that name, or nullptr.
const CheckpointKind *find_checkpoint_kind(const std::string &kind) {
    for (const CheckpointKind &k : checkpoint_kinds())
        if (kind == k.kind) return &k;
    return nullptr;
}

// A model may bring its parameters to one form (the sine-Euler Hamiltonian
// averages each lambda pair, zeroes the mean mode's terms, and stores Euler's
// as N alone). A checkpoint whose parameters are not in that form did not
// come from this library, and would save back to other bytes: refused.
void require_canonical_parameters(const std::string &kind, const std::vector<double> &stored,
                                  const std::vector<double> &rebuilt) {
    if (stored.size() != rebuilt.size())
        fail(LPI_ERR_FORMAT, "the " + std::to_string(stored.size()) + " parameters are not in the "
                                 "form this library writes: the " + kind + " system they describe "
                                 "saves " + std::to_string(rebuilt.size()));
    for (std::size_t i = 0; i < stored.size(); ++i)
        if (std::memcmp(&stored[i], &rebuilt[i], sizeof(double)) != 0)
            fail(LPI_ERR_FORMAT, "parameter " + std::to_string(i) + " is not in the form this "
                                 "library writes: the " + kind + " system it describes saves " +
                                 number_text(rebuilt[i], 17) + " there, not " +
                                 number_text(stored[i], 17));
}

// The model a checkpoint names, rebuilt from its parameters. The state
// length is checked first: a crafted file must not make the library
// allocate a model far larger than the file.
std::unique_ptr<Model> make_model_for_checkpoint(const std::string &kind,
                                                 const std::vector<double> &p,
                                                 std::size_t state_length) {
    const CheckpointKind *entry = find_checkpoint_kind(kind);
    if (!entry) fail(LPI_ERR_FORMAT, "unknown system kind '" + kind + "'");
    if (entry->parameter_count != kCheckedByKind && p.size() != entry->parameter_count)
        fail(LPI_ERR_FORMAT, "a " + kind + " system has " + std::to_string(entry->parameter_count) +
                                 " parameters, the checkpoint gives " + std::to_string(p.size()));
    try {
        const std::uint64_t expected = entry->state_size(p);
        if (state_length != expected)
            fail(LPI_ERR_FORMAT, "the state has " + std::to_string(state_length) + " values, a " +
                                     kind + " system of these parameters has " +
                                     std::to_string(expected));
        std::unique_ptr<Model> model = entry->build(p);
        require_canonical_parameters(kind, p, model->checkpoint_parameters());
        return model;
    } catch (const Error &e) {
        // Neither is a bad file: a build without FFTW cannot load sine-Euler, and
        // a system too large for this machine's memory may load on a larger one.
        if (e.status() == LPI_ERR_UNSUPPORTED || e.status() == LPI_ERR_FORMAT ||
            e.status() == LPI_ERR_NO_MEMORY)
            throw;
        fail(LPI_ERR_FORMAT, std::string("invalid ") + kind + " parameters: " + e.what());
    }
}

// The working state must be one the model's own operations produce, checked
// as strictly as the setters check what users give: the checksum proves
// that the bytes are those written, not that this library wrote them.
void check_working_state(const CheckpointKind &kind, const Model &model,
                         const std::vector<double> &state) {
    for (std::size_t i = 0; i < state.size(); ++i)
        if (!std::isfinite(state[i]))
            fail(LPI_ERR_FORMAT, "working state entry " + std::to_string(i) + " is not finite");
    if (!kind.check_state) return;
    try {
        kind.check_state(model, state.data());
    } catch (const Error &e) {
        fail(LPI_ERR_FORMAT, std::string("the stored state: ") + e.what());
    }
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
    // What is saved must load: a kind without a restore is refused here.
    if (!find_checkpoint_kind(model.kind()))
        fail(LPI_ERR_UNSUPPORTED, std::string("a ") + model.kind() + " system cannot be "
                                  "checkpointed: this library cannot rebuild its kind");
    // A model spread over processes stores its whole state, as one process
    // holding it would: the file loads either way.
    const std::vector<double> state = model.whole_state(system.working_state().data());
    // Written (it allocates) with one outcome on every process of a spread
    // model: one short of memory leaves none waiting in the next collective.
    std::vector<unsigned char> bytes;
    model.agree_on_every_process([&] {
        Writer w;
        w.bytes().assign(kMagic, kMagic + sizeof kMagic);
        w.put(kByteOrder);
        w.put(kCheckpointVersion);
        w.put(std::uint64_t{0});  // total size, filled in below
        w.put_string(model.kind());
        w.put_doubles32(parameters, "parameters");
        w.put_string(model.split());
        w.put_string(system.method().name);
        w.put_doubles32(system.method().gammas, "composition weights");
        w.put(system.implicit_settings().tolerance);
        w.put(static_cast<std::int32_t>(system.implicit_settings().max_iterations));
        w.put(system.time());
        w.put(system.time_carry());
        w.put(static_cast<std::uint64_t>(state.size()));
        for (double x : state) w.put(x);
        const std::uint64_t total = w.bytes().size() + kChecksumSize;
        std::memcpy(w.bytes().data() + 16, &total, sizeof total);
        w.put(crc32(w.bytes().data(), w.bytes().size()));
        bytes.swap(w.bytes());
    });
    return bytes;
}

Checkpoint decode_checkpoint(const unsigned char *data, std::size_t size) {
    check_header(data, size, size);
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
    if (load_u32(data + 12) >= 2) cp.time_carry = r.get<double>("time carry");
    cp.state = r.get_doubles(r.get<std::uint64_t>("state length"), "state");
    if (r.left() != 0)
        fail(LPI_ERR_FORMAT, std::to_string(r.left()) + " unread bytes at the end of the payload");

    cp.model = make_model_for_checkpoint(kind, parameters, cp.state.size());
    const CheckpointKind &entry = *find_checkpoint_kind(kind);
    try {
        cp.model->set_split(split);
    } catch (const Error &e) {
        fail(LPI_ERR_FORMAT, e.what());
    }
    if (cp.state.size() != cp.model->state_size())
        fail(LPI_ERR_FORMAT, "the state has " + std::to_string(cp.state.size()) + " values, a " +
                                 kind + " system of these parameters has " +
                                 std::to_string(cp.model->state_size()));
    if (!std::isfinite(cp.time)) fail(LPI_ERR_FORMAT, "the time is not finite");
    // The carry a save writes is below half a unit of the time's last place.
    if (!std::isfinite(cp.time_carry) || cp.time + cp.time_carry != cp.time)
        fail(LPI_ERR_FORMAT, "the time's carry " + number_text(cp.time_carry) +
                                 " is not below half a unit in the last place of the time");
    check_working_state(entry, *cp.model, cp.state);
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
        system.restore_working_state(cp.state, cp.time, cp.time_carry);
    } catch (const MethodNotApplicable &e) {
        // A method that can never run on this system: no save writes that.
        fail(LPI_ERR_FORMAT, e.what());
    } catch (const Error &e) {
        // Not a bad file: a method this build or this layout cannot run (a
        // baseline on a system spread over processes, a matrix baseline
        // without LAPACK), or no memory.
        if (e.status() == LPI_ERR_NO_MEMORY || e.status() == LPI_ERR_UNSUPPORTED) throw;
        fail(LPI_ERR_FORMAT, e.what());
    }
    // An alias ("strang") is resolved on load but never written.
    if (system.method().name != cp.method)
        fail(LPI_ERR_FORMAT, "method '" + cp.method + "' is stored under its name '" +
                                 system.method().name + "', not an alias");
    // Bit-for-bit continuation needs the very same weights.
    const std::vector<double> &gammas = system.method().gammas;
    if (gammas.size() != cp.gammas.size() ||
        (!gammas.empty() &&
         std::memcmp(gammas.data(), cp.gammas.data(), gammas.size() * sizeof(double)) != 0))
        fail(LPI_ERR_FORMAT, "method '" + cp.method + "' has other weights in this build than "
                             "in the checkpoint; resuming would not continue the same trajectory");
}

std::vector<unsigned char> read_checkpoint_file(const std::string &path) {
    RegularFileReader file(path);
    // The header first, checked against the file's size: a foreign or lying
    // file costs 24 bytes of reading, never an allocation of its size.
    unsigned char head[kHeaderSize];
    const std::size_t head_size = file.read(head, sizeof head);
    check_header(head, head_size, file.size());
    std::vector<unsigned char> bytes(file.size());
    std::memcpy(bytes.data(), head, kHeaderSize);
    const std::size_t rest = bytes.size() - kHeaderSize;
    if (file.read(bytes.data() + kHeaderSize, rest) != rest)
        fail(LPI_ERR_FORMAT, "truncated while it was read (the file shrank)");
    return bytes;
}

}  // namespace lpi
