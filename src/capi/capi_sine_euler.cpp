// The C ABI of sine-Euler and FFTW wisdom.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "../core/methods.hpp"
#include "../models/sine_euler.hpp"
#include "handle.hpp"
#include "lpi_config.h"

#if LPI_HAVE_FFTW
#include <fftw3.h>
#endif

using lpi::capi::create;
using lpi::capi::guarded;
using lpi::capi::require;

namespace {

lpi::SineEulerModel &sine_euler(const lpi_system *sys) {
    require(sys, "system");
    auto *model = dynamic_cast<const lpi::SineEulerModel *>(&sys->system.model());
    if (!model)
        lpi::fail(LPI_ERR_UNSUPPORTED, std::string("system is a ") + sys->system.model().kind() +
                                           " system, not sine-euler");
    return const_cast<lpi::SineEulerModel &>(*model);
}

std::size_t squared(int N) { return static_cast<std::size_t>(N) * static_cast<std::size_t>(N); }

// Stores public coordinates converted from modes or a grid: the input was
// finite, so a coordinate that is not has overflowed in the conversion.
void set_converted(lpi_system *sys, const std::vector<double> &x, const char *from) {
    lpi::require_no_overflow(x.data(), x.size(), [from](std::size_t i) {
        return std::string("coordinate ") + std::to_string(i) + " of the field from these " + from;
    });
    sys->system.set_state(x.data(), x.size());
}

// "mode (a, b)" / "grid value (a, b)" of entry i of an N x N array.
std::string entry_name(const char *what, std::size_t i, int N) {
    return std::string(what) + " (" + std::to_string(i / static_cast<std::size_t>(N)) + ", " +
           std::to_string(i % static_cast<std::size_t>(N)) + ")";
}

[[maybe_unused]] void no_fftw() {
    lpi::fail(LPI_ERR_UNSUPPORTED, "FFTW wisdom needs FFTW3; this build has none");
}

}  // namespace

