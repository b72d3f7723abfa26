// The C ABI of checkpoints: a system saved to a file or a buffer and loaded
// back (format and validation in src/core/checkpoint.*).
#include <cstring>
#include <memory>
#include <vector>

#include "../core/cancellation.hpp"
#include "../core/checkpoint.hpp"
#include "../core/files.hpp"
#include "../core/text.hpp"
#include "handle.hpp"

using lpi::capi::Arguments;
using lpi::capi::guarded;
using lpi::capi::require;
using lpi::capi::require_path;
using lpi::capi::Text;

namespace {

// Bytes to load: a caller's buffer, or a file read into `owned`.
struct Bytes {
    const unsigned char *data = nullptr;
    std::size_t size = 0;
    std::vector<unsigned char> owned;
};

// A new handle from the bytes that read() gives; *out stays NULL on failure.
// A refused file's path leads the message (I/O errors name it already).
template <class Read>
int load(lpi_system **out, const char *function, const char *path, Read &&read) {
    if (out) *out = nullptr;
    return guarded(nullptr, function, [&] {
        require(out, "out");
        try {
            Bytes bytes;
            read(bytes);
            lpi::Checkpoint cp = lpi::decode_checkpoint(bytes.data, bytes.size);
            auto handle = std::make_unique<lpi_system>(std::move(cp.model));
            lpi::restore_checkpoint(handle->system, cp);
            *out = handle.release();
        } catch (const lpi::Error &e) {
            if (!path || (e.status() != LPI_ERR_FORMAT && e.status() != LPI_ERR_UNSUPPORTED)) throw;
            lpi::fail(e.status(), lpi::quoted(path) + ": " + e.what());
        }
    });
}

}  // namespace

extern "C" {

LPI_API int lpi_save(const lpi_system *sys, const char *path) {
    lpi::act_on_a_pending_cancel();
    return guarded(sys, "lpi_save", Arguments(Text{path}), [&] {
        require(sys, "system");
        require_path(path);
        const std::vector<unsigned char> bytes = lpi::encode_checkpoint(sys->system);
        // Written once when the system is spread over processes.
        sys->system.model().on_one_process([&] { lpi::write_file_atomically(path, bytes.data(), bytes.size()); });
    });
}

LPI_API int lpi_load(lpi_system **out, const char *path) {
    lpi::act_on_a_pending_cancel();
    return load(out, "lpi_load", path, [&](Bytes &bytes) {
        require_path(path);
        bytes.owned = lpi::read_checkpoint_file(path);
        bytes.data = bytes.owned.data();
        bytes.size = bytes.owned.size();
    });
}

LPI_API int lpi_save_buffer(const lpi_system *sys, void *buf, size_t capacity, size_t *size) {
    return guarded(sys, "lpi_save_buffer", Arguments(buf, capacity, size), [&] {
        require(sys, "system");
        require(size, "size");
        if (!buf && capacity > 0)
            lpi::fail(LPI_ERR_NULL, "buf is NULL with capacity " + std::to_string(capacity) +
                                        " (pass capacity 0 to query the size)");
        const std::vector<unsigned char> bytes = lpi::encode_checkpoint(sys->system);
        *size = bytes.size();
        if (!buf) return;  // size query
        if (capacity < bytes.size())
            lpi::fail(LPI_ERR_SIZE, "buffer of " + std::to_string(capacity) + " bytes is too small; " +
                                        std::to_string(bytes.size()) + " needed");
        std::memcpy(buf, bytes.data(), bytes.size());
    });
}

LPI_API int lpi_load_buffer(lpi_system **out, const void *buf, size_t size) {
    return load(out, "lpi_load_buffer", nullptr, [&](Bytes &bytes) {
        require(buf, "buf");
        bytes.data = static_cast<const unsigned char *>(buf);
        bytes.size = size;
    });
}

}  // extern "C"
