// Memory a dependency will take and cannot fail gracefully without: FFTW
// aborts when its allocation fails, OpenBLAS retries its buffers for ever.
// Before calling it, the library asks the system for as much itself.
#pragma once

#include <cstddef>

namespace lpi {

// Whether `bytes` of address space can be had now: mapped and given back at
// once (mapped, not malloc'ed: a compiler may drop a malloc whose block is
// never used, and a mapping is given back whole). Memory that another thread
// takes between this and the dependency's own allocation is not covered.
bool address_space_available(std::size_t bytes);

}  // namespace lpi