extern "C" {

LPI_API int lpi_sine_euler_create(lpi_system **out, int32_t N) {
    return create(out, "lpi_sine_euler_create", [&] { return lpi::make_sine_euler(N); });
}

LPI_API int lpi_sine_euler_size(const lpi_system *sys, int32_t *N) {
    return guarded(sys, "lpi_sine_euler_size", [&] {
        const auto &model = sine_euler(sys);
        require(N, "N");
        *N = model.order();
    });
}

LPI_API int lpi_sine_euler_set_modes(lpi_system *sys, const double *re_im, size_t n) {
    return guarded(sys, "lpi_sine_euler_set_modes", [&] {
        const auto &model = sine_euler(sys);
        require(re_im, "modes");
        lpi::require_length("modes", n, 2 * squared(model.order()));
        std::vector<double> x(squared(model.order()));
        model.public_from_modes(re_im, x.data());
        set_converted(sys, x, "modes");
    });
}

LPI_API int lpi_sine_euler_get_modes(const lpi_system *sys, double *re_im, size_t n) {
    return guarded(sys, "lpi_sine_euler_get_modes", [&] {
        const auto &model = sine_euler(sys);
        require(re_im, "modes buffer");
        lpi::require_length("modes buffer", n, 2 * squared(model.order()));
        const std::vector<double> &state = sys->system.working_state();
        std::memcpy(re_im, state.data(), sizeof(double) * n);
    });
}

LPI_API int lpi_sine_euler_set_grid(lpi_system *sys, const double *w, size_t n) {
    return guarded(sys, "lpi_sine_euler_set_grid", [&] {
        const auto &model = sine_euler(sys);
        require(w, "grid");
        lpi::require_length("grid", n, squared(model.order()));
        std::vector<double> x(squared(model.order()));
        model.public_from_grid(w, x.data());
        set_converted(sys, x, "grid values");
    });
}

LPI_API int lpi_sine_euler_get_grid(const lpi_system *sys, double *w, size_t n) {
    return guarded(sys, "lpi_sine_euler_get_grid", [&] {
        const auto &model = sine_euler(sys);
        require(w, "grid buffer");
        lpi::require_length("grid buffer", n, squared(model.order()));
        std::vector<double> grid(n);
        model.grid(sys->system.working_state().data(), grid.data());
        lpi::require_no_overflow(grid.data(), n, [&](std::size_t i) {
            return entry_name("grid value", i, model.order()) + " of this state";
        });
        std::memcpy(w, grid.data(), sizeof(double) * n);
    });
}

LPI_API int lpi_sine_euler_enstrophy(const lpi_system *sys, double *out) {
    return guarded(sys, "lpi_sine_euler_enstrophy", [&] {
        const auto &model = sine_euler(sys);
        require(out, "out");
        const double enstrophy = model.enstrophy(sys->system.working_state().data());
        lpi::require_no_overflow(&enstrophy, 1, [](std::size_t) { return std::string("the enstrophy of this state"); });
        *out = enstrophy;
    });
}

LPI_API int lpi_sine_euler_casimir_traces(const lpi_system *sys, int32_t kmax, double *out) {
    return guarded(sys, "lpi_sine_euler_casimir_traces", [&] {
        const auto &model = sine_euler(sys);
        require(out, "out");
        if (kmax < 1) lpi::fail(LPI_ERR_INVALID, "kmax must be >= 1, got " + std::to_string(kmax));
        std::vector<double> traces(static_cast<std::size_t>(kmax));
        model.casimir_traces(sys->system.working_state().data(), kmax, traces.data());
        lpi::require_no_overflow(traces.data(), traces.size(), [](std::size_t i) {
            return "(1/N) tr W^" + std::to_string(i + 1) + " of this state";
        });
        std::copy(traces.begin(), traces.end(), out);
    });
}

LPI_API int lpi_sine_euler_fft_floor(lpi_system *sys, int64_t nsteps, double *seconds_per_step,
                                     double *transforms_per_step) {
    return guarded(sys, "lpi_sine_euler_fft_floor", [&] {
        auto &model = sine_euler(sys);
        require(seconds_per_step, "seconds_per_step");
        require(transforms_per_step, "transforms_per_step");
        if (nsteps < 1) lpi::fail(LPI_ERR_INVALID, "nsteps must be >= 1, got " + std::to_string(nsteps));
        const lpi::Method &method = sys->system.method();
        // Only splittings have a flow program; every other kind is refused.
        const bool splitting = method.kind == lpi::MethodKind::Sequence ||
                               method.kind == lpi::MethodKind::SequenceAdjoint ||
                               method.kind == lpi::MethodKind::SymmetricComposition;
        if (!splitting)
            lpi::fail(LPI_ERR_INVALID, "the FFT floor is defined for splitting methods, not '" +
                                           method.name + "'");
        // Flows per step in a long run, as the splitting integrator counts them.
        const auto program = lpi::build_flow_program(method, model.piece_count());
        const bool seam = program.size() > 1 && program.front().piece == program.back().piece;
        const std::size_t flows = program.size() - (seam ? 1 : 0);
        if (static_cast<std::uint64_t>(nsteps) > SIZE_MAX / flows)
            lpi::fail(LPI_ERR_OVERFLOW, "nsteps = " + std::to_string(nsteps) + " times " +
                                            std::to_string(flows) +
                                            " flows per step overflows the flow count");
        sys->system.prepare_threads();
        const auto start = std::chrono::steady_clock::now();
        const double transforms = model.run_fft_floor(flows * static_cast<std::size_t>(nsteps));
        const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start;
        *seconds_per_step = elapsed.count() / static_cast<double>(nsteps);
        *transforms_per_step = transforms / static_cast<double>(nsteps);
    });
}

LPI_API int lpi_fftw_wisdom_import_file(const char *path) {
    return guarded(nullptr, "lpi_fftw_wisdom_import_file", [&] {
        require(path, "path");
#if LPI_HAVE_FFTW
        std::lock_guard<std::mutex> lock(lpi::fftw_planner_mutex());
        if (!fftw_import_wisdom_from_filename(path))
            lpi::fail(LPI_ERR_INVALID, std::string("could not read FFTW wisdom from '") + path + "'");
#else
        no_fftw();
#endif
    });
}

LPI_API int lpi_fftw_wisdom_export_file(const char *path) {
    return guarded(nullptr, "lpi_fftw_wisdom_export_file", [&] {
        require(path, "path");
#if LPI_HAVE_FFTW
        std::lock_guard<std::mutex> lock(lpi::fftw_planner_mutex());
        if (!fftw_export_wisdom_to_filename(path))
            lpi::fail(LPI_ERR_INVALID, std::string("could not write FFTW wisdom to '") + path + "'");
#else
        no_fftw();
#endif
    });
}

LPI_API int lpi_fftw_wisdom_import_string(const char *wisdom) {
    return guarded(nullptr, "lpi_fftw_wisdom_import_string", [&] {
        require(wisdom, "wisdom");
#if LPI_HAVE_FFTW
        std::lock_guard<std::mutex> lock(lpi::fftw_planner_mutex());
        if (!fftw_import_wisdom_from_string(wisdom))
            lpi::fail(LPI_ERR_INVALID, "the string is not valid FFTW wisdom");
#else
        no_fftw();
#endif
    });
}

LPI_API int lpi_fftw_wisdom_export_string(char *buf, size_t size, size_t *length) {
    return guarded(nullptr, "lpi_fftw_wisdom_export_string", [&] {
        require(length, "length");
        if (size > 0) require(buf, "buf");
#if LPI_HAVE_FFTW
        char *text;
        {
            std::lock_guard<std::mutex> lock(lpi::fftw_planner_mutex());
            text = fftw_export_wisdom_to_string();
        }
        if (!text) throw std::bad_alloc();
        const std::size_t needed = std::strlen(text);
        *length = needed;
        if (size > needed) std::memcpy(buf, text, needed + 1);
        std::free(text);
        if (size <= needed)
            lpi::fail(LPI_ERR_SIZE, "buffer of " + std::to_string(size) + " bytes is too small; " +
                                        std::to_string(needed + 1) + " needed");
#else
        no_fftw();
#endif
    });
}

}  // extern "C"
