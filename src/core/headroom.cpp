#include "headroom.hpp"

#include <sys/mman.h>

namespace lpi {

bool address_space_available(std::size_t bytes) {
    void *probe = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (probe == MAP_FAILED) return false;
    munmap(probe, bytes);
    return true;
}

}  // namespace lpi
