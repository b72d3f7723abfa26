// libFuzzer harness of the lpi tool's .npy reader (src/cli/data_files.cpp,
// what lpi run --init and a resumed run read): the input bytes are the file,
// read through the reader's own path (a memfd, by /proc/self/fd). Checked: no
// crash or sanitizer report; an array that is read has as many values as its
// shape says; and written back as float64 (npy_file) and read again, it
// gives the same shape and the same bits. The corpus (tests/fuzz/corpus_npy)
// holds files NumPy wrote: float64, float32, int32, int64, Fortran order, a
// scalar, an empty array, format 2.0. Build and run with tests/fuzz/run.sh.
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "cli/data_files.hpp"

namespace {

[[noreturn]] void fail(const char *what) {
    std::fprintf(stderr, "fuzz_npy: %s\n", what);
    std::abort();
}

// The bytes as a file the reader opens by name: "" where it cannot be made.
std::string as_file(const std::uint8_t *data, std::size_t size) {
    static const int fd = memfd_create("npy", 0);
    if (fd < 0 || ftruncate(fd, 0) != 0 || lseek(fd, 0, SEEK_SET) != 0) return "";
    for (std::size_t done = 0; done < size;) {
        const ssize_t n = write(fd, data + done, size - done);
        if (n <= 0) return "";
        done += static_cast<std::size_t>(n);
    }
    return "/proc/self/fd/" + std::to_string(fd);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
    std::string path = as_file(data, size);
    if (path.empty()) fail("cannot make the memfd");
    lpi_cli::Array a;
    if (!lpi_cli::read_npy(path, a).empty()) return 0;
    std::size_t count = 1;
    for (std::size_t n : a.shape) count *= n;
    if (count != a.values.size()) fail("an array read with another number of values than its shape");
    a.integer = false;
    const std::string again = lpi_cli::npy_file(a);
    path = as_file(reinterpret_cast<const std::uint8_t *>(again.data()), again.size());
    lpi_cli::Array b;
    const std::string why = lpi_cli::read_npy(path, b);
    if (!why.empty()) fail(("its own float64 file is refused: " + why).c_str());
    if (b.shape != a.shape || b.values.size() != a.values.size() ||
        (count && std::memcmp(b.values.data(), a.values.data(), count * sizeof(double)) != 0))
        fail("its own float64 file reads back otherwise");
    return 0;
}
